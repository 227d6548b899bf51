; expect: drill-with-xy.nc:4:5: a drilling block (G01 toward -Z with E1 armed) must not move X or Y
G00 Z1
E1
G01 Y3 Z-5 F60
M30
