%
O3001 (TCPC TYPE 2: TIP AND TOOL VECTOR)
(Built-in head-table-bc, examples/offsets.toml: H1 = 120 mm)
G21 G17 G90 G94 G54
G0 X0 Y0 Z150. B0 C0
G43.5 H1 X-40. Y0 Z20.
(Chamfer-like pass: the tool leans 30 degrees towards -X, then turns around)
G1 Z0 I-0.5 J0 K0.866025 F800.
X40. I0.5 J0 K0.866025
Y40. I0 J0.5 K0.866025
X-40. I-0.5 J0.5 K0.707107
(Tool vertical: the rotating axis C holds its position)
G1 Y0 I0 J0 K1.
G0 Z50.
G49
G28 B0 C0
M30
%
