; expect: orbit-without-radius.nc:3:1: G160 needs R (the final hole radius, mm)
E2 F30
G160
M30
