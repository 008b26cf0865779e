//! LinuxCNC's tilted-working-plane remap (`twp_remap = true`): G68.2 P0–P3
//! with their rotation orders, G68.3, G68.4, G69, G53.1 / G53.3 / G53.6,
//! judged by forward kinematics (`Machine::forward`) against rotation
//! matrices written out here in closed form: after G53.x the tool
//! direction is the plane's +Z (1e-9) and the tip is on the programmed
//! point of the plane (1e-6). Every error the remap's README lists.

mod common;

use fiveaxis_control::{Motion, Segment};
use fiveaxis_machine::{Joints, Machine, Offsets, ToolOffset, Vec3};
use nalgebra::Matrix3;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

const DIR_TOLERANCE: f64 = 1e-9;
const TIP_TOLERANCE: f64 = 1e-6;
/// Tool 1's length.
const TOOL: f64 = 100.0;
/// The G54 offset the programs set (G10 L2 P1).
const WORK: [f64; 3] = [120.0, -80.0, -300.0];

/// A head with C about Z and A about X (nutation 90°, LinuxCNC's trsrn
/// head with the nutation angle set to 90°), pivots off the gauge point:
/// it reaches every direction.
const HEAD_90: &str = r#"
name = "head C + A, nutation 90"
type = "head"
control = "linuxcnc"
[[linear]]
name = "X"
min = -5000.0
max = 5000.0
[[linear]]
name = "Y"
min = -5000.0
max = 5000.0
[[linear]]
name = "Z"
min = -5000.0
max = 5000.0
[[rotary]]
name = "C"
on = "head"
axis = [0.0, 0.0, 1.0]
center = [10.0, 0.0, 0.0]
min = -3600.0
max = 3600.0
[[rotary]]
name = "A"
on = "head"
axis = [1.0, 0.0, 0.0]
center = [0.0, 5.0, 150.0]
min = -180.0
max = 180.0
[parameters]
twp_remap = true
"#;

/// A nutating head: C about Z, then B about a line 45° from Z in the
/// Y-Z plane (nutation 45°): tool directions up to 90° from +Z.
const NUTATING_45: &str = r#"
name = "nutating head C + B, nutation 45"
type = "head"
control = "linuxcnc"
[[linear]]
name = "X"
min = -5000.0
max = 5000.0
[[linear]]
name = "Y"
min = -5000.0
max = 5000.0
[[linear]]
name = "Z"
min = -5000.0
max = 5000.0
[[rotary]]
name = "C"
on = "head"
axis = [0.0, 0.0, 1.0]
center = [0.0, 0.0, 0.0]
rollover = true
[[rotary]]
name = "B"
on = "head"
axis = [0.0, -0.70710678118654752, 0.70710678118654752]
center = [0.0, 0.0, 200.0]
min = -360.0
max = 360.0
[parameters]
twp_remap = true
"#;

/// A mixed machine: C rotary table (rollover), B head about Y.
const MIXED: &str = r#"
name = "table C + head B"
type = "mixed"
control = "linuxcnc"
[[linear]]
name = "X"
min = -5000.0
max = 5000.0
[[linear]]
name = "Y"
min = -5000.0
max = 5000.0
[[linear]]
name = "Z"
min = -5000.0
max = 5000.0
[[rotary]]
name = "C"
on = "table"
axis = [0.0, 0.0, 1.0]
center = [30.0, -20.0, 0.0]
rollover = true
[[rotary]]
name = "B"
on = "head"
axis = [0.0, 1.0, 0.0]
center = [0.0, 0.0, 180.0]
min = -120.0
max = 120.0
[parameters]
twp_remap = true
"#;

fn machine(text: &str) -> Machine {
    Machine::from_toml(text).expect("the machine file reads")
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: TOOL,
            ..ToolOffset::default()
        },
    );
    o
}

/// The program's start: G54 offset, tool 1 with its length.
fn prelude() -> String {
    format!(
        "G21 G90 G54\nG10 L2 P1 X{} Y{} Z{}\nT1 M6 G43 H1\n",
        WORK[0], WORK[1], WORK[2]
    )
}

struct Run {
    segments: Vec<Segment>,
    alarm: Option<String>,
}

fn run(m: &Machine, program: &str) -> Run {
    let out = common::run(m, offsets(), program);
    Run {
        segments: out.segments,
        alarm: out.alarm.map(|a| a.to_string()),
    }
}

fn run_ok(m: &Machine, program: &str) -> Vec<Segment> {
    let r = run(m, program);
    assert!(r.alarm.is_none(), "{:?}\n{program}", r.alarm);
    r.segments
}

/// The alarm of a program that must stop: its text (code and message).
fn alarm(m: &Machine, program: &str) -> String {
    run(m, program)
        .alarm
        .unwrap_or_else(|| panic!("no alarm:\n{program}"))
}

// ----- closed-form rotations ------------------------------------------------

