; expect: percent-not-alone.nc:2:3: '%' must be alone on its line
% G00 X1
M30
