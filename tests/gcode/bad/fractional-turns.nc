; expect: fractional-turns.nc:3:9: extra turns 'P0.5' must be a whole number 0..1000
G00 X1
G03 I-1 P0.5 F60
M30
