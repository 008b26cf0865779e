//! Tilted working plane (G68.2, G53.1, G69) judged by forward kinematics:
//! on every built-in 5-axis machine, for random feature frames of both
//! forms (P0 Euler ZXZ, P1 roll-pitch-yaw, P2 three points, P3 two vectors,
//! P4 projection angles), after G53.1 the reported tip
//! of every row is the frame's transform of the programmed point and the
//! tool direction is the frame's Z (within 1e-9). The frame is computed
//! here from closed-form rotation matrices, not by the kernel's code.

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Row};
use fiveaxis_machine::{Machine, Offsets, ToolOffset};
use proptest::prelude::*;
use proptest::test_runner::Config;

/// Rotation matrices about X, Y, Z by `deg` degrees, as rows.
fn rx(deg: f64) -> [[f64; 3]; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}
fn ry(deg: f64) -> [[f64; 3]; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}
fn rz(deg: f64) -> [[f64; 3]; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}
fn mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}
fn apply(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| m[i][k] * v[k]).sum())
}

/// The rotation (as rows) whose +Z is along `z` and whose +X is `x` made
/// normal to it: the frame of the P2 and P3 definitions.
fn frame(x: [f64; 3], z: [f64; 3]) -> [[f64; 3]; 3] {
    let unit = |v: [f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / n)
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let z = unit(z);
    let along = x[0] * z[0] + x[1] * z[1] + x[2] * z[2];
    let x = unit([0, 1, 2].map(|i| x[i] - along * z[i]));
    let y = cross(z, x);
    [0, 1, 2].map(|i| [x[i], y[i], z[i]])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i] - b[i])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A G68.2 definition of form `form` (one or more blocks, each ending in
/// a newline) built from an origin and three angles, with the rotation
/// and origin it defines, computed here from the forms' definitions.
fn definition(form: u32, o: [f64; 3], [i, j, k]: [f64; 3]) -> (String, [[f64; 3]; 3], [f64; 3]) {
    let round = |v: f64| (v * 1e4).round() / 1e4;
    let base = mul(mul(rz(i), rx(j)), rz(k));
    let [x, y, z] = [0, 1, 2].map(|c| [base[0][c], base[1][c], base[2][c]]);
    match form {
        0 => (
            format!(
                "G68.2 X{:?} Y{:?} Z{:?} I{i:?} J{j:?} K{k:?}\n",
                o[0], o[1], o[2]
            ),
            base,
            o,
        ),
        1 => (
            format!(
                "G68.2 P1 X{:?} Y{:?} Z{:?} I{i:?} J{j:?} K{k:?}\n",
                o[0], o[1], o[2]
            ),
            mul(mul(rz(k), ry(j)), rx(i)),
            o,
        ),
        2 => {
            // Three points of the plane of `base`, an origin shift and a
            // turn about the new Z.
            let p2 = [0, 1, 2].map(|c| round(o[c] + 25.0 * x[c]));
            let p3 = [0, 1, 2].map(|c| round(o[c] + 7.0 * x[c] + 15.0 * y[c]));
            let m = frame(sub(p2, o), cross(sub(p2, o), sub(p3, o)));
            let shift = [2.5, -3.0, 1.0];
            let moved = apply(m, shift);
            (
                format!(
                    "G68.2 P2 Q0 X2.5 Y-3. Z1. R20.\nG68.2 P2 Q1 X{:?} Y{:?} Z{:?}\n\
                     G68.2 P2 Q2 X{:?} Y{:?} Z{:?}\nG68.2 P2 Q3 X{:?} Y{:?} Z{:?}\n",
                    o[0], o[1], o[2], p2[0], p2[1], p2[2], p3[0], p3[1], p3[2]
                ),
                mul(m, rz(20.0)),
                [0, 1, 2].map(|c| o[c] + moved[c]),
            )
        }
        3 => {
            // The X and Z directions of `base`, scaled, as the program
            // writes them (not quite square after rounding).
            let xv = x.map(|c| round(3.0 * c));
            let zv = z.map(|c| round(0.5 * c));
            (
                format!(
                    "G68.2 P3 Q1 X{:?} Y{:?} Z{:?} I{:?} J{:?} K{:?}\nG68.2 P3 Q2 I{:?} J{:?} K{:?}\n",
                    o[0], o[1], o[2], xv[0], xv[1], xv[2], zv[0], zv[1], zv[2]
                ),
                frame(xv, zv),
                o,
            )
        }
        _ => {
            // Projection angles: the plane's traces in Z-X (+X turned by J
            // about Y) and Y-Z (+Y turned by I about X), then K about Z.
            let xt = apply(ry(j), [1.0, 0.0, 0.0]);
            let yt = apply(rx(i), [0.0, 1.0, 0.0]);
            (
                format!(
                    "G68.2 P4 X{:?} Y{:?} Z{:?} I{i:?} J{j:?} K{k:?}\n",
                    o[0], o[1], o[2]
                ),
                mul(frame(xt, cross(xt, yt)), rz(k)),
                o,
            )
        }
    }
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            ..ToolOffset::default()
        },
    );
    o
}

