; expect: unknown-letter.nc:3:1: unknown word 'S1200'
G00 X0
S1200 M03
M30
