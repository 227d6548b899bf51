%
(row-of-holes.nc: five 8 mm deep holes 10 mm apart along X, rapids between them)
G17 G21 G90
G00 Z5
G00 X-20 Y0              (first hole)
M03 M08
F60                      (the cap for every drilling block below)
G00 Z0.5
E1
G01 Z-8                  (hole 1)
E0
G00 Z2
G91 G00 X10              (incremental step to the next hole)
G90 G00 Z0.5
E1
G01 Z-8                  (hole 2)
E0
G00 Z2
G91 G00 X10
G90 G00 Z0.5
E1
G01 Z-8                  (hole 3)
E0
G00 Z2
G91 G00 X10
G90 G00 Z0.5
E1
G01 Z-8                  (hole 4)
E0
G00 Z2
G91 G00 X10
G90 G00 Z0.5
E1
G01 Z-8                  (hole 5)
E0
G00 Z5
M05 M09
M30
%
