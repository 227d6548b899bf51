; expect: wear-beyond-z-limit.nc:4:5: drilling with wear pre-compensation moves Z to -70.000 mm
G00 Z0
E1
G01 Z-40 F60
M30
