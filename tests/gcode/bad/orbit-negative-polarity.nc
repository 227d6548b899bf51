; expect: orbit-negative-polarity.nc:5:1: G160 orbit finishing needs a positive-polarity condition; E1 'drill-rough' is negative
G00 Z0
E1
G01 Z-5 F60
G160 R0.55
M30