fn run(machine: &Machine, program: &str) -> (Vec<Row>, Option<Alarm>) {
    common::run_sampled(machine, offsets(), program, &[0.5, 1.0])
}

const MACHINES: [&str; 4] = [
    "trunnion-ac",
    "trunnion-bc",
    "head-table-bc",
    "head-head-ca",
];

fn close(a: &[f64], b: &[f64], what: &str) -> Result<(), TestCaseError> {
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    prop_assert!(d < 1e-9, "{what}: {a:?} vs {b:?}");
    Ok(())
}

proptest! {
    #![proptest_config(Config {
        cases: 96,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x0068_0002),
        ..Config::default()
    })]

    #[test]
    fn rows_in_the_tilted_plane_are_the_frames_transform_of_the_program(
        form in 0u32..5,
        origin in prop::array::uniform3(-50.0..50.0f64),
        angles in prop::array::uniform3(-40.0..40.0f64),
        point in prop::array::uniform3(-30.0..30.0f64),
        radius in 5.0..20.0f64,
    ) {
        // Everything as the program writes it: four decimals.
        let round = |v: f64| (v * 1e4).round() / 1e4;
        let [i, j, k] = angles.map(round);
        let p = point.map(round);
        let o = origin.map(round);
        let radius = round(radius);
        let (definition, r, o) = definition(form, o, [i, j, k]);
        let x0 = round(p[0] + 10.0);
        let x1 = round(x0 + radius);
        let z4 = round(p[2] + 40.0);
        let lines = definition.lines().count() as u32;
        let program = format!(
            "G43 H1 G0 Z250.\n{definition}G53.1\n\
             G0 X{:?} Y{:?} Z{:?}\nG1 X{x0:?} F500.\nG3 X{:?} R{radius:?}\nG81 Z-5. R2.\nG80\nG69\n",
            p[0], p[1], z4, x1,
        );
        // The motion lines after the definition (its blocks start at line 2).
        let at_line = |n: u32| n + lines - 1;
        let z = apply(r, [0.0, 0.0, 1.0]);
        let to_work = |q: [f64; 3]| {
            let v = apply(r, q);
            [o[0] + v[0], o[1] + v[1], o[2] + v[2]]
        };
        for name in MACHINES {
            let machine = builtin_at_zero(name).expect("built in");
            let (rows, alarm) = run(&machine, &program);
            if let Some(a) = &alarm {
                // A frame the machine cannot tilt to is the control's alarm;
                // the B/C trunnion (B +-120, C endless) reaches every frame
                // of these angles, so it is checked in every case.
                prop_assert!(
                    name != "trunnion-bc" && a.line == at_line(3) && a.code.to_string() == "FX0075",
                    "{name}: {a:?}\n{program}"
                );
                continue;
            }
            // Every row after G53.1: the tool along the frame's Z.
            for row in rows.iter().filter(|r| r.line >= at_line(4) && r.line <= at_line(7)) {
                close(row.dir.as_slice(), &z, &format!("{name} line {} direction", row.line))?;
            }
            let ends: Vec<&Row> = rows.iter().filter(|r| r.s == 1.0).collect();
            let at = |line: u32| ends.iter().find(|r| r.line == line).copied();
            let end4 = at(at_line(4)).expect("line 4 moves");
            close(end4.tip.as_slice(), &to_work([p[0], p[1], z4]), &format!("{name} line 4"))?;
            let end5 = at(at_line(5)).expect("line 5 moves");
            close(end5.tip.as_slice(), &to_work([x0, p[1], z4]), &format!("{name} line 5"))?;
            // The arc: its end, and its middle on the circle of the plane.
            let end6 = at(at_line(6)).expect("line 6 moves");
            close(end6.tip.as_slice(), &to_work([x1, p[1], z4]), &format!("{name} arc end"))?;
            let mid = rows.iter().find(|r| r.line == at_line(6) && r.s == 0.5).expect("arc middle");
            // G3 from x0 to x1 (a chord c) with R r: the minor arc,
            // counter-clockwise, its centre left of the chord, its middle
            // r below the centre.
            let c = x1 - x0;
            let h = (radius * radius - 0.25 * c * c).sqrt();
            close(mid.tip.as_slice(), &to_work([x0 + 0.5 * c, p[1] + h - radius, z4]), &format!("{name} arc middle"))?;
            // G81 drills along the frame's Z at the last position.
            let bottom = rows
                .iter()
                .filter(|r| r.line == at_line(7) && r.s == 1.0)
                .map(|r| r.tip)
                .find(|t| {
                    let q = to_work([x1, p[1], -5.0]);
                    (t.x - q[0]).abs() + (t.y - q[1]).abs() + (t.z - q[2]).abs() < 1e-9
                });
            prop_assert!(bottom.is_some(), "{name}: no G81 row at the hole bottom: {rows:?}");
        }
    }
}

