; expect: unknown-condition.nc:3:1: unknown condition 'E9' (this machine has E1 E2)
G00 Z1
E9
M30
