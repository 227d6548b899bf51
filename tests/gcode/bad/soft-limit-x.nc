; expect: soft-limit-x.nc:3:5: X 150.000 mm is beyond the X soft limit (-100.000..100.000 mm)
G00 Z5
G00 X150
M30
