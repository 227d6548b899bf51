; expect: unclosed-comment.nc:2:8: unclosed comment
G00 X1 (rapid over
M30