fn rx(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn ry(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
fn rz(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
fn about(digit: u32, deg: f64) -> Matrix3<f64> {
    match digit {
        1 => rx(deg),
        2 => ry(deg),
        _ => rz(deg),
    }
}

/// G68.2 P0 Q…: true Euler angles, turns about the moving axes: the
/// first turn (I) about the first axis, then J about the turned second
/// axis, then K about the twice-turned third axis.
fn euler(q: u32, [i, j, k]: [f64; 3]) -> Matrix3<f64> {
    about(q / 100, i) * about(q / 10 % 10, j) * about(q % 10, k)
}

/// G68.2 P1 Q…: turns about the fixed axes of the work coordinate
/// system, I first: the later turn multiplies from the left.
fn fixed(q: u32, [i, j, k]: [f64; 3]) -> Matrix3<f64> {
    about(q % 10, k) * about(q / 10 % 10, j) * about(q / 100, i)
}

/// The frame whose +Z is `z` and whose +X is `x` made normal to it.
fn frame(x: Vec3, z: Vec3) -> Matrix3<f64> {
    let z = z.normalize();
    let x = (x - z * x.dot(&z)).normalize();
    let y = z.cross(&x);
    Matrix3::from_columns(&[x, y, z])
}

// ----- judging ----------------------------------------------------------------

/// The pose of the last segment's end by forward kinematics, tip in the
/// table frame.
fn end_pose(m: &Machine, segments: &[Segment]) -> (Joints, Vec3, Vec3) {
    let last = segments.last().expect("a move");
    let pose = m.forward(&last.end, TOOL);
    (last.end, pose.tip, pose.dir)
}

/// After the program: the tool along `r`·Z and the tip on `origin +
/// r·p` of the work coordinate system.
fn assert_on_plane(m: &Machine, segments: &[Segment], r: &Matrix3<f64>, origin: Vec3, p: Vec3) {
    let (_, tip, dir) = end_pose(m, segments);
    let want_dir = r * Vec3::z();
    let want_tip = Vec3::from(WORK) + origin + r * p;
    assert!(
        (dir - want_dir).norm() < DIR_TOLERANCE,
        "direction {dir:?}, want {want_dir:?}"
    );
    assert!(
        (tip - want_tip).norm() < TIP_TOLERANCE,
        "tip {tip:?}, want {want_tip:?} (off {})",
        (tip - want_tip).norm()
    );
}

fn fmt(v: f64) -> String {
    format!("{v:.6}")
}

// ----- the Euler forms, every order -------------------------------------------

#[test]
fn every_rotation_order_against_closed_form() {
    let m = machine(HEAD_90);
    let angles = [[30.0, -20.0, 50.0], [-65.0, 40.0, 15.0], [0.0, 0.0, 0.0]];
    for (form, orders) in [
        (0, [121, 131, 212, 232, 313, 323]),
        (1, [123, 132, 213, 231, 312, 321]),
    ] {
        for q in orders {
            for a in angles {
                let program = format!(
                    "{}G68.2 P{form} Q{q} X10 Y-20 Z30 I{} J{} K{} R25\nG53.1\nG1 X5 Y6 Z7 F1000\nM2\n",
                    prelude(),
                    a[0],
                    a[1],
                    a[2]
                );
                let segments = run_ok(&m, &program);
                let r = if form == 0 { euler(q, a) } else { fixed(q, a) } * rz(25.0);
                assert_on_plane(
                    &m,
                    &segments,
                    &r,
                    Vec3::new(10.0, -20.0, 30.0),
                    Vec3::new(5.0, 6.0, 7.0),
                );
            }
        }
    }
}

#[test]
fn default_orders_are_313_and_123() {
    let m = machine(HEAD_90);
    let a = [20.0, 35.0, -10.0];
    for (form, q) in [(0, 313), (1, 123)] {
        let program = format!(
            "{}G68.2 P{form} I20 J35 K-10\nG53.3 X1 Y2 Z3\nM2\n",
            prelude()
        );
        let segments = run_ok(&m, &program);
        let r = if form == 0 { euler(q, a) } else { fixed(q, a) };
        assert_on_plane(&m, &segments, &r, Vec3::zeros(), Vec3::new(1.0, 2.0, 3.0));
    }
    // P left out is P0.
    let program = format!("{}G68.2 I20 J35 K-10\nG53.3 X1 Y2 Z3\nM2\n", prelude());
    let segments = run_ok(&m, &program);
    assert_on_plane(
        &m,
        &segments,
        &euler(313, a),
        Vec3::zeros(),
        Vec3::new(1.0, 2.0, 3.0),
    );
}

/// The demos' plane `G68.2 X50 Y50 Z-50 Q121 I30 J15`, then `G53.3 X0 Y0
/// Z100` (lcnc_trsrn_simple_example.ngc), worked by hand: Q121 turns 30°
/// about X, then 15° about the turned Y: +Z of the plane is Rx(30)·Ry(15)·Z
/// = (sin 15°, −sin 30° cos 15°, cos 30° cos 15°).
#[test]
fn simple_example_by_hand() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G0 X0 Y0 Z100\nG68.2 X50 Y50 Z-50 Q121 I30 J15\nG53.3 X0 Y0 Z100\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let (s15, c15) = 15f64.to_radians().sin_cos();
    let z = Vec3::new(s15, -0.5 * c15, 0.75f64.sqrt() * c15);
    let (_, tip, dir) = end_pose(&m, &segments);
    assert!((dir - z).norm() < DIR_TOLERANCE, "{dir:?}");
    let want = Vec3::from(WORK) + Vec3::new(50.0, 50.0, -50.0) + 100.0 * z;
    assert!((tip - want).norm() < TIP_TOLERANCE, "{tip:?} {want:?}");
    // G53.3 is one rapid move.
    assert_eq!(segments.last().map(|s| s.motion), Some(Motion::Rapid));
}

// ----- between G68.2 and G53.x the program is untilted -------------------------

#[test]
fn definition_moves_nothing_and_the_program_stays_untilted_until_g53() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G0 X10 Y10 Z10\nG68.2 Q121 I30 J15 X5\nG0 X20 Y30 Z40\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    // G68.2 (line 5) makes no segment; the G0 after it is in the
    // untilted G54.
    assert!(segments.iter().all(|s| s.line != 5), "{segments:#?}");
    assert_eq!(segments.last().map(|s| s.line), Some(6));
    let (j, tip, dir) = end_pose(&m, &segments);
    assert!((dir - Vec3::z()).norm() < DIR_TOLERANCE);
    assert!((tip - (Vec3::from(WORK) + Vec3::new(20.0, 30.0, 40.0))).norm() < TIP_TOLERANCE);
    assert_eq!((j[3], j[4]), (0.0, 0.0));
}

#[test]
fn g53_1_turns_only_the_rotary_axes_and_switches_to_g59() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G0 X10 Y10 Z10\nG68.2 Q121 I30 J15\nG53.1\n#<ws> = #5220\n#<g59x> = #5321\nG0 X0 Y0 Z50\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let turn = &segments[segments.len() - 2];
    assert_eq!(turn.start[..3], turn.end[..3], "linear axes stand");
    assert_ne!(turn.start[3..5], turn.end[3..5]);
    let r = euler(121, [30.0, 15.0, 0.0]);
    assert_on_plane(&m, &segments, &r, Vec3::zeros(), Vec3::new(0.0, 0.0, 50.0));
    // #5220 reads 6 (G59) and G59 holds G54's offset.
    let program = format!(
        "{}G68.2 Q121 I30 J15\nG53.1\no1 if [#5220 NE 6]\n(abort, not G59)\no1 endif\no2 if [ABS[#5321 - {}] GT 0.000001]\n(abort, G59 X)\no2 endif\nG69\no3 if [#5220 NE 1]\n(abort, not G54)\no3 endif\nM2\n",
        prelude(),
        WORK[0]
    );
    let r = run(&m, &program);
    assert!(r.alarm.is_none(), "{:?}", r.alarm);
}

