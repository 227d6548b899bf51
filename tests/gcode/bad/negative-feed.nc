; expect: negative-feed.nc:2:8: feed rate 'F-60' must be > 0 (mm/min)
G01 X1 F-60
M30