#[test]
fn g53_1_needs_a_frame_and_the_plane_refuses_what_it_does_not_combine() {
    let m = builtin_at_zero("trunnion-ac").expect("built in");
    let code = |program: &str| run(&m, program).1.map(|a| a.code.to_string());
    assert_eq!(code("G53.1\n").as_deref(), Some("FX0150"));
    for inside in ["G55", "G54.4 P1"] {
        assert_eq!(
            code(&format!("G68.2 J10.\n{inside}\n")).as_deref(),
            Some("FX0150"),
            "{inside}"
        );
    }
    assert_eq!(
        code("G43.4 H1 Z50.\nG68.2 J10.\n").as_deref(),
        Some("FX0150")
    );
    // The plane stays while TCPC is on.
    assert_eq!(
        code("G68.2 J10.\nG43.4 H1\nG69\n").as_deref(),
        Some("FX0150")
    );
    // Not nested with the 2-D program transforms either way; G69 ends both.
    assert_eq!(code("G68 R30.\nG68.2 J10.\n").as_deref(), Some("FX0150"));
    assert_eq!(code("G68.2 J10.\nG68 R30.\n").as_deref(), Some("FX0150"));
    assert_eq!(code("G68.2 J10.\nG69\nG68 R30.\nG69\nG0 X1.\n"), None);
    // G69 with a move: the move is in the workpiece frame.
    let (rows, alarm) = run(&m, "G68.2 X10. J30.\nG69 G0 X1. Y2.\n");
    assert_eq!(alarm, None);
    let end = rows.last().expect("a row");
    assert!(
        (end.tip.x - 1.0).abs() < 1e-9 && (end.tip.y - 2.0).abs() < 1e-9,
        "{:?}",
        end.tip
    );
    // G69 ends it: G55 is fine again, and G68.2 / G69 blocks move nothing.
    let (rows, alarm) = run(&m, "G0 X5.\nG68.2 X10. J10.\nG69\nG55\n");
    assert_eq!(alarm, None);
    assert_eq!(rows.iter().filter(|r| r.s == 1.0).count(), 1, "{rows:?}");
}

#[test]
fn g68_4_defines_the_frame_inside_the_frame_in_force() {
    // G68.2 tilts 30 degrees about X at X10; G68.4 then moves 5 along the
    // tilted Y and turns 90 degrees about the tilted Z.
    let m = builtin_at_zero("trunnion-bc").expect("built in");
    let (rows, alarm) = run(
        &m,
        "G43 H1 G0 Z250.\nG68.2 X10. J30.\nG68.4 Y5. I90.\nG53.1\nG0 X1. Y2. Z3.\n",
    );
    assert_eq!(alarm, None);
    let r = mul(rx(30.0), rz(90.0));
    let o = {
        let v = apply(rx(30.0), [0.0, 5.0, 0.0]);
        [10.0 + v[0], v[1], v[2]]
    };
    let want = {
        let v = apply(r, [1.0, 2.0, 3.0]);
        [o[0] + v[0], o[1] + v[1], o[2] + v[2]]
    };
    let end = rows
        .iter()
        .rfind(|r| r.line == 5 && r.s == 1.0)
        .expect("line 5");
    for (a, b) in end.tip.iter().zip(want) {
        assert!((a - b).abs() < 1e-9, "{:?} vs {want:?}", end.tip);
    }
}

