; expect: helix.nc:3:8: helical arcs are not supported
G00 X5
G02 X5 Z-1 I-5 F60
M30
