; expect: two-motion-codes.nc:2:8: 'G01' conflicts with 'G00' in the same block
G00 X1 G01 Y1 F60
M30
