%
(demo.nc: what ./edm demo runs. A 12 mm blind hole with a Ø1.0 mm tube electrode, then the)
(wall finished to a Ø1.20 mm hole: seed 004's process on the simulated drilling machine)
G17 G21 G90              (XY plane, mm, absolute)
G00 Z5                   (clear of the work)
G00 X5 Y5                (over the hole)
M03 M08                  (rotation and flushing on)
G00 Z0.5                 (just above the surface: rapids never discharge)
E1                       (drill-rough, negative polarity: arms the generator)
G01 Z-12 F60             (gap-controlled drilling to 12 mm, wear compensated; back up to Z0.5)
G00 Z-11.8               (rapid back into the hole, 0.2 mm off its bottom)
E2                       (wall-finish, positive polarity)
G160 R0.60 F30           (orbit finishing out to a 0.60 mm hole radius, back to the centre)
E0                       (generator off)
G00 Z5                   (out of the hole)
M05 M09
M30
%