#[test]
fn g53_6_turns_the_tool_with_its_tip_held() {
    for name in MACHINES {
        let m = builtin_at_zero(name).expect("built in");
        let (rows, alarm) = common::run_sampled(
            &m,
            offsets(),
            "G43 H1 G0 X5. Y5. Z60.\nG68.2 X0 J25.\nG53.6\n",
            &[0.25, 0.5, 0.75, 1.0],
        );
        assert_eq!(alarm, None, "{name}");
        let before = rows
            .iter()
            .find(|r| r.line == 1 && r.s == 1.0)
            .expect("line 1")
            .tip;
        let turn: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
        assert_eq!(turn.len(), 4, "{name}: {rows:?}");
        for row in turn {
            assert!(
                (row.tip - before).norm() < 1e-9,
                "{name}: {:?} vs {before:?}",
                row.tip
            );
        }
        let last = rows.last().expect("rows");
        let z = apply(rx(25.0), [0.0, 0.0, 1.0]);
        for (a, b) in last.dir.iter().zip(z) {
            assert!((a - b).abs() < 1e-9, "{name}: {:?}", last.dir);
        }
    }
}

#[test]
fn g68_3_takes_the_tool_axis_as_the_frames_z() {
    for name in MACHINES {
        let m = builtin_at_zero(name).expect("built in");
        let (r0, r1) = (m.rotary[0].name, m.rotary[1].name);
        // Tilt the tool (rotary words as the machine names them), then
        // build the frame from it at the current position.
        let program = format!(
            "G43 H1 G0 X10. Y5. Z80.\nG0 {r0}-20. {r1}30.\nG68.3\nG91 G0 Z10.\nG90 G0 X0 Y0 Z0\nG69\n"
        );
        let (rows, alarm) = run(&m, &program);
        assert_eq!(alarm, None, "{name}");
        let ends: Vec<&Row> = rows.iter().filter(|r| r.s == 1.0).collect();
        let tilted = ends.iter().find(|r| r.line == 2).expect("line 2");
        let up = ends.iter().find(|r| r.line == 4).expect("line 4");
        // G91 Z10 in the frame: 10 along the tool, the tool unchanged.
        let moved = up.tip - tilted.tip;
        let want = tilted.dir * 10.0;
        assert!(
            (moved - want).norm() < 1e-9,
            "{name}: {moved:?} vs {want:?}"
        );
        assert!((up.dir - tilted.dir).norm() < 1e-12, "{name}");
        // X0 Y0 Z0 is the origin: the position in workpiece coordinates
        // when G68.3 was given. Without TCPC, turning the rotary axes does
        // not change it (the control's absolute position stays X10 Y5
        // Z80): the tip goes back to where line 1 put it.
        let origin = ends.iter().find(|r| r.line == 5).expect("line 5");
        let start = ends.iter().find(|r| r.line == 1).expect("line 1");
        assert!(
            (origin.tip - start.tip).norm() < 1e-9,
            "{name}: {:?}",
            origin.tip
        );
    }
    // One or two origin words: PS5457.
    let m = builtin_at_zero("trunnion-ac").expect("built in");
    let (_, alarm) = run(&m, "G68.3 X1. Y2.\n");
    assert_eq!(alarm.map(|a| a.code.to_string()).as_deref(), Some("PS5457"));
}

#[test]
fn cutter_compensation_c_runs_in_the_feature_plane() {
    // The same compensated contour (lines, an arc, start-up and cancel),
    // once in the workpiece plane and once in a tilted plane: every row of
    // the tilted run is the frame's transform of the plain run's row.
    let m = builtin_at_zero("trunnion-bc").expect("built in");
    let contour = "G0 X-20. Y-20. Z5.\nG41 G1 X0 Y0 D1 F300.\nY30.\nG2 X20. Y50. R20.\nG1 X40.\nY0\nX0\nG40 G0 X-20. Y-20.\n";
    let mut offsets = offsets();
    offsets.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            radius: 4.0,
            ..ToolOffset::default()
        },
    );
    let run_with = |program: &str| common::run_sampled(&m, offsets.clone(), program, &[0.5, 1.0]);
    let (plain, alarm) = run_with(&format!("G43 H1 G0 Z250.\n{contour}"));
    assert_eq!(alarm, None);
    let (tilted, alarm) = run_with(&format!(
        "G43 H1 G0 Z250.\nG68.2 X10. Y-5. Z3. I20. J35. K-10.\nG53.1\n{contour}"
    ));
    assert_eq!(alarm, None);
    let r = mul(mul(rz(20.0), rx(35.0)), rz(-10.0));
    // From the end of the first positioning on (its middle depends on
    // where the tool came from).
    let plain: Vec<&Row> = plain
        .iter()
        .filter(|r| r.line > 2 || (r.line == 2 && r.s == 1.0))
        .collect();
    let tilted: Vec<&Row> = tilted
        .iter()
        .filter(|r| r.line > 4 || (r.line == 4 && r.s == 1.0))
        .collect();
    assert_eq!(plain.len(), tilted.len());
    for (a, b) in plain.iter().zip(&tilted) {
        let v = apply(r, [a.tip.x, a.tip.y, a.tip.z]);
        let want = [10.0 + v[0], -5.0 + v[1], 3.0 + v[2]];
        for (x, y) in b.tip.iter().zip(want) {
            assert!(
                (x - y).abs() < 1e-9,
                "line {}: {:?} vs {want:?}",
                a.line,
                b.tip
            );
        }
    }
}