#[test]
fn g53_6_keeps_the_tip_while_the_head_turns() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G0 X10 Y-20 Z60\nG68.2 Q313 I40 J50 K-30\nG53.6\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let turn = segments.last().expect("the turn");
    let before = m.forward(&turn.start, TOOL).tip;
    for k in 0..=20 {
        let s = f64::from(k) / 20.0;
        let tip = m.forward(&turn.eval(&m, s), TOOL).tip;
        assert!(
            (tip - before).norm() < TIP_TOLERANCE,
            "s {s}: {tip:?} {before:?}"
        );
    }
    let dir = m.forward(&turn.end, TOOL).dir;
    let want = euler(313, [40.0, 50.0, -30.0]) * Vec3::z();
    assert!((dir - want).norm() < DIR_TOLERANCE);
}

#[test]
fn g53_3_axes_left_out_keep_the_tips_plane_coordinate() {
    let m = machine(HEAD_90);
    // Before: tip at (0, 0, 80) of G54 = the plane origin + 80 along +Z
    // of a plane turned about its own Z only (the +Z stays).
    let program = format!("{}G0 X0 Y0 Z80\nG68.2 Q313 I30\nG53.3 X10\nM2\n", prelude());
    let segments = run_ok(&m, &program);
    assert_on_plane(
        &m,
        &segments,
        &rz(30.0),
        Vec3::zeros(),
        Vec3::new(10.0, 0.0, 80.0),
    );
}

// ----- P strategies ---------------------------------------------------------------

/// The C angle after orienting to a plane that needs C at ±90° + k·360°.
fn c_after(m: &Machine, p: u32, start_c: f64) -> f64 {
    let program = format!(
        "{}G0 C{start_c}\nG68.2 P1 I30 K90\nG53.1 P{p}\nM2\n",
        prelude()
    );
    let segments = run_ok(m, &program);
    let (j, _, dir) = end_pose(m, &segments);
    let want = fixed(123, [30.0, 0.0, 90.0]) * Vec3::z();
    assert!((dir - want).norm() < DIR_TOLERANCE, "P{p}: {dir:?}");
    j[3]
}

