G01 X1 F
G99
E999
G02 X1 I
(unclosed comment
X1 X2