#[test]
fn tcpc_inside_the_tilted_plane_programs_in_the_feature_frame() {
    // G43.5 in G68.2: the tip and the tool vector I J K are feature
    // coordinates; every row is the frame's transform of them.
    let r = mul(mul(rz(15.0), rx(30.0)), rz(0.0));
    let o = [10.0, -5.0, 2.0];
    let to_work = |q: [f64; 3]| {
        let v = apply(r, q);
        [o[0] + v[0], o[1] + v[1], o[2] + v[2]]
    };
    for name in MACHINES {
        let m = builtin_at_zero(name).expect("built in");
        let program = "G43 H1 G0 Z250.\nG68.2 X10. Y-5. Z2. I15. J30.\nG53.1\nG49\n\
                       G43.5 H1 X0 Y0 Z20.\nG1 X10. I0 J.2 K1. F500.\nG1 Y10. I.1 J0 K1.\nG49\nG69\n";
        let (rows, alarm) = run(&m, program);
        assert_eq!(alarm, None, "{name}");
        for (line, p, v) in [
            (6, [10.0, 0.0, 20.0], [0.0, 0.2, 1.0f64]),
            (7, [10.0, 10.0, 20.0], [0.1, 0.0, 1.0]),
        ] {
            let row = rows
                .iter()
                .find(|r| r.line == line && r.s == 1.0)
                .unwrap_or_else(|| panic!("{name}: line {line}"));
            let want = to_work(p);
            for (a, b) in row.tip.iter().zip(want) {
                assert!(
                    (a - b).abs() < 1e-9,
                    "{name} line {line}: {:?} vs {want:?}",
                    row.tip
                );
            }
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let dir = apply(r, v.map(|x| x / n));
            for (a, b) in row.dir.iter().zip(dir) {
                assert!(
                    (a - b).abs() < 1e-9,
                    "{name} line {line}: {:?} vs {dir:?}",
                    row.dir
                );
            }
        }
    }
}

/// The end tip of the last row of `line`.
fn end_tip(rows: &[Row], line: u32) -> [f64; 3] {
    let row = rows
        .iter()
        .rfind(|r| r.line == line && r.s == 1.0)
        .expect("the line moves");
    [row.tip.x, row.tip.y, row.tip.z]
}

#[test]
fn g68_2_p2_three_points_by_hand() {
    // Points (10,0,0), (10,5,0), (4,0,0): +X along the workpiece +Y, the
    // third point on the side of the workpiece -X, so +Y is -X and +Z is
    // +Z: a quarter turn about Z. Q0 shifts the origin by 1 along the new
    // X (workpiece +Y). Program point (1, 2, 3) is then
    // (10,1,0) + (-2, 1, 3) = (8, 2, 3).
    let m = builtin_at_zero("trunnion-ac").expect("built in");
    let (rows, alarm) = run(
        &m,
        "G68.2 P2 Q0 X1.\nG68.2 P2 Q1 X10.\nG68.2 P2 Q2 X10. Y5.\nG68.2 P2 Q3 X4.\nG53.1\nG0 X1. Y2. Z3.\n",
    );
    assert_eq!(alarm, None);
    let tip = end_tip(&rows, 6);
    for (a, b) in tip.iter().zip([8.0, 2.0, 3.0]) {
        assert!((a - b).abs() < 1e-9, "{tip:?}");
    }
    // Without Q0 the first point is the origin: (10,0,0) + (-2,1,3).
    let (rows, alarm) = run(
        &m,
        "G68.2 P2 Q1 X10.\nG68.2 P2 Q2 X10. Y5.\nG68.2 P2 Q3 X4.\nG0 X1. Y2. Z3.\n",
    );
    assert_eq!(alarm, None);
    let tip = end_tip(&rows, 4);
    for (a, b) in tip.iter().zip([8.0, 1.0, 3.0]) {
        assert!((a - b).abs() < 1e-9, "{tip:?}");
    }
}