#[test]
fn p_word_chooses_the_direction_of_the_primary_turn() {
    let m = machine(HEAD_90);
    for start in [0.0, 100.0, -250.0] {
        let shortest = c_after(&m, 0, start);
        let positive = c_after(&m, 1, start);
        let negative = c_after(&m, 2, start);
        assert!(
            positive >= start - 1e-9 && positive - start < 360.0,
            "{start}: {positive}"
        );
        assert!(
            negative <= start + 1e-9 && start - negative < 360.0,
            "{start}: {negative}"
        );
        assert!(
            (shortest - start).abs() <= 180.0 + 1e-9,
            "{start}: {shortest}"
        );
        assert!((shortest - start).abs() <= (positive - start).abs() + 1e-9);
        assert!((shortest - start).abs() <= (negative - start).abs() + 1e-9);
    }
    let text = alarm(&m, &format!("{}G68.2 I30\nG53.1 P3\nM2\n", prelude()));
    assert!(text.contains("FX0014") && text.contains("P3"), "{text}");
}

// ----- other machines ---------------------------------------------------------------

#[test]
fn nutating_head_reaches_the_plane_and_refuses_beyond_its_cone() {
    let m = machine(NUTATING_45);
    for (q, a) in [(121, [30.0, 15.0, 0.0]), (313, [70.0, 60.0, 10.0])] {
        let program = format!(
            "{}G68.2 Q{q} X5 Y6 Z7 I{} J{} K{}\nG53.1\nG1 X10 Y-5 Z20 F500\nG53.6\nG1 X0 Y0 Z50\nM2\n",
            prelude(),
            a[0],
            a[1],
            a[2]
        );
        let segments = run_ok(&m, &program);
        assert_on_plane(
            &m,
            &segments,
            &euler(q, a),
            Vec3::new(5.0, 6.0, 7.0),
            Vec3::new(0.0, 0.0, 50.0),
        );
    }
    // 120° from +Z: beyond the nutating head's 90°.
    let text = alarm(&m, &format!("{}G68.2 Q121 I120\nG53.1\nM2\n", prelude()));
    assert!(text.contains("FX0075"), "{text}");
}

#[test]
fn mixed_machine_orients_table_and_head() {
    let m = machine(MIXED);
    for a in [[30.0, 40.0, 0.0], [-100.0, -60.0, 20.0]] {
        let program = format!(
            "{}G68.2 P1 X3 Y4 Z5 I{} J{} K{} R-15\nG53.6\nG1 X1 Y2 Z3 F800\nG2 X-1 Y4 I-1 J1\nG0 X7 Y8 Z9\nM2\n",
            prelude(),
            a[0],
            a[1],
            a[2]
        );
        let segments = run_ok(&m, &program);
        let r = fixed(123, a) * rz(-15.0);
        assert_on_plane(
            &m,
            &segments,
            &r,
            Vec3::new(3.0, 4.0, 5.0),
            Vec3::new(7.0, 8.0, 9.0),
        );
    }
}

// ----- three points, two vectors -------------------------------------------------------

fn points_program(q0: Option<([f64; 3], f64)>, p: [[f64; 3]; 3], unit: &str) -> String {
    let mut s = format!("{}{unit}\n", prelude());
    if let Some((shift, r)) = q0 {
        s += &format!(
            "G68.2 P2 Q0 X{} Y{} Z{} R{}\n",
            fmt(shift[0]),
            fmt(shift[1]),
            fmt(shift[2]),
            fmt(r)
        );
    }
    for (k, point) in p.iter().enumerate() {
        s += &format!(
            "G68.2 P2 Q{} I{} J{} K{}\n",
            k + 1,
            fmt(point[0]),
            fmt(point[1]),
            fmt(point[2])
        );
    }
    s
}

#[test]
fn three_points_by_hand() {
    let m = machine(HEAD_90);
    // Points on the plane z = x (a plane tilted 45° about Y): +X from p1
    // to p2, +Y towards p3.
    let p = [[0.0, 0.0, 0.0], [100.0, 0.0, 100.0], [0.0, 50.0, 0.0]];
    let program =
        points_program(Some(([5.0, 0.0, 0.0], 90.0)), p, "G21") + "G53.1\nG1 X1 Y2 Z3 F100\nM2\n";
    let segments = run_ok(&m, &program);
    let s = 0.5f64.sqrt();
    let r = Matrix3::from_columns(&[
        Vec3::new(s, 0.0, s),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(-s, 0.0, s),
    ]) * rz(90.0);
    assert_on_plane(
        &m,
        &segments,
        &r,
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::new(1.0, 2.0, 3.0),
    );
}

#[test]
fn two_vectors_by_hand() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G68.2 P3 Q1 X1 Y2 Z3 I1 J0 K0.05 R10\nG68.2 P3 Q2 I0 J-1 K1\nG53.1\nG1 X4 Y5 Z6 F100\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let r = frame(Vec3::new(1.0, 0.0, 0.05), Vec3::new(0.0, -1.0, 1.0)) * rz(10.0);
    assert_on_plane(
        &m,
        &segments,
        &r,
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(4.0, 5.0, 6.0),
    );
}

// ----- the README's errors -------------------------------------------------------------

