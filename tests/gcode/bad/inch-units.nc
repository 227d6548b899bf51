; expect: inch-units.nc:3:1: 'G20' (inch units) is not supported
G21 G90
G20
M30
