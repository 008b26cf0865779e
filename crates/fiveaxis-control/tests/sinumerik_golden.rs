//! Golden examples of the SINUMERIK front end: small part programs whose
//! end positions were worked out by hand, each written next to the case
//! with how it was computed.
//!
//! Every position is judged by forward kinematics (`Machine::forward`) of
//! the machine position the kernel gives, with the tool length and work
//! offset the case expects (not the ones the segment reports), so a wrong
//! tool or offset shows as a wrong tip.
//!
//! Machines:
//!
//! * `Mill`: three axes, X, Y, Z ±1000 mm, SINUMERIK, reference at 0.
//! * `RotaryC`: the same with an endless table C about +Z.
//! * `DmuBc`: the built-in `sinumerik-dmu-bc` (45° head B, table C; it
//!   starts at its reference position, Z 500).
//!
//! Offsets (`OFFSETS`): T1 100 mm, the named tool `"FRA-D12"` 90 mm (it
//! takes offset number 2, after the numbered one), G54 = (10, 20, −300).
//! With D1 and no rotary axis turned the machine position is
//! `W + P + L·ez`: X = P.x + 10, Y = P.y + 20, Z = P.z − 300 + L.

mod common;

use common::{Outcome, run};
use fiveaxis_control::{Motion, Segment};
use fiveaxis_machine::{Machine, Offsets, Vec3};

// ----- machines and offsets ----------------------------------------------------

const MILL: &str = r#"
name = "SINUMERIK three-axis test mill"
type = "none"
control = "sinumerik"

[[linear]]
name = "X"
min = -1000.0
max = 1000.0

[[linear]]
name = "Y"
min = -1000.0
max = 1000.0

[[linear]]
name = "Z"
min = -1000.0
max = 1000.0
"#;

const ROTARY_C: &str = r#"
name = "SINUMERIK four-axis test mill, endless table C"
type = "table"
control = "sinumerik"

[[linear]]
name = "X"
min = -1000.0
max = 1000.0

[[linear]]
name = "Y"
min = -1000.0
max = 1000.0

[[linear]]
name = "Z"
min = -1000.0
max = 1000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, 1]
center = [0, 0, 0]
rollover = true
"#;

const OFFSETS: &str = "[tools]\n1 = { length = 100 }\n\"FRA-D12\" = { length = 90 }\n\
                       [work]\nG54 = [10, 20, -300]\n";

/// The work offset of `OFFSETS`.
const W: [f64; 3] = [10.0, 20.0, -300.0];

/// Tip tolerance, mm.
const EPS: f64 = 1e-9;
/// Tolerance of the built-in 5-axis case (irrational numbers written
/// with 15 digits), mm and unit-vector components.
const EPS_5X: f64 = 1e-9;

#[derive(Clone, Copy, Debug)]
enum Mach {
    Mill,
    RotaryC,
    DmuBc,
}

fn machine(m: Mach) -> Machine {
    let text = match m {
        Mach::Mill => MILL,
        Mach::RotaryC => ROTARY_C,
        Mach::DmuBc => fiveaxis_machine::builtin_source("sinumerik-dmu-bc").expect("built-in"),
    };
    Machine::from_toml(text).expect("test machine file")
}

fn offsets() -> Offsets {
    Offsets::from_toml(OFFSETS).expect("test offsets file")
}

// ----- judging -------------------------------------------------------------------

fn moving(out: &Outcome) -> Vec<&Segment> {
    out.segments.iter().filter(|s| s.moves()).collect()
}

/// The tip in the part frame at `s` of `seg`, with tool length `l` and the
/// work offset `W` (rotaries at 0 on these machines).
fn tip(m: &Machine, seg: &Segment, s: f64, l: f64) -> Vec3 {
    m.forward(&seg.eval(m, s), l).tip - Vec3::from(W)
}

fn close(a: &Vec3, b: &[f64; 3], eps: f64) -> bool {
    (a - Vec3::from(*b)).norm() <= eps
}

