; expect: after-end.nc:4:1: nothing may follow the program end (M30 on line 3)
G00 X1
M30
G00 X2
