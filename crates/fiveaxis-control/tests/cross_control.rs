//! One part, three controls: the same machining programmed in FANUC
//! (G68.2 + G53.1, G43.5 with I J K, G52 + G68), SINUMERIK (CYCLE800,
//! TRAORI with A3= B3= C3=, TRANS + AROT) and HEIDENHAIN Klartext
//! (PLANE SPATIAL … TURN / STAY, M128 + LN, cycles 7 and 10) on the same
//! machine kinematics gives the same machine positions, within 1e-9 mm
//! or degrees.
//!
//! The machine is the built-in `heidenhain-dmu-ac` (A/C swivelling
//! table, A −120 … +30, C endless) at machine zero, cloned with
//! `control` = FANUC 30i, SINUMERIK and HEIDENHAIN. Every control uses
//! the same offsets file: tool 1, 100 mm (FANUC `H1`, SINUMERIK `T1 D1`,
//! HEIDENHAIN `TOOL CALL 1 Z`), and G54 (HEIDENHAIN preset 0) at
//! X0 Y0 Z−400.
//!
//! Conventions the programs rely on: FANUC G68.2 I J K are Euler angles
//! Z, X′, Z″ (R = Rz(I)·Rx(J)·Rz(K)); CYCLE800 mode 57 turns about X,
//! then the turned Y, then the turned Z (R = Rx(A)·Ry(B)·Rz(C));
//! PLANE SPATIAL turns about the fixed X, then Y, then Z
//! (R = Rz(SPC)·Ry(SPB)·Rx(SPA)). A plane turned about X alone is the
//! same R in all three. Where the table reaches the plane two ways,
//! SINUMERIK `_DIR` −1 and HEIDENHAIN `SEQ-` pick the lower A; A = +45°
//! is beyond the A travel, so FANUC's choice is the same one.
//!
//! Each fixture also checks the result by forward kinematics, so that
//! three controls agreeing on a wrong answer do not pass.

mod common;

use common::{builtin_at_zero, run_ends};
use fiveaxis_control::Row;
use fiveaxis_machine::{Control, Machine, Offsets, ToolOffset, Vec3};

const JOINT_EPS: f64 = 1e-9;
const LENGTH: f64 = 100.0;

fn work() -> Vec3 {
    Vec3::new(0.0, 0.0, -400.0)
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: LENGTH,
            ..ToolOffset::default()
        },
    );
    o.work[0] = work();
    o
}

fn machine(control: Control) -> Machine {
    let mut m = builtin_at_zero("heidenhain-dmu-ac").expect("built-in");
    m.control = control;
    m
}

/// The rows at the end of every segment of `program` on the machine with
/// `control`.
fn ends(control: Control, program: &str) -> Vec<Row> {
    let m = machine(control);
    let (rows, alarm) = run_ends(&m, offsets(), program);
    assert!(alarm.is_none(), "{control:?}: {alarm:?}\n{program}");
    rows
}

/// Where the machine stands after line `line` (the end of the last
/// segment up to it).
fn after(rows: &[Row], line: u32) -> [f64; 5] {
    let r = rows
        .iter()
        .rev()
        .find(|r| r.line <= line)
        .unwrap_or_else(|| panic!("no segment up to line {line}"));
    let mut j = [0.0; 5];
    j.copy_from_slice(&r.joints[..5]);
    j
}

fn same(what: &str, a: [f64; 5], b: [f64; 5]) {
    for k in 0..5 {
        assert!(
            (a[k] - b[k]).abs() <= JOINT_EPS,
            "{what}: axis {k}: {a:?} ≠ {b:?}"
        );
    }
}

/// The tip (relative to G54) and tool direction of machine position `j`.
fn pose(j: [f64; 5]) -> (Vec3, Vec3) {
    let m = machine(Control::Heidenhain);
    let mut joints = [0.0; fiveaxis_machine::MAX_AXES];
    joints[..5].copy_from_slice(&j);
    let p = m.forward(&joints, LENGTH);
    (p.tip - work(), p.dir)
}

