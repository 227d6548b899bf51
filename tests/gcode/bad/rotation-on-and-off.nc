; expect: rotation-on-and-off.nc:2:5: 'M05' conflicts with 'M03' in the same block
M03 M05
M30