#[test]
fn g68_2_p4_with_one_angle_is_that_rotation() {
    // One projection angle alone is the rotation about that axis (the
    // plane's other trace stays on its axis): P4 Ia = P1 Ia, P4 Jb = P1 Jb.
    let m = builtin_at_zero("trunnion-bc").expect("built in");
    for (words, program_point) in [("I25.", [3.0, -4.0, 5.0]), ("J-35.", [-6.0, 2.0, 7.0])] {
        let motion = format!(
            "G53.1\nG0 X{:?} Y{:?} Z{:?}\n",
            program_point[0], program_point[1], program_point[2]
        );
        let (p4, a4) = run(&m, &format!("G68.2 P4 X5. {words} K10.\n{motion}"));
        let (p1, a1) = run(&m, &format!("G68.4 P1 X5. {words}\nG68.4 K10.\n{motion}"));
        assert_eq!((a4, a1), (None, None));
        let (a, b) = (end_tip(&p4, 3), end_tip(&p1, 4));
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-9, "{words}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn g68_2_definitions_the_control_refuses() {
    let m = builtin_at_zero("trunnion-ac").expect("built in");
    let alarm = |program: &str| {
        run(&m, program)
            .1
            .map(|a| (a.code.to_string(), a.line))
            .unwrap_or_else(|| panic!("no alarm: {program}"))
    };
    let refused = |program: &str, line: u32| {
        assert_eq!(alarm(program), ("PS5457".to_string(), line), "{program}");
    };
    // No such form.
    refused("G68.2 P5 I10.\n", 1);
    // Three points on one line; two the same.
    refused("G68.2 P2 Q1\nG68.2 P2 Q2 X1.\nG68.2 P2 Q3 X3.\n", 3);
    refused("G68.2 P2 Q1 X1.\nG68.2 P2 Q2 X1.\nG68.2 P2 Q3 Y3.\n", 3);
    // Out of order, interrupted, without Q.
    refused("G68.2 P2 Q2 X1.\n", 1);
    refused("G68.2 P2 Q1\nG68.2 P2 Q3 X1.\n", 2);
    refused("G68.2 P2 Q1\nG0 X1.\n", 2);
    refused("G68.2 P2 Q1\nG68.2 P3 Q1 I1.\n", 2);
    refused("G68.2 P2 X1.\n", 1);
    refused("G68.2 P3 Q0 I1.\n", 1);
    // Two vectors: zero, or more than 5 degrees from square.
    refused("G68.2 P3 Q1 I0 J0 K0\n", 1);
    refused("G68.2 P3 Q1 I1.\nG68.2 P3 Q2 I0.1 K1.\n", 2);
    // Within 5 degrees of square: accepted (X made square to Z).
    assert_eq!(run(&m, "G68.2 P3 Q1 I1.\nG68.2 P3 Q2 I0.08 K1.\n").1, None);
    // Projection angles whose traces both run along Z.
    refused("G68.2 P4 I90. J90.\n", 1);
    // R belongs to P2 Q0 only.
    assert_eq!(
        alarm("G68.2 P2 Q1 R10.\n").0,
        "FX0012".to_string(),
        "R on Q1"
    );
}

/// Rodrigues: `v` turned by `deg` degrees about the unit vector `k`.
fn rodrigues(k: [f64; 3], deg: f64, v: [f64; 3]) -> [f64; 3] {
    let n = (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt();
    let k = k.map(|c| c / n);
    let (s, c) = deg.to_radians().sin_cos();
    let kxv = cross(k, v);
    let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    [0, 1, 2].map(|i| v[i] * c + kxv[i] * s + k[i] * kv * (1.0 - c))
}

#[test]
fn g68_three_dimensional_conversion_by_hand() {
    let m = builtin_at_zero("trunnion-ac").expect("built in");
    let check = |program: &str, line: u32, want: [f64; 3]| {
        let (rows, alarm) = run(&m, program);
        assert_eq!(alarm, None, "{program}");
        let tip = end_tip(&rows, line);
        for (a, b) in tip.iter().zip(want) {
            assert!((a - b).abs() < 1e-9, "{program}: {tip:?} vs {want:?}");
        }
    };
    // A quarter turn about Z through (10, 0, 0): (11, 0, 0) is (10, 1, 0).
    check(
        "G68 X10. Y0 Z0 I0 J0 K1 R90.\nG0 X11. Y0 Z0\n",
        2,
        [10.0, 1.0, 0.0],
    );
    // 30 degrees about Y through the origin: (0, 0, 10) is (5, 0, 8.66).
    let half3 = 10.0 * 30f64.to_radians().cos();
    check(
        "G68 X0 Y0 Z0 I0 J1. K0 R30.\nG0 X0 Y0 Z10.\n",
        2,
        [5.0, 0.0, half3],
    );
    // Centre words left out: where the program stands (here X20).
    check(
        "G0 X20. Y0 Z0\nG68 I0 J0 K1. R90.\nG0 X21.\n",
        3,
        [20.0, 1.0, 0.0],
    );
    // Nested: 90 about Z, then 90 about the converted X: (0, 0, 1) goes to
    // (0, -1, 0) by the inner, then (1, 0, 0) by the outer.
    check(
        "G68 X0 Y0 Z0 K1. R90.\nG68 X0 Y0 Z0 I1. R90.\nG0 X0 Y0 Z1.\n",
        3,
        [1.0, 0.0, 0.0],
    );
    // G69 ends both levels; the plain 2-D rotation still works after it.
    check(
        "G68 X0 Y0 Z0 K1. R90.\nG68 X0 Y0 Z0 I1. R90.\nG69\nG68 X0 Y0 R90.\nG0 X1. Y0 Z0\n",
        5,
        [0.0, 1.0, 0.0],
    );
    let code = |program: &str| run(&m, program).1.map(|a| a.code.to_string());
    assert_eq!(code("G68 I0 J0 K0 R10.\n").as_deref(), Some("PS0049"));
    assert_eq!(
        code("G68 K1. R1.\nG68 I1. R1.\nG68 J1. R1.\n").as_deref(),
        Some("PS0049")
    );
    assert_eq!(
        code("G68 K1. R10.\nG68.2 J10.\n").as_deref(),
        Some("FX0150")
    );
    assert_eq!(
        code("G68.2 J10.\nG68 K1. R10.\n").as_deref(),
        Some("FX0150")
    );
    assert_eq!(code("G68 K1. R10.\nG53.1\n").as_deref(), Some("FX0150"));
    assert_eq!(
        code("G68 K1. R10.\nG68 X1. R10.\n").as_deref(),
        Some("FX0150")
    );
}

proptest! {
    #![proptest_config(Config {
        cases: 64,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x0068_0003),
        ..Config::default()
    })]

    #[test]
    fn g68_conversion_rows_are_the_rodrigues_rotation_of_the_program(
        center in prop::array::uniform3(-50.0..50.0f64),
        axis in prop::array::uniform3(-1.0..1.0f64),
        angle in -180.0..180.0f64,
        point in prop::array::uniform3(-30.0..30.0f64),
    ) {
        let round = |v: f64| (v * 1e4).round() / 1e4;
        let (c, k, p, r) = (center.map(round), axis.map(round), point.map(round), round(angle));
        prop_assume!(k.iter().map(|v| v * v).sum::<f64>() > 0.01);
        let program = format!(
            "G68 X{:?} Y{:?} Z{:?} I{:?} J{:?} K{:?} R{r:?}\nG1 X{:?} Y{:?} Z{:?} F1000.\n",
            c[0], c[1], c[2], k[0], k[1], k[2], p[0], p[1], p[2]
        );
        let turned = rodrigues(k, r, sub(p, c));
        let want = [0, 1, 2].map(|i| c[i] + turned[i]);
        let m = builtin_at_zero("head-table-bc").expect("built in");
        let (rows, alarm) = run(&m, &program);
        prop_assert!(alarm.is_none(), "{alarm:?}");
        close(&end_tip(&rows, 2), &want, "conversion")?;
    }
}

