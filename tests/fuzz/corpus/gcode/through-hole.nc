%
(through-hole.nc: a 1 mm hole through a 10 mm plate, drilled 1 mm past the far side)
(plate top at Z0, bottom at Z-10; tube electrode of 1 mm diameter)
G17 G21 G90
G00 Z5
G00 X12.5 Y-7.5
M03 M08
G00 Z0.5
E1                       (drill-rough, negative)
G01 Z-11 F90             (gap-controlled; the last millimetre breaks through)
E0
G00 Z5
M05 M09
M30
%
