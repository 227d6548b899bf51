%
(drill-then-finish.nc: seed 004's process. Drill with negative polarity, then finish the)
(hole wall with positive polarity by orbiting out to the final radius)
(1 mm electrode: the drilled hole is about 0.58 mm in radius; finish the wall to 0.60)
G17 G21 G90
G00 Z5
G00 X-20 Y10
M03 M08
G00 Z0.5
E1                       (drill-rough: negative polarity)
G01 Z-15 F60             (gap-controlled drilling; the electrode comes back up to Z0.5)
G00 Z-14.8               (rapid back into the drilled hole, 0.2 mm off the bottom)
E2                       (wall-finish: positive polarity)
G160 R0.60 F30           (orbit finishing: radius grows by eq. 20-21 up to 0.60 mm, back to centre)
E0
G00 Z5
M05 M09
M30
%