#[test]
fn tcpc_on_the_workpiece_frame_inside_the_tilted_plane() {
    // WKP = 1: the programming frame does not turn with the table, and the
    // feature frame is defined on it. Under G43.4 the tip of every row,
    // turned from the table frame into that frame by forward kinematics,
    // is the feature frame's transform of the programmed path, while the
    // rotary axes turn.
    let r = mul(mul(rz(15.0), rx(30.0)), rz(0.0));
    let o = [10.0, -5.0, 2.0];
    let to_work = |q: [f64; 3]| {
        let v = apply(r, q);
        [o[0] + v[0], o[1] + v[1], o[2] + v[2]]
    };
    for name in ["trunnion-ac", "trunnion-bc", "head-table-bc"] {
        let mut m = builtin_at_zero(name).expect("built in");
        m.params.programming_frame = fiveaxis_machine::ProgrammingFrame::Workpiece;
        let (r0, r1) = (m.rotary[0].name, m.rotary[1].name);
        let program = format!(
            "G43 H1 G0 Z250.\nG68.2 X10. Y-5. Z2. I15. J30.\nG43.4 H1 X0 Y3. Z20.\n\
             G1 X5. {r0}10. {r1}20. F500.\nG2 X15. I5. J0\nG49\nG69\n"
        );
        let (rows, alarm) = run(&m, &program);
        assert_eq!(alarm, None, "{name}");
        let fixed = |row: &Row| {
            let t = m
                .chain(fiveaxis_machine::Side::Table, &row.joints)
                .transform_point(&row.tip.into())
                .coords;
            [t.x, t.y, t.z]
        };
        // The arc G2 from (5, 3) to (15, 3) about (10, 3) (I J: a half
        // circle by R would hang on a square root of rounding), clockwise,
        // its middle at (10, 8).
        for (line, s, p) in [
            (4, 0.5, [2.5, 3.0, 20.0]),
            (4, 1.0, [5.0, 3.0, 20.0]),
            (5, 0.5, [10.0, 8.0, 20.0]),
            (5, 1.0, [15.0, 3.0, 20.0]),
        ] {
            let row = rows
                .iter()
                .find(|row| row.line == line && row.s == s)
                .unwrap_or_else(|| panic!("{name}: line {line} s {s}"));
            let (got, want) = (fixed(row), to_work(p));
            for (a, b) in got.iter().zip(want) {
                assert!(
                    (a - b).abs() < 1e-9,
                    "{name} line {line} s {s}: {got:?} vs {want:?}"
                );
            }
        }
    }
}

