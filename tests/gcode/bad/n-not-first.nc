; expect: n-not-first.nc:2:5: 'N' (block number) must be the first word
G00 N20 X1
M30
