; expect: fractional-condition.nc:2:1: condition 'E1.5' must be a whole number >= 0
E1.5
M30
