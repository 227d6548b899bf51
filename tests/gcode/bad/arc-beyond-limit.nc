; expect: arc-beyond-limit.nc:3:1: G03 arc: Y -103.000 mm is beyond the Y soft limit
G00 X0 Y-95
G03 X0 Y-95 J-4 F60
M30
