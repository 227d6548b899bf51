; expect: no-end.nc:3:1: program has no end: finish it with M02 or M30
G00 X1
G00 X2
