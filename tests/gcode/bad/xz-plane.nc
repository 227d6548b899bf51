; expect: xz-plane.nc:2:1: 'G18' is not supported: arcs are in the XY plane only (G17)
G18
M30
