; expect: g90-and-g91.nc:2:5: 'G91' conflicts with 'G90' in the same block
G90 G91 G00 X1
M30
