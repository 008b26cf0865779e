%
O2710 (POCKET AND CHAMFER ON A BLOCK)
(Built-in trunnion-ac, examples/offsets.toml: T1 a 10 mm end mill.)
(Check it with its stock: --stock box:-40,-30,-25,40,30,0)
G21 G17 G90 G94 G40 G49 G80
T1 M6
G54 G0 A0 C0
G43 H1 G0 X-15. Y-5. Z20.
(First level: 3 mm)
G0 Z2.
G1 Z-3. F200.
X15. F600.
Y5.
X-15.
Y-5.
(Second level: the rapid down to the first level's floor cuts air)
G0 Z-2.5
G1 Z-6. F200.
X15. F600.
Y5.
X-15.
Y-5.
G0 Z20.
(Chamfer the far edge with the tool leaning 45 degrees, TCPC)
G43.4 H1 X-15. Y13. Z20. A-45. C0
(The tool's rim dips 3.5 mm below its tip: approach and leave at Z8)
G0 Z8.
G1 Z-1.5 F300.
X15. F600.
G1 Z8.
G0 Z20.
G49 G0 Z200.
G28 A0 C0
M30
%
