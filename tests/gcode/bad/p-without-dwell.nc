; expect: p-without-dwell.nc:2:8: 'P2' is only used by G04 (dwell) and G02/G03 (extra turns)
G00 X1 P2
M30
