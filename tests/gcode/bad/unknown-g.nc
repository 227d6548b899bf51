; expect: unknown-g.nc:3:1: unknown G code 'G28'
G00 X0
G28 X0
M30
