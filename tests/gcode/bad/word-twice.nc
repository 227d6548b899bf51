; expect: word-twice.nc:3:11: 'X' given twice in one block (first at column 5)
G00 Z5
G00 X1 Y2 X3
M30
