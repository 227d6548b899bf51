; expect: stray-character.nc:2:11: unexpected character '$'
G00 X1 Y2 $
M30