fn rx(deg: f64) -> nalgebra::Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    nalgebra::Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn rz(deg: f64) -> nalgebra::Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    nalgebra::Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

// ----- 3+2: a hole position in a tilted plane ----------------------------------

/// The plane turned −45° about X (its Z is (0, sin 45°, cos 45°)), the
/// tool to X10 Y20 Z5 of the plane, then to Z−5 (the hole's bottom).
#[test]
fn tilted_plane_drilling_position() {
    let fanuc = "G90 G54 G17\nG43 H1 G0 Z100.\nG68.2 X0 Y0 Z0 I0 J-45. K0\nG53.1\n\
                 G0 X10. Y20. Z5.\nG1 Z-5. F100.\nM30\n";
    let sinumerik = "T1 D1\nG54 G17 G90\nG0 Z100\nCYCLE800(0,\"TC1\",0,57,0,0,0,-45,0,0,0,0,0,-1)\n\
                     G0 X10 Y20 Z5\nG1 Z-5 F100\nM30\n";
    let turn = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                PLANE SPATIAL SPA-45 SPB+0 SPC+0 TURN FMAX SEQ-\n\
                L X+10 Y+20 Z+5 FMAX\nL Z-5 F100\nEND PGM P MM\n";
    let stay = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                PLANE SPATIAL SPA-45 SPB+0 SPC+0 STAY SEQ-\nL A+Q120 C+Q122 R0 FMAX\n\
                L X+10 Y+20 Z+5 FMAX\nL Z-5 F100\nEND PGM P MM\n";
    let f = ends(Control::Fanuc30i, fanuc);
    let s = ends(Control::Sinumerik, sinumerik);
    let h = ends(Control::Heidenhain, turn);
    let hs = ends(Control::Heidenhain, stay);
    // The point above the hole, then its bottom.
    let r = rx(-45.0);
    for (fl, sl, hl, hsl, p) in [
        (5, 5, 5, 6, Vec3::new(10.0, 20.0, 5.0)),
        (6, 6, 6, 7, Vec3::new(10.0, 20.0, -5.0)),
    ] {
        let want = after(&f, fl);
        same("SINUMERIK / FANUC", after(&s, sl), want);
        same("HEIDENHAIN TURN / FANUC", after(&h, hl), want);
        same("HEIDENHAIN STAY / FANUC", after(&hs, hsl), want);
        // Why: the tip at R·P, the tool along R·ez, A = −45°.
        let (tip, dir) = pose(want);
        assert!((tip - r * p).norm() < 1e-9, "tip {tip:?}");
        assert!((dir - r * Vec3::z()).norm() < 1e-9, "dir {dir:?}");
        assert!((want[3] + 45.0).abs() < 1e-9, "{want:?}");
    }
}

// ----- simultaneous 5-axis: tool vectors --------------------------------------