/// What a case expects.
#[derive(Debug)]
enum Expect {
    /// The tip at the end of every segment that moves, in order (part
    /// frame).
    Tips(&'static [[f64; 3]]),
    /// The machine position of the first axes at the end of the last
    /// segment.
    EndJoints(&'static [f64]),
    /// The tip at positions s inside the moving segments of a line.
    Samples {
        line: u32,
        at: &'static [(f64, [f64; 3])],
    },
    /// The kind of interpolation of every moving segment, in order.
    Motions(&'static [Motion]),
    /// The travel (end − start) of axis `axis` of every moving segment.
    Travel { axis: usize, deltas: &'static [f64] },
    /// No segment of `line` moves.
    Still(u32),
    /// The run stops with this alarm number on this line.
    Alarm { code: &'static str, line: u32 },
}

struct Case {
    name: &'static str,
    machine: Mach,
    /// The active tool length the positions are judged with.
    length: f64,
    program: &'static str,
    expect: &'static [Expect],
}

/// The hand-computed cases. Programs start from machine zero; `T1 D1`
/// with `G54` puts the tip at P with machine Z = P.z − 200.
const CASES: &[Case] = &[
    Case {
        // G0 then G1: tips as programmed; machine position of the last
        // end = (30 + 10, 20 + 20, 5 − 300 + 100).
        name: "G0 and G1",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X10 Y20 Z5\nG1 X30 F500\n",
        expect: &[
            Expect::Tips(&[[10.0, 20.0, 5.0], [30.0, 20.0, 5.0]]),
            Expect::EndJoints(&[40.0, 40.0, -195.0]),
            Expect::Motions(&[Motion::Rapid, Motion::Linear]),
        ],
    },
    Case {
        // The D block moves nothing; the next position takes the length:
        // machine Z of `Z0` after D1 is 0 − 300 + 100.
        name: "D1 takes effect with the next position",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1\nG54 G0 X0 Y0 Z0\nD1\nZ0\n",
        expect: &[Expect::Still(3), Expect::EndJoints(&[10.0, 20.0, -200.0])],
    },
    Case {
        // G2 from (0, 0) to (20, 0), centre I10 J0 from the start:
        // (10, 0), radius 10. Clockwise from 180° through 90°: at s = ½
        // the tip is at (10, 10); at s = ¼ at angle 135°:
        // (10 − 5√2, 5√2).
        name: "G2 with incremental centre I J",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG2 X20 Y0 I10 J0 F100\n",
        expect: &[
            Expect::Tips(&[[0.0, 0.0, 0.0], [20.0, 0.0, 0.0]]),
            Expect::Samples {
                line: 4,
                at: &[
                    (0.25, [10.0 - 7.0710678118654755, 7.0710678118654755, 0.0]),
                    (0.5, [10.0, 10.0, 0.0]),
                    (0.75, [10.0 + 7.0710678118654755, 7.0710678118654755, 0.0]),
                ],
            },
            Expect::Motions(&[Motion::Rapid, Motion::Cw]),
        ],
    },
    Case {
        // G3 with the centre absolute (I=AC(10) J=AC(0)): counterclockwise
        // from 180° through 270°: (10, −10) at s = ½. The start is at
        // (0, 5): a centre from the start would be (10, 5) instead.
        name: "G3 with absolute centre I=AC() J=AC()",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG3 X20 Y0 I=AC(10) J=AC(0) F100\n",
        expect: &[
            Expect::Tips(&[[0.0, 0.0, 0.0], [20.0, 0.0, 0.0]]),
            Expect::Samples {
                line: 4,
                at: &[(0.5, [10.0, -10.0, 0.0])],
            },
        ],
    },
    Case {
        // G3 from (5, 5) with I=AC(10) J=AC(5): centre (10, 5), radius 5,
        // to (15, 5) counterclockwise: from 180° through 270°, (10, 0) at
        // s = ½. With the centre taken from the start it would be
        // (15, 10), not equidistant: the absolute reading is what gives a
        // circle here.
        name: "G3 with absolute centre away from the origin",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X5 Y5 Z0\nG3 X15 Y5 I=AC(10) J=AC(5) F100\n",
        expect: &[
            Expect::Tips(&[[5.0, 5.0, 0.0], [15.0, 5.0, 0.0]]),
            Expect::Samples {
                line: 4,
                at: &[(0.5, [10.0, 0.0, 0.0])],
            },
        ],
    },
    Case {
        // CR=+10√2 from (0, 0) to (20, 0), clockwise, the short way:
        // centre (10, −10) (both ends 10√2 from it), start at 135°, end at
        // 45°, a quarter turn through 90°: (10, −10 + 10√2) at s = ½.
        name: "CR= positive: the arc of at most 180°",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG2 X20 Y0 CR=14.142135623730951 F100\n",
        expect: &[
            Expect::Tips(&[[0.0, 0.0, 0.0], [20.0, 0.0, 0.0]]),
            Expect::Samples {
                line: 4,
                at: &[(0.5, [10.0, 4.142135623730951, 0.0])],
            },
        ],
    },
    Case {
        // CR=−10√2: the long way, centre (10, 10); clockwise from 225°
        // down to −45° (270°), through 90° at s = ½: (10, 10 + 10√2).
        name: "CR= negative: the arc of more than 180°",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG2 X20 Y0 CR=-14.142135623730951 F100\n",
        expect: &[
            Expect::Tips(&[[0.0, 0.0, 0.0], [20.0, 0.0, 0.0]]),
            Expect::Samples {
                line: 4,
                at: &[
                    (0.5, [10.0, 24.14213562373095, 0.0]),
                    // 225° − 67.5° = 157.5°.
                    (
                        0.25,
                        [
                            10.0 + 14.142135623730951 * -0.9238795325112867,
                            10.0 + 14.142135623730951 * 0.3826834323650898,
                            0.0,
                        ],
                    ),
                ],
            },
        ],
    },
    Case {
        // Helix: G3 from (0, 0, 0) to (20, 0, −9) about (10, 0), TURN=1:
        // the half circle plus one whole turn, 540°, Z linear in the
        // sweep. s = ⅓: 180° swept, at (20, 0, −3); s = ½: 270° swept,
        // angle 180° + 270° = 90°: (10, 10, −4.5); s = ⅔: 360°, back at
        // (0, 0, −6). (The sweep itself: `helix_turn_sweeps_540_degrees`.)
        name: "helix with TURN=1",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG3 X20 Y0 Z-9 I10 J0 TURN=1 F100\n",
        expect: &[
            Expect::Tips(&[[0.0, 0.0, 0.0], [20.0, 0.0, -9.0]]),
            Expect::Samples {
                line: 4,
                at: &[
                    (1.0 / 3.0, [20.0, 0.0, -3.0]),
                    (0.5, [10.0, 10.0, -4.5]),
                    (2.0 / 3.0, [0.0, 0.0, -6.0]),
                ],
            },
        ],
    },
    Case {
        // G91 with AC / IC per word: from (10, 10, 0), `X5` is +5 → 15,
        // `Y=AC(50)` → 50, `Z=IC(-2)` → −2. Then `X=AC(0) Y5`: X 0,
        // Y 50 + 5. Back to G90: `X=IC(3)` → 3, Y stays.
        name: "AC and IC words mixed with G91",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X10 Y10 Z0\nG91 G1 X5 Y=AC(50) Z=IC(-2) F100\n\
                  X=AC(0) Y5\nG90 X=IC(3)\n",
        expect: &[Expect::Tips(&[
            [10.0, 10.0, 0.0],
            [15.0, 50.0, -2.0],
            [0.0, 55.0, -2.0],
            [3.0, 55.0, -2.0],
        ])],
    },
    Case {
        // Endless C from 0: ACP(350) turns +350; ACN(10) from 350 turns
        // negative to 10: −340; DC(340) from 10: the short way, −30;
        // ACP(20) from 340: +40; `C=DC(20)` again: no travel (not moving,
        // left out of the list).
        name: "DC, ACP, ACN on an endless C",
        machine: Mach::RotaryC,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nC=ACP(350)\nC=ACN(10)\nC=DC(340)\n\
                  C=ACP(20)\nC=DC(20)\n",
        expect: &[Expect::Travel {
            axis: 3,
            deltas: &[0.0, 350.0, -340.0, -30.0, 40.0],
        }],
    },
    Case {
        // R parameters in addresses: R1 = 10, R2 = R1 / 4 = 2.5;
        // X = 10·2 + 5 = 25, Y = 2.5, Z = −10.
        name: "R parameters and expressions",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nR1=10\nR2=R1/4\nG1 X=R1*2+5 Y=R2 Z=-R1 F100\n",
        expect: &[Expect::Tips(&[[25.0, 2.5, -10.0]])],
    },
    Case {
        // WHILE: R1 = 0, 1, 2 move X to 0, 10, 20, all on line 6.
        name: "WHILE loop moving in steps",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X-5 Y0 Z0\nR1=0\nWHILE R1<3\nG1 X=R1*10 F100\n\
                  R1=R1+1\nENDWHILE\nG0 Z50\n",
        expect: &[Expect::Tips(&[
            [-5.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [20.0, 0.0, 0.0],
            [20.0, 0.0, 50.0],
        ])],
    },
    Case {
        // MCALL CYCLE81(RTP 10, RFP 0, SDIS 2, DP −15): at each position
        // the XY move at the height the tool stands, then Z rapid to
        // RFP + SDIS = 2, feed to −15, rapid to RTP 10. `MCALL` alone
        // ends it: X30 only moves.
        name: "MCALL CYCLE81 at two positions",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z50 F200\nMCALL CYCLE81(10,0,2,-15)\nX10 Y10\n\
                  X20 Y10\nMCALL\nX30\n",
        expect: &[
            Expect::Tips(&[
                [0.0, 0.0, 50.0],
                [10.0, 10.0, 50.0],
                [10.0, 10.0, 2.0],
                [10.0, 10.0, -15.0],
                [10.0, 10.0, 10.0],
                [20.0, 10.0, 10.0],
                [20.0, 10.0, 2.0],
                [20.0, 10.0, -15.0],
                [20.0, 10.0, 10.0],
                [30.0, 10.0, 10.0],
            ]),
            Expect::Motions(&[
                Motion::Rapid,
                Motion::Rapid,
                Motion::Rapid,
                Motion::Linear,
                Motion::Rapid,
                Motion::Rapid,
                Motion::Rapid,
                Motion::Linear,
                Motion::Rapid,
                Motion::Rapid,
            ]),
        ],
    },
    Case {
        // CYCLE83(RTP 10, RFP 0, SDIS 2, DP −12, , FDEP −5, , DAM 2,
        // DTB 0, DTS 0, FRF 1, VARI 0): chip breaking, _VRT 1 mm,
        // _MDEP = DAM = 2. Rapid 2, feed −5 (peck 5); peck 5 − 2 = 3:
        // lift to −4, feed −8; peck max(1, 2) = 2: lift −7, feed −10;
        // peck 2: lift −9, feed −12 (the depth); rapid RTP 10.
        name: "CYCLE83 pecks (chip breaking)",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z20 F100\nCYCLE83(10,0,2,-12,,-5,,2,0,0,1,0)\n",
        expect: &[
            Expect::Tips(&[
                [0.0, 0.0, 20.0],
                [0.0, 0.0, 2.0],
                [0.0, 0.0, -5.0],
                [0.0, 0.0, -4.0],
                [0.0, 0.0, -8.0],
                [0.0, 0.0, -7.0],
                [0.0, 0.0, -10.0],
                [0.0, 0.0, -9.0],
                [0.0, 0.0, -12.0],
                [0.0, 0.0, 10.0],
            ]),
            Expect::Motions(&[
                Motion::Rapid,
                Motion::Rapid,
                Motion::Linear,
                Motion::Rapid,
                Motion::Linear,
                Motion::Rapid,
                Motion::Linear,
                Motion::Rapid,
                Motion::Linear,
                Motion::Rapid,
            ]),
        ],
    },
    Case {
        // HOLES2(CPA 50, CPO 50, RAD 20, STA1 0, INDA 90, NUM 4) under
        // MCALL CYCLE81(10, 0, 2, −5): holes at 0°, 90°, 180°, 270° about
        // (50, 50): (70, 50), (50, 70), (30, 50), (50, 30); at each the
        // move in the plane, Z 2, Z −5, Z 10.
        name: "HOLES2 with MCALL CYCLE81",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z20 F100\nMCALL CYCLE81(10,0,2,-5)\n\
                  HOLES2(50,50,20,0,90,4)\nMCALL\n",
        expect: &[Expect::Tips(&[
            [0.0, 0.0, 20.0],
            [70.0, 50.0, 20.0],
            [70.0, 50.0, 2.0],
            [70.0, 50.0, -5.0],
            [70.0, 50.0, 10.0],
            [50.0, 70.0, 10.0],
            [50.0, 70.0, 2.0],
            [50.0, 70.0, -5.0],
            [50.0, 70.0, 10.0],
            [30.0, 50.0, 10.0],
            [30.0, 50.0, 2.0],
            [30.0, 50.0, -5.0],
            [30.0, 50.0, 10.0],
            [50.0, 30.0, 10.0],
            [50.0, 30.0, 2.0],
            [50.0, 30.0, -5.0],
            [50.0, 30.0, 10.0],
        ])],
    },
    Case {
        // G4 F2: two seconds, no motion; the next move starts where the
        // tool stood.
        name: "G4 F dwell",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG0 X5 Y5 Z5\nG4 F2\nG1 X6 F100\n",
        expect: &[
            Expect::Still(4),
            Expect::Tips(&[[5.0, 5.0, 5.0], [6.0, 5.0, 5.0]]),
        ],
    },
    Case {
        // T="FRA-D12" is offset number 2 (after the numbered tool 1),
        // 90 mm: machine Z of Z0 = 0 − 300 + 90. Judged with L = 90: a
        // length of 100 would show the tip 10 mm high.
        name: "named tool T=\"FRA-D12\" with D1",
        machine: Mach::Mill,
        length: 90.0,
        program: "T=\"FRA-D12\"\nD1\nG54 G17 G90\nG0 X0 Y0 Z0\n",
        expect: &[
            Expect::Tips(&[[0.0, 0.0, 0.0]]),
            Expect::EndJoints(&[10.0, 20.0, -210.0]),
        ],
    },
    Case {
        // G70: lengths in inches. X1 Y2 Z0.5 → (25.4, 50.8, 12.7); after
        // G71 X1 is 1 mm again.
        name: "G70 inch input",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nG70\nG1 X1 Y2 Z0.5 F100\nG71\nX1\n",
        expect: &[Expect::Tips(&[[25.4, 50.8, 12.7], [1.0, 50.8, 12.7]])],
    },
    Case {
        // TRANS X10 Y5, AROT Z90: (10, 0, 0) turned to (0, 10, 0), shifted
        // to (10, 15, 0). A bare TRANS clears the whole frame.
        name: "TRANS, AROT and bare TRANS",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nTRANS X10 Y5\nAROT Z90\nG1 X10 Y0 Z0 F100\nTRANS\n\
                  G1 X10 Y0 Z0\n",
        expect: &[Expect::Tips(&[[10.0, 15.0, 0.0], [10.0, 0.0, 0.0]])],
    },
    Case {
        // ROT RPL=90 in G17: about Z; (10, 0, 5) → (0, 10, 5). In G18
        // (plane Z-X, applicate Y) RPL=90 turns about Y: (10, 0, 0) →
        // (0, 0, −10).
        name: "ROT RPL= in G17 and G18",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nROT RPL=90\nG1 X10 Y0 Z5 F100\nG18\nROT RPL=90\n\
                  G1 X10 Y0 Z0\n",
        expect: &[Expect::Tips(&[[0.0, 10.0, 5.0], [0.0, 0.0, -10.0]])],
    },
    Case {
        // G53 leaves G54 and TRANS out for its block: machine (1, 2, 3)
        // with D0 (no length); the tip in the part frame is
        // (1 − 10, 2 − 20, 3 + 300).
        name: "G53 machine coordinates",
        machine: Mach::Mill,
        length: 0.0,
        program: "T1 D0\nG54 G17 G90\nTRANS X5\nG0 X0 Y0 Z0\nG0 G53 X1 Y2 Z3\n",
        expect: &[
            Expect::Tips(&[[5.0, 0.0, 0.0], [-9.0, -18.0, 303.0]]),
            Expect::EndJoints(&[1.0, 2.0, 3.0]),
        ],
    },
    Case {
        // SUPA likewise, at feed; the next block is in G54 + TRANS again.
        name: "SUPA machine coordinates",
        machine: Mach::Mill,
        length: 0.0,
        program: "T1 D0\nG54 G17 G90\nTRANS X5\nG1 SUPA X-1 Y-2 Z-3 F100\nG1 X0 Y0 Z0\n",
        expect: &[Expect::Tips(&[[-11.0, -22.0, 297.0], [5.0, 0.0, 0.0]])],
    },
    Case {
        // CYCLE800 mode 57 with C = 90 and _DIR = 0 (the frame only, the
        // tool stays vertical): X10 in the turned plane is (0, 10, 0).
        // Head B at 0: machine = W + tip + L·ez = (10, 30, −200), B 0, C 0.
        name: "CYCLE800 frame only (_DIR=0)",
        machine: Mach::DmuBc,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nCYCLE800(0,\"TC1\",0,57,0,0,0,0,0,90,0,0,0,0)\n\
                  G1 X10 Y0 Z0 F1000\n",
        expect: &[
            Expect::Tips(&[[0.0, 10.0, 0.0]]),
            Expect::EndJoints(&[10.0, 30.0, -200.0, 0.0, 0.0]),
        ],
    },
    Case {
        // CYCLE800 with X0 = (5, 0, 0), turned 90° about X, X1 = (0, 0, 2):
        // R = Rx(90): (x, y, z) → (x, −z, y); the origin is
        // X0 + R·X1 = (5, −2, 0); `G1 X1 Y0 Z0` → (6, −2, 0) on the
        // table, the tool not turned (_DIR=0).
        name: "CYCLE800 shifts before and after the turn",
        machine: Mach::DmuBc,
        length: 100.0,
        program: "T1 D1\nG54 G17 G90\nCYCLE800(0,\"TC1\",0,57,5,0,0,90,0,0,0,0,2,0)\n\
                  G1 X1 Y0 Z0 F1000\n",
        expect: &[Expect::Tips(&[[6.0, -2.0, 0.0]])],
    },
    Case {
        name: "unknown G function G503",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54\nG503\n",
        expect: &[Expect::Alarm {
            code: "12470",
            line: 3,
        }],
    },
    Case {
        name: "undefined name",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54\nG1 X=NOSUCHNAME F100\n",
        expect: &[Expect::Alarm {
            code: "12550",
            line: 3,
        }],
    },
    Case {
        name: "jump target missing",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54\nGOTOF NOWHERE\nG0 X0\n",
        expect: &[Expect::Alarm {
            code: "14080",
            line: 3,
        }],
    },
    Case {
        name: "SETAL user alarm",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54\nG0 X1 Y0 Z0\nSETAL(65000)\nG0 X2\n",
        expect: &[
            Expect::Tips(&[[1.0, 0.0, 0.0]]),
            Expect::Alarm {
                code: "65000",
                line: 4,
            },
        ],
    },
    Case {
        // X995 with G54 X10: machine X 1005 beyond the limit 1000.
        name: "soft limit",
        machine: Mach::Mill,
        length: 100.0,
        program: "T1 D1\nG54\nG0 X995 Y0 Z0\n",
        expect: &[Expect::Alarm {
            code: "10720",
            line: 3,
        }],
    },
];

fn check_case(case: &Case) -> Result<(), String> {
    let m = machine(case.machine);
    let out = run(&m, offsets(), case.program);
    let l = case.length;
    let moving = moving(&out);
    let mut alarm_expected = false;
    for e in case.expect {
        match e {
            Expect::Tips(tips) => {
                let got: Vec<Vec3> = moving.iter().map(|s| tip(&m, s, 1.0, l)).collect();
                let ok = got.len() == tips.len()
                    && got.iter().zip(tips.iter()).all(|(g, w)| close(g, w, EPS));
                if !ok {
                    return Err(format!(
                        "tips at segment ends: want {tips:?}\n got {:?}",
                        got.iter().map(|v| [v.x, v.y, v.z]).collect::<Vec<_>>()
                    ));
                }
            }
            Expect::EndJoints(want) => {
                let last = moving.last().ok_or("no segment moves")?;
                let got = &last.end[..want.len()];
                if got
                    .iter()
                    .zip(want.iter())
                    .any(|(g, w)| (g - w).abs() > EPS)
                {
                    return Err(format!("end joints: want {want:?}, got {got:?}"));
                }
            }
            Expect::Samples { line, at } => {
                let seg = moving
                    .iter()
                    .find(|s| s.line == *line)
                    .ok_or_else(|| format!("no moving segment on line {line}"))?;
                for (s, want) in at.iter() {
                    let got = tip(&m, seg, *s, l);
                    if !close(&got, want, EPS) {
                        return Err(format!("line {line} at s = {s}: want {want:?}, got {got}"));
                    }
                }
            }
            Expect::Motions(want) => {
                let got: Vec<Motion> = moving.iter().map(|s| s.motion).collect();
                if got != *want {
                    return Err(format!("motions: want {want:?}, got {got:?}"));
                }
            }
            Expect::Travel { axis, deltas } => {
                let got: Vec<f64> = moving
                    .iter()
                    .map(|s| s.end[*axis] - s.start[*axis])
                    .collect();
                let ok = got.len() == deltas.len()
                    && got
                        .iter()
                        .zip(deltas.iter())
                        .all(|(g, w)| (g - w).abs() < EPS);
                if !ok {
                    return Err(format!(
                        "travel of axis {axis}: want {deltas:?}, got {got:?}"
                    ));
                }
            }
            Expect::Still(line) => {
                if let Some(s) = moving.iter().find(|s| s.line == *line) {
                    return Err(format!("line {line} moves: {:?} → {:?}", s.start, s.end));
                }
            }
            Expect::Alarm { code, line } => {
                alarm_expected = true;
                let a = out.alarm.as_ref().ok_or("no alarm")?;
                if a.code.to_string() != *code || a.line != *line {
                    return Err(format!(
                        "alarm: want {code} on line {line}, got {} on line {}: {}",
                        a.code, a.line, a.message
                    ));
                }
            }
        }
    }
    if !alarm_expected && let Some(a) = &out.alarm {
        return Err(format!(
            "unexpected alarm {} on line {}: {}",
            a.code, a.line, a.message
        ));
    }
    Ok(())
}

#[test]
fn golden_cases() {
    let failures: Vec<String> = CASES
        .iter()
        .filter_map(|c| {
            check_case(c)
                .err()
                .map(|e| format!("{}:\n{}\n{e}", c.name, c.program))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} golden cases fail:\n\n{}",
        failures.len(),
        CASES.len(),
        failures.join("\n\n")
    );
}

/// The sweep of a segment's tip about `centre` in the XY plane, degrees,
/// by sampling `Segment::eval` finely and adding the turns between
/// samples (each well under 180°).
fn swept(m: &Machine, seg: &Segment, centre: [f64; 2], l: f64) -> f64 {
    let n = 720;
    let angle = |s: f64| {
        let t = tip(m, seg, s, l);
        (t.y - centre[1]).atan2(t.x - centre[0])
    };
    let mut total = 0.0;
    let mut prev = angle(0.0);
    for k in 1..=n {
        let a = angle(f64::from(k) / f64::from(n));
        let mut d = a - prev;
        while d > std::f64::consts::PI {
            d -= 2.0 * std::f64::consts::PI;
        }
        while d < -std::f64::consts::PI {
            d += 2.0 * std::f64::consts::PI;
        }
        total += d;
        prev = a;
    }
    total.to_degrees()
}

/// TURN=1 on a half circle: 540° counterclockwise (one whole turn beyond
/// the programmed half), with Z linear in the swept angle and the radius
/// 10 all along.
#[test]
fn helix_turn_sweeps_540_degrees() {
    let m = machine(Mach::Mill);
    let out = run(
        &m,
        offsets(),
        "T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG3 X20 Y0 Z-9 I10 J0 TURN=1 F100\n",
    );
    assert!(out.alarm.is_none(), "{:?}", out.alarm);
    let seg = out
        .segments
        .iter()
        .find(|s| s.line == 4)
        .expect("helix segment");
    let sweep = swept(&m, seg, [10.0, 0.0], 100.0);
    assert!((sweep - 540.0).abs() < 1e-6, "sweep {sweep}°");
    for k in 0..=16 {
        let s = f64::from(k) / 16.0;
        let t = tip(&m, seg, s, 100.0);
        let r = (t.x - 10.0).hypot(t.y);
        assert!((r - 10.0).abs() < 1e-9, "radius {r} at s = {s}");
        assert!((t.z - -9.0 * s).abs() < 1e-9, "z {} at s = {s}", t.z);
    }
}

/// Without TURN the same arc sweeps 180°; with TURN=2, 900°.
#[test]
fn helix_turns_add_whole_circles() {
    let m = machine(Mach::Mill);
    for (turn, want) in [("", 180.0), (" TURN=0", 180.0), (" TURN=2", 900.0)] {
        let program = format!("T1 D1\nG54 G17 G90\nG0 X0 Y0 Z0\nG3 X20 Y0 Z-9 I10 J0{turn} F100\n");
        let out = run(&m, offsets(), &program);
        assert!(out.alarm.is_none(), "{program}: {:?}", out.alarm);
        let seg = out.segments.iter().find(|s| s.line == 4).expect("arc");
        let sweep = swept(&m, seg, [10.0, 0.0], 100.0);
        assert!((sweep - want).abs() < 1e-6, "{program}: sweep {sweep}°");
    }
}

/// A clockwise helix: G2 with TURN=1 from (20, 0) to (0, 0) about
/// (10, 0): −540°.
#[test]
fn clockwise_helix_turns_negative() {
    let m = machine(Mach::Mill);
    let out = run(
        &m,
        offsets(),
        "T1 D1\nG54 G17 G90\nG0 X20 Y0 Z0\nG2 X0 Y0 Z5 I-10 J0 TURN=1 F100\n",
    );
    assert!(out.alarm.is_none(), "{:?}", out.alarm);
    let seg = out.segments.iter().find(|s| s.line == 4).expect("arc");
    let sweep = swept(&m, seg, [10.0, 0.0], 100.0);
    assert!((sweep + 540.0).abs() < 1e-6, "sweep {sweep}°");
    assert!(close(&tip(&m, seg, 1.0, 100.0), &[0.0, 0.0, 5.0], EPS));
}

/// The built-in DMU-style machine, TRAORI with the tool vector
/// (1/√2, ½, ½): that is the 45° head B turned by 90° (Rodrigues about
/// a = (0, 1, 1)/√2: R·ez = (a × ez)·sin 90° + a (a·ez)(1 − cos 90°) =
/// (1/√2, 0, 0) + (0, ½, ½)), table C at 0 (B = −90° would need C but is
/// outside B's −5° … 180°). The pivot is 150 mm above the gauge point, the
/// tool 100 mm: tip = X + (0, 0, 150) − 250·v, so for the tip at the work
/// zero (G54 = 0) X = 250·v − (0, 0, 150) = (176.776695296637, 125, −25).
#[test]
fn dmu_bc_traori_vector_golden() {
    let m = fiveaxis_machine::builtin("sinumerik-dmu-bc").expect("built-in");
    let o = Offsets::from_toml("[tools]\n1 = { length = 100 }\n[work]\nG54 = [0, 0, 0]\n")
        .expect("offsets");
    let out = run(
        &m,
        o,
        "T1 D1\nG54 G17 G90\nTRAORI\nG1 X0 Y0 Z0 A3=0.707106781186548 B3=0.5 C3=0.5 F1000\n",
    );
    assert!(out.alarm.is_none(), "{:?}", out.alarm);
    let last = out.segments.last().expect("a segment");
    let want = [176.776_695_296_636_9, 125.0, -25.0, 90.0, 0.0];
    let c = fiveaxis_machine::principal(last.end[4]);
    let got = [last.end[0], last.end[1], last.end[2], last.end[3], c];
    assert!(
        got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-6),
        "want {want:?}, got {got:?}"
    );
    let pose = m.forward(&last.end, 100.0);
    assert!(pose.tip.norm() < 1e-6, "tip {}", pose.tip);
    let v = Vec3::new(0.5f64.sqrt(), 0.5, 0.5);
    assert!((pose.dir - v).norm() < EPS_5X, "dir {}", pose.dir);
}
