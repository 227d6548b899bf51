%
(blind-hole.nc: a 1 mm diameter blind hole, 20 mm deep, drilled in one plunge with E1)
(work surface at Z0; tube electrode of 1 mm diameter; machine coordinates in mm)
N10 G17 G21 G90          (XY plane, mm, absolute)
N20 G00 Z5.0             (clear the work)
N30 G00 X0 Y0            (over the hole)
N40 M03 M08              (electrode rotation and flushing on)
N50 G00 Z0.5             (rapid to just above the surface: rapids never discharge)
N60 E1                   (drill-rough: negative polarity, arms the generator)
N70 G01 Z-20.0 F60       (gap-controlled drilling to the nominal bottom; F caps it at 1 mm/s)
N80 E0                   (generator off)
N90 G00 Z5.0             (retract)
N100 M05 M09
N110 M30
%
