; expect: arc-centre-mismatch.nc:3:1: G03 end point is not on the arc's circle: start radius 4.123 mm, end radius 6.083 mm
G00 X0 Y0
G03 X10 Y0 I4 J1 F60
M30