#[test]
fn readme_errors() {
    let m = machine(HEAD_90);
    let p = prelude();
    let cases: Vec<(String, &str, &str)> = vec![
        // P2 blocks not consecutive.
        (
            format!("{p}G68.2 P2 Q1 I0 J0 K0\nG0 X1\nM2\n"),
            "FX0152",
            "Q2",
        ),
        (
            format!("{p}G68.2 P2 Q1 I0 J0 K0\nG68.2 P2 Q3 I0 J50 K0\nM2\n"),
            "FX0152",
            "out of order",
        ),
        // Two points the same.
        (
            points_program(None, [[0.0; 3], [50.0, 0.0, 0.0], [50.0, 0.0, 0.0]], "G21"),
            "FX0152",
            "same point",
        ),
        // Three points on a line.
        (
            points_program(None, [[0.0; 3], [50.0, 0.0, 0.0], [100.0, 0.0, 0.0]], "G21"),
            "FX0152",
            "one line",
        ),
        // A point 5 mm from the line through the others.
        (
            points_program(None, [[0.0; 3], [100.0, 0.0, 0.0], [50.0, 5.0, 0.0]], "G21"),
            "FX0152",
            "10 mm",
        ),
        // 0.4 inch in G20.
        (
            points_program(None, [[0.0; 3], [4.0, 0.0, 0.0], [2.0, 0.4, 0.0]], "G20"),
            "FX0152",
            "0.5 inch",
        ),
        // P3 not consecutive, a zero vector, an angle outside 85–95°.
        (
            format!("{p}G68.2 P3 Q1 I1 J0 K0\nG1 X0 F100\nM2\n"),
            "FX0152",
            "Q2",
        ),
        (
            format!("{p}G68.2 P3 Q1 I0 J0 K0\nM2\n"),
            "FX0152",
            "zero vector",
        ),
        (
            format!("{p}G68.2 P3 Q1 I1 J0 K0\nG68.2 P3 Q2 I0 J0 K0\nM2\n"),
            "FX0152",
            "zero vector",
        ),
        (
            format!("{p}G68.2 P3 Q1 I1 J0 K0\nG68.2 P3 Q2 I0.18 J0 K1\nM2\n"),
            "FX0152",
            "85 to 95",
        ),
        (
            format!("{p}G68.2 P3 Q1 I1 J0 K0\nG68.2 P3 Q2 I-0.18 J0 K1\nM2\n"),
            "FX0152",
            "85 to 95",
        ),
        // G68.4 with no plane defined.
        (format!("{p}G68.4 I10\nM2\n"), "FX0150", "no tilted"),
        // A plane is defined only in G54.
        (format!("{p}G55\nG68.2 I10\nM2\n"), "FX0150", "G54"),
        (
            format!("{p}G68.2 I10\nG53.1\nG68.2 I20\nM2\n"),
            "FX0150",
            "G69",
        ),
        (format!("{p}G68.2 I10\nG53.1\nG68.3\nM2\n"), "FX0150", "G54"),
        // G53.x without a plane.
        (format!("{p}G53.1\nM2\n"), "FX0150", "defined first"),
        (format!("{p}G53.6 P1\nM2\n"), "FX0150", "defined first"),
        // Orders that are not of the form.
        (format!("{p}G68.2 Q123 I10\nM2\n"), "FX0152", "Q121"),
        (format!("{p}G68.2 P1 Q313 I10\nM2\n"), "FX0152", "Q123"),
        (format!("{p}G68.2 P4 I10\nM2\n"), "FX0152", "P3"),
        // Group 1: not with G0 / G1 in one block.
        (format!("{p}G0 G68.2 I10\nM2\n"), "FX0015", "modal group 1"),
        (format!("{p}G68.2 I10\nG1 G53.1 F100\nM2\n"), "FX0015", ""),
        // In the oriented plane the work offset stays G59.
        (format!("{p}G68.2 I10\nG53.1\nG54\nM2\n"), "FX0150", ""),
        // G53.1 takes no axis words.
        (format!("{p}G68.2 I10\nG53.1 X5\nM2\n"), "FX0012", ""),
    ];
    let mut failures = Vec::new();
    for (program, code, text) in cases {
        match run(&m, &program).alarm {
            Some(a) if a.contains(code) && a.contains(text) => {}
            other => failures.push(format!("{program}\n  want {code} {text:?}, got {other:?}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // 0.6 inch is far enough.
    run_ok(
        &m,
        &(points_program(None, [[0.0; 3], [4.0, 0.0, 0.0], [2.0, 0.6, 0.0]], "G20") + "M2\n"),
    );
    // 86° and 94° are square enough.
    for k in ["0.07", "-0.07"] {
        run_ok(
            &m,
            &format!("{p}G68.2 P3 Q1 I1 J0 K0\nG68.2 P3 Q2 I{k} J0 K1\nG53.1\nM2\n"),
        );
    }
}

#[test]
fn without_the_remap_the_codes_are_unknown() {
    let text = HEAD_90.replace("twp_remap = true", "");
    let m = machine(&text);
    for code in ["G68.2 I10", "G68.3", "G68.4 I10", "G53.1", "G53.6"] {
        let program = format!("{}{code}\nM2\n", prelude());
        let a = alarm(&m, &program);
        assert!(a.contains("FX0010"), "{code}: {a}");
    }
    // The key is LinuxCNC's.
    let fanuc = HEAD_90.replace("control = \"linuxcnc\"", "control = \"fanuc30i\"");
    let e = Machine::from_toml(&fanuc).expect_err("refused");
    assert_eq!(e.key.as_deref(), Some("twp_remap"), "{e}");
}

#[test]
fn g69_cancels_without_motion_and_back_in_g54() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G68.2 Q121 I30 J15 X7\nG53.1\nG0 X1 Y2 Z3\nG69\nG0 X4 Y5 Z6\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let g69_line = 7;
    assert!(segments.iter().all(|s| s.line != g69_line));
    // After G69 the program is in G54 again with identity kinematics:
    // the axes are the programmed point plus the offset and the tool
    // length along Z (LinuxCNC G43); the head stays.
    let (j, _, dir) = end_pose(&m, &segments);
    let want_axes = Vec3::from(WORK) + Vec3::new(4.0, 5.0, 6.0 + TOOL);
    assert!(
        (Vec3::new(j[0], j[1], j[2]) - want_axes).norm() < TIP_TOLERANCE,
        "{j:?}"
    );
    let want = euler(121, [30.0, 15.0, 0.0]) * Vec3::z();
    assert!((dir - want).norm() < DIR_TOLERANCE);
    // G68.4 after G69 has no plane.
    let program = format!("{}G68.2 I10\nG69\nG68.4 I5\nM2\n", prelude());
    assert!(alarm(&m, &program).contains("FX0150"));
}

#[test]
fn g68_3_takes_the_tool_axis() {
    let m = machine(HEAD_90);
    // Tilt the head by hand, then define the plane from the tool axis.
    let program = format!(
        "{}G0 C30 A40\nG68.3 X1 Y2 Z3 R15\nG53.1\nG1 X4 Y5 Z6 F100\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let mut j = [0.0; fiveaxis_machine::MAX_AXES];
    j[3] = 30.0;
    j[4] = 40.0;
    let z = m.forward(&j, 0.0).dir;
    // FANUC's +X: vertical × tool axis.
    let x = Vec3::z().cross(&z);
    let r = frame(x, z) * rz(15.0);
    assert_on_plane(
        &m,
        &segments,
        &r,
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(4.0, 5.0, 6.0),
    );
}

// ----- G68.4 repeated -----------------------------------------------------------------

/// The demos' loop `o100 repeat [100] g68.4 q131 i35 j35 k0 g53.6 …` with
/// an origin shift: after 100 turns the plane is the product of the 100
/// rotations and the origin the sum of the shifts each in its plane.
#[test]
fn g68_4_one_hundred_times_is_the_product() {
    let m = machine(HEAD_90);
    let program = format!(
        "{}G68.2 Q121 I25 J-10\nG53.1\no100 repeat [100]\nG68.4 X2 Q131 I35 J35 K0\nG53.6\nG0 X50 Y50 Z100\no100 endrepeat\nM2\n",
        prelude()
    );
    let segments = run_ok(&m, &program);
    let mut r = euler(121, [25.0, -10.0, 0.0]);
    let mut origin = Vec3::zeros();
    let step = euler(131, [35.0, 35.0, 0.0]);
    for _ in 0..100 {
        origin += r * Vec3::new(2.0, 0.0, 0.0);
        r *= step;
    }
    assert_on_plane(&m, &segments, &r, origin, Vec3::new(50.0, 50.0, 100.0));
}

// ----- seeded random planes ---------------------------------------------------------------

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x7A1D_2026),
        failure_persistence: None,
        ..Config::default()
    }
}

fn angle() -> impl Strategy<Value = f64> {
    -180.0..180.0f64
}

fn coord() -> impl Strategy<Value = f64> {
    -200.0..200.0f64
}

#[test]
fn random_euler_planes() {
    let m = machine(HEAD_90);
    let orders = [
        (0u32, 121u32),
        (0, 131),
        (0, 212),
        (0, 232),
        (0, 313),
        (0, 323),
        (1, 123),
        (1, 132),
        (1, 213),
        (1, 231),
        (1, 312),
        (1, 321),
    ];
    common::check(
        config(120),
        (
            0..orders.len(),
            [angle(), angle(), angle(), angle()],
            [coord(), coord(), coord()],
            [coord(), coord(), coord()],
            0..3u32,
        ),
        |(o, a, origin, p, how)| {
            let (form, q) = orders[o];
            let code = ["G53.1", "G53.6", "G53.3 X0 Y0 Z0"][how as usize];
            let program = format!(
                "{}G68.2 P{form} Q{q} X{} Y{} Z{} I{} J{} K{} R{}\n{code}\nG1 X{} Y{} Z{} F2000\nM2\n",
                prelude(),
                fmt(origin[0]),
                fmt(origin[1]),
                fmt(origin[2]),
                fmt(a[0]),
                fmt(a[1]),
                fmt(a[2]),
                fmt(a[3]),
                fmt(p[0]),
                fmt(p[1]),
                fmt(p[2])
            );
            let r = run(&m, &program);
            prop_assert!(r.alarm.is_none(), "{:?}\n{program}", r.alarm);
            let round = |v: f64| fmt(v).parse::<f64>().expect("a number");
            let a = a.map(round);
            let rot = if form == 0 {
                euler(q, [a[0], a[1], a[2]])
            } else {
                fixed(q, [a[0], a[1], a[2]])
            } * rz(a[3]);
            let (_, tip, dir) = end_pose(&m, &r.segments);
            let want_dir = rot * Vec3::z();
            let want_tip =
                Vec3::from(WORK) + Vec3::from(origin.map(round)) + rot * Vec3::from(p.map(round));
            prop_assert!(
                (dir - want_dir).norm() < DIR_TOLERANCE,
                "{dir:?} {want_dir:?}"
            );
            prop_assert!(
                (tip - want_tip).norm() < TIP_TOLERANCE,
                "{tip:?} {want_tip:?}"
            );
            Ok(())
        },
    );
}

#[test]
fn random_point_and_vector_planes() {
    let m = machine(MIXED);
    common::check(
        config(80),
        (
            [coord(), coord(), coord()],
            [coord(), coord(), coord()],
            [coord(), coord(), coord()],
            [coord(), coord(), coord()],
            angle(),
        ),
        |(p1, p2, p3, p, turn)| {
            let round = |v: f64| fmt(v).parse::<f64>().expect("a number");
            let [a, b, c] = [p1, p2, p3].map(|v| Vec3::from(v.map(round)));
            let least = [(b, c, a), (a, c, b), (a, b, c)]
                .iter()
                .map(|(u, v, w)| (w - u).cross(&(v - u)).norm() / (v - u).norm())
                .fold(f64::INFINITY, f64::min);
            prop_assume!(least > 10.0);
            let x = b - a;
            let z = x.cross(&(c - a));
            let r = frame(x, z) * rz(round(turn));
            // The plane's +Z may face down: the mixed machine's B reaches
            // 120°; skip the directions it cannot reach.
            prop_assume!((r * Vec3::z()).z > -0.45);
            let program = points_program(Some(([0.0; 3], turn)), [p1, p2, p3], "G21")
                + &format!("G53.3 X{} Y{} Z{}\nM2\n", fmt(p[0]), fmt(p[1]), fmt(p[2]));
            let run1 = run(&m, &program);
            prop_assert!(run1.alarm.is_none(), "{:?}\n{program}", run1.alarm);
            let (_, tip, dir) = end_pose(&m, &run1.segments);
            let want_tip = Vec3::from(WORK) + a + r * Vec3::from(p.map(round));
            prop_assert!((dir - r * Vec3::z()).norm() < DIR_TOLERANCE);
            prop_assert!(
                (tip - want_tip).norm() < TIP_TOLERANCE,
                "{tip:?} {want_tip:?}"
            );
            // The same plane by two vectors (+X, +Z) from the origin a.
            let program = format!(
                "{}G68.2 P3 Q1 X{} Y{} Z{} I{} J{} K{} R{}\nG68.2 P3 Q2 I{} J{} K{}\nG53.3 X{} Y{} Z{}\nM2\n",
                prelude(),
                fmt(a.x),
                fmt(a.y),
                fmt(a.z),
                fmt(x.x),
                fmt(x.y),
                fmt(x.z),
                fmt(turn),
                fmt(z.x),
                fmt(z.y),
                fmt(z.z),
                fmt(p[0]),
                fmt(p[1]),
                fmt(p[2])
            );
            let run2 = run(&m, &program);
            prop_assert!(run2.alarm.is_none(), "{:?}\n{program}", run2.alarm);
            let (_, tip, dir) = end_pose(&m, &run2.segments);
            prop_assert!((dir - r * Vec3::z()).norm() < DIR_TOLERANCE);
            prop_assert!(
                (tip - want_tip).norm() < TIP_TOLERANCE,
                "{tip:?} {want_tip:?}"
            );
            Ok(())
        },
    );
}

// ----- three rotary axes ------------------------------------------------------------

/// LinuxCNC's xyzbca-trsrn: B rotary table, C spindle rotary (primary),
/// A nutating (secondary, nutation ν from Z towards X). Built in code: the
/// machine file holds at most two rotary axes until the "chain" work
/// lifts it.
fn trsrn(nutation: f64) -> Machine {
    let mut m = machine(HEAD_90);
    let (s, c) = nutation.to_radians().sin_cos();
    m.rotary[1].axis = nalgebra::Unit::new_normalize(Vec3::new(s, 0.0, c));
    let mut table = m.rotary[0].clone();
    table.name = 'B';
    table.on = fiveaxis_machine::Side::Table;
    table.axis = nalgebra::Unit::new_normalize(Vec3::y());
    table.center = Vec3::new(0.0, 0.0, -50.0);
    table.limits = Some((-360.0, 360.0));
    m.rotary.insert(0, table);
    m.linear.truncate(3);
    m
}

#[test]
fn three_rotary_machine_turns_the_head_pair_with_the_table_held() {
    for nutation in [90.0, 60.0] {
        let m = trsrn(nutation);
        for b in [0.0, 25.0] {
            let program = format!(
                "{}G0 B{b}\nG68.2 Q121 I30 J15 X5\nG53.6\nG1 X1 Y2 Z3 F500\nG68.4 Q131 I-10 J20\nG53.3 X0 Y0 Z40\nM2\n",
                prelude()
            );
            let segments = run_ok(&m, &program);
            let (j, _, _) = end_pose(&m, &segments);
            assert!((j[3] - b).abs() < 1e-12, "the table holds: {j:?}");
            let r = euler(121, [30.0, 15.0, 0.0]) * euler(131, [-10.0, 20.0, 0.0]);
            assert_on_plane(
                &m,
                &segments,
                &r,
                Vec3::new(5.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 40.0),
            );
        }
    }
}

#[test]
fn machine_file_keys() {
    // Written back and read again.
    let text = HEAD_90.replace("twp_remap = true", "twp_remap = true\ntwp_priority = 2");
    let m = machine(&text);
    assert!(m.params.twp_remap);
    assert_eq!(m.params.twp_priority, 2);
    let again = Machine::from_toml(&m.to_toml()).expect("the written file reads");
    assert_eq!(again.params, m.params);
    // twp_priority is 1 or 2.
    let e = Machine::from_toml(
        &HEAD_90.replace("twp_remap = true", "twp_remap = true\ntwp_priority = 3"),
    )
    .expect_err("refused");
    assert_eq!(e.key.as_deref(), Some("twp_priority"), "{e}");
    // Two rotary axes at least.
    let one = HEAD_90
        .split("[[rotary]]\nname = \"A\"")
        .next()
        .expect("text")
        .to_owned()
        + "[parameters]\ntwp_remap = true\n";
    let e = Machine::from_toml(&one).expect_err("refused");
    assert_eq!(e.key.as_deref(), Some("twp_remap"), "{e}");
}

/// The secondary axis prioritized: its P direction holds.
#[test]
fn twp_priority_2_steers_the_secondary() {
    let text = HEAD_90.replace("twp_remap = true", "twp_remap = true\ntwp_priority = 2");
    let m = machine(&text);
    for (p, positive) in [(1, true), (2, false)] {
        let program = format!("{}G0 A10\nG68.2 P1 I30\nG53.1 P{p}\nM2\n", prelude());
        let segments = run_ok(&m, &program);
        let (j, _, dir) = end_pose(&m, &segments);
        assert!((dir - rx(30.0) * Vec3::z()).norm() < DIR_TOLERANCE);
        if positive {
            assert!(j[4] >= 10.0 - 1e-9, "{j:?}");
        } else {
            assert!(j[4] <= 10.0 + 1e-9, "{j:?}");
        }
    }
}

/// Random sequences of the TWP codes with wild values: every run ends
/// (an alarm or the end), never a panic, and every segment is finite.
#[test]
fn random_twp_programs_never_panic() {
    let machines = [
        machine(HEAD_90),
        machine(NUTATING_45),
        machine(MIXED),
        trsrn(50.0),
    ];
    let value = prop_oneof![
        -400.0..400.0f64,
        Just(0.0),
        Just(1e30),
        Just(-1e200),
        Just(90.0),
        Just(180.0)
    ];
    let template = 0..17usize;
    let line = (
        template,
        [value.clone(), value.clone(), value.clone(), value.clone()],
        0..4u32,
    );
    common::check(
        config(300),
        (0..machines.len(), proptest::collection::vec(line, 1..12)),
        |(mi, lines)| {
            let m = &machines[mi];
            let mut program = prelude();
            for (t, v, q) in lines {
                let [a, b, c, d] = v.map(fmt);
                program += &match t {
                    0 => format!(
                        "G68.2 Q{} I{a} J{b} K{c} R{d}\n",
                        [121, 131, 313, 323][q as usize]
                    ),
                    1 => format!(
                        "G68.2 P1 Q{} X{a} I{b} J{c} K{d}\n",
                        [123, 132, 312, 321][q as usize]
                    ),
                    2 => format!("G68.2 P2 Q{q} I{a} J{b} K{c}\n"),
                    3 => format!("G68.2 P3 Q{} X{a} I{b} J{c} K{d}\n", q % 3),
                    4 => format!("G68.3 X{a} R{b}\n"),
                    5 => format!("G68.4 Q131 I{a} J{b} X{c}\n"),
                    6 => format!("G53.1 P{}\n", q % 3),
                    7 => format!("G53.3 X{a} Y{b} Z{c}\n"),
                    8 => format!("G53.6 P{q}\n"),
                    9 => "G69\n".into(),
                    10 => format!("G0 X{a} Y{b} Z{c}\n"),
                    11 => format!(
                        "G1 X{a} Y{b} F{}\n",
                        fmt(d.parse::<f64>().map_or(100.0, f64::abs) + 1.0)
                    ),
                    12 => format!("G2 X{a} Y{b} I{c} F500\n"),
                    13 => format!("G52 X{a}\n"),
                    14 => format!("G10 L2 P0 X{a} Y{b}\n"),
                    15 => "G55\n".into(),
                    _ => "G54\n".into(),
                };
            }
            program += "M2\n";
            let r = run(m, &program);
            for seg in &r.segments {
                for s in [0.0, 0.5, 1.0] {
                    let j = seg.eval(m, s);
                    prop_assert!(j.iter().all(|x| x.is_finite()), "{j:?}\n{program}");
                }
            }
            Ok(())
        },
    );
}
