%
(A 10 x 10 mm square punch from the start hole at X-9 Y0, in the 20 mm plate of wire-sim:)
(a main cut and two skims over one contour, subprogram O100, each pass with its condition's)
(wire offset, G41: the wire left of the path, the punch on its right, clockwise.)
G21 G90 G54
G00 X-9 Y0
M08
E1 F3 M98 P100 (main cut)
M01 (optional stop: a real punch is held by a tab or a magnet before the skims)
E2 F6 M98 P100 (first skim)
E3 F8 M98 P100 (second skim)
E0 M09
M30

O100 (the contour: lead-in from the start hole, the square, lead-out back to it)
G41 G01 X-5 Y0
Y5
X5
Y-5
X-5
Y0
G40 X-9 Y0
M99
%
