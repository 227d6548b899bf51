; expect: no-feed.nc:4:1: G01 needs a feed rate
G00 Z1
E1
G01 Z-5
M30
