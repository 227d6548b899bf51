; expect: malformed-number.nc:2:5: malformed number in 'X1.2.3'
G00 X1.2.3
M30
