; expect: missing-number.nc:2:5: missing number after 'X'
G00 X Y1
M30