#[test]
fn three_dimensional_tool_compensation_inside_the_tilted_plane() {
    // G41 with I J K in G68.2: the vector is read in the feature frame, so
    // the compensated path is the frame's transform of the same program
    // run untilted (radius 4, vectors not along the tool).
    let mut offsets = offsets();
    offsets.tools.insert(
        2,
        ToolOffset {
            radius: 4.0,
            ..ToolOffset::default()
        },
    );
    let r = mul(mul(rz(20.0), rx(25.0)), rz(-10.0));
    let o = [5.0, 8.0, -3.0];
    let body = "G0 X10. Y0 Z20.\nG41 D2 G1 X12. Y1. Z18. I1. J0 K1. F300.\n\
                X20. Y5. I0 J1. K0\nX25. Z15. I-1. J1. K1.\nG40 X30.\n";
    for name in MACHINES {
        let m = builtin_at_zero(name).expect("built in");
        let run_with =
            |program: &str| common::run_sampled(&m, offsets.clone(), program, &[0.5, 1.0]);
        let (flat, a0) = run_with(&format!("G43 H1 G0 Z250.\n{body}"));
        let (tilted, a1) = run_with(&format!(
            "G43 H1 G0 Z250.\nG68.2 X5. Y8. Z-3. I20. J25. K-10.\nG53.1\n{body}"
        ));
        if let Some(a) = &a1 {
            // A frame the machine cannot tilt to (G53.1, line 3).
            assert!(a.line == 3 && name != "trunnion-bc", "{name}: {a:?}");
            continue;
        }
        assert_eq!(a0, None, "{name}");
        let moves = |rows: &[Row], first: u32| -> Vec<[f64; 3]> {
            rows.iter()
                .filter(|r| r.line >= first)
                .map(|r| [r.tip.x, r.tip.y, r.tip.z])
                .collect()
        };
        let (flat, tilted) = (moves(&flat, 3), moves(&tilted, 5));
        assert_eq!(flat.len(), tilted.len(), "{name}");
        assert!(flat.len() >= 6, "{name}");
        for (a, b) in flat.iter().zip(&tilted) {
            let v = apply(r, *a);
            let want = [o[0] + v[0], o[1] + v[1], o[2] + v[2]];
            for (x, y) in b.iter().zip(want) {
                assert!((x - y).abs() < 1e-9, "{name}: {b:?} vs {want:?}");
            }
        }
    }
}
