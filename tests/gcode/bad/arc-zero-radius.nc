; expect: arc-zero-radius.nc:3:1: G02 arc radius is zero
G00 X5 Y5
G02 X5 Y5 I0 J0 F60
M30
