; expect: arc-without-centre.nc:3:1: G02 needs I and/or J
G00 X0 Y0
G02 X10 Y0 F60
M30
