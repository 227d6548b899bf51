; expect: dwell-without-p.nc:3:1: G04 needs P (the dwell time in seconds)
G00 Z5
G04
M30
