; expect: unknown-m.nc:3:1: unknown M code 'M06'
G00 X0
M06
M30
