; expect: axis-without-mode.nc:2:1: 'X10' without a motion mode
X10 Y10
M30
