; expect: orbit-not-armed.nc:3:1: G160 needs an armed condition
F30
G160 R1
M30