/// Tool vectors made by forward kinematics from table positions (A, C);
/// the tip runs through three points with the vector of each.
#[test]
fn five_axis_path_by_tool_vectors() {
    let m = machine(Control::Heidenhain);
    let positions = [[-10.0, 20.0], [-25.0, 35.0], [-40.0, 10.0]];
    let points = [
        Vec3::new(10.0, 0.0, 5.0),
        Vec3::new(20.0, 10.0, 0.0),
        Vec3::new(30.0, -5.0, -2.0),
    ];
    // FANUC: no I J K in the G43.5 block on a table machine (PS5421).
    let mut fanuc = String::from("G90 G54 G17\nG0 X0 Y0 Z100.\nG1 G43.5 H1 X0 Y0 Z100. F1000.\n");
    let mut sinumerik = String::from("T1 D1\nG54 G17 G90\nG0 X0 Y0 Z100\nTRAORI\n");
    let mut klartext =
        String::from("BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL X+0 Y+0 Z+100 R0 FMAX\nM128\n");
    let mut dirs = Vec::new();
    for (q, p) in positions.iter().zip(points) {
        let mut j = [0.0; fiveaxis_machine::MAX_AXES];
        j[3] = q[0];
        j[4] = q[1];
        let d = m.forward(&j, 0.0).dir;
        let t = [d.x, d.y, d.z].map(|c| format!("{c:.12}"));
        fanuc.push_str(&format!(
            "G1 X{:.3} Y{:.3} Z{:.3} I{} J{} K{} F1000.\n",
            p.x, p.y, p.z, t[0], t[1], t[2]
        ));
        sinumerik.push_str(&format!(
            "G1 X{:.3} Y{:.3} Z{:.3} A3={} B3={} C3={} F1000\n",
            p.x, p.y, p.z, t[0], t[1], t[2]
        ));
        let s = [d.x, d.y, d.z].map(|c| format!("{c:+.12}"));
        klartext.push_str(&format!(
            "LN X{:+.3} Y{:+.3} Z{:+.3} TX{} TY{} TZ{} R0 F1000\n",
            p.x, p.y, p.z, s[0], s[1], s[2]
        ));
        dirs.push((
            p,
            Vec3::new(
                t[0].parse().unwrap(),
                t[1].parse().unwrap(),
                t[2].parse().unwrap(),
            ),
        ));
    }
    klartext.push_str("END PGM P MM\n");
    let f = ends(Control::Fanuc30i, &fanuc);
    let s = ends(Control::Sinumerik, &sinumerik);
    let h = ends(Control::Heidenhain, &klartext);
    for (k, (p, d)) in dirs.iter().enumerate() {
        let k = k as u32;
        let want = after(&f, 4 + k);
        same("SINUMERIK / FANUC", after(&s, 5 + k), want);
        same("HEIDENHAIN / FANUC", after(&h, 5 + k), want);
        // Why: the tip on the point, the tool along the vector.
        let (tip, dir) = pose(want);
        assert!((tip - p).norm() < 1e-9, "tip {tip:?} want {p:?}");
        assert!((dir - d.normalize()).norm() < 1e-9, "dir {dir:?}");
    }
}

// ----- datum shift and rotation --------------------------------------------------

/// A shift to (10, 5) and a rotation of 30° about it: FANUC G52 + G68,
/// SINUMERIK TRANS + AROT, HEIDENHAIN cycles 7 and 10.
#[test]
fn datum_shift_and_rotation() {
    let fanuc = "G90 G54 G17\nG43 H1 G0 Z100.\nG52 X10. Y5.\nG68 X0 Y0 R30.\n\
                 G0 X20. Y0 Z5.\nG1 X20. Y10. F100.\nM30\n";
    let sinumerik = "T1 D1\nG54 G17 G90\nG0 Z100\nTRANS X10 Y5\nAROT Z30\n\
                     G0 X20 Y0 Z5\nG1 X20 Y10 F100\nM30\n";
    let klartext = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                    CYCL DEF 7.0 DATUM SHIFT\nCYCL DEF 7.1 X+10\nCYCL DEF 7.2 Y+5\n\
                    CYCL DEF 10.0 ROTATION\nCYCL DEF 10.1 ROT+30\n\
                    L X+20 Y+0 Z+5 FMAX\nL X+20 Y+10 F100\nEND PGM P MM\n";
    let f = ends(Control::Fanuc30i, fanuc);
    let s = ends(Control::Sinumerik, sinumerik);
    let h = ends(Control::Heidenhain, klartext);
    for (fl, sl, hl, p) in [
        (5, 6, 9, Vec3::new(20.0, 0.0, 5.0)),
        (6, 7, 10, Vec3::new(20.0, 10.0, 5.0)),
    ] {
        let want = after(&f, fl);
        same("SINUMERIK / FANUC", after(&s, sl), want);
        same("HEIDENHAIN / FANUC", after(&h, hl), want);
        // Why: the tip at (10, 5, 0) + Rz(30°)·P.
        let (tip, _) = pose(want);
        let w = Vec3::new(10.0, 5.0, 0.0) + rz(30.0) * p;
        assert!((tip - w).norm() < 1e-9, "tip {tip:?} want {w:?}");
    }
}
