%
(die-sink-pocket.nc: a small round pocket, 8 mm across and 2 mm deep)
(plunge at the centre, then widen in XY at depth with lines and arcs)
G17 G21 G90
G00 Z5
G00 X30 Y30              (pocket centre)
M08
G00 Z0.5
E1
G01 Z-2 F30              (gap-controlled plunge to the pocket depth)
G01 X32 F60              (out to a 2 mm radius)
G03 X30 Y32 I-2 J0       (quarter circle, counter-clockwise)
G03 X28 Y30 I0 J-2
G03 X30 Y28 I2 J0
G03 X32 Y30 I0 J2        (back to the start of the circle)
G01 X34                  (out to a 4 mm radius)
G03 I-4 P1               (full circle plus one extra turn)
G02 X26 Y30 I-4 J0       (half circle, clockwise, over the top)
G01 X30                  (back to the centre)
E0
G00 Z5
M09
M30
%
