//! One part, three controls: the same machining programmed in FANUC
//! (G68.2 + G53.1, G43.5 with I J K, G52 + G68), SINUMERIK (CYCLE800,
//! TRAORI with A3= B3= C3=, TRANS + AROT) and HEIDENHAIN Klartext
//! (PLANE SPATIAL … TURN / STAY, M128 + LN, cycles 7 and 10) on the same
//! machine kinematics gives the same machine positions, within 1e-9 mm
//! or degrees.
//!
//! Machines: the built-in `heidenhain-dmu-ac` (A/C swivelling table,
//! A −120 … +30, C endless) and `head-table-bc` (B head −110 … 110, C
//! table), at machine zero, each cloned with `control` = FANUC 30i,
//! SINUMERIK and HEIDENHAIN. Every control uses the same offsets file:
//! tool 1, 100 mm (FANUC `H1`, SINUMERIK `T1 D1`, HEIDENHAIN
//! `TOOL CALL 1 Z`), and G54 (HEIDENHAIN preset 0) low enough for the
//! machine's Z travel.
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

/// A machine by built-in name and the G54 used on it.
#[derive(Clone, Copy)]
struct Setup {
    name: &'static str,
    work: [f64; 3],
}

/// The A/C table; G54 low enough for its Z travel (−650 … 0).
const DMU: Setup = Setup {
    name: "heidenhain-dmu-ac",
    work: [0.0, 0.0, -400.0],
};

/// B head (−110° … 110°) and C table; Z travel −300 … 500.
const HEAD_TABLE: Setup = Setup {
    name: "head-table-bc",
    work: [0.0, 0.0, -150.0],
};

fn offsets_for(setup: Setup) -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: LENGTH,
            ..ToolOffset::default()
        },
    );
    o.work[0] = Vec3::new(setup.work[0], setup.work[1], setup.work[2]);
    o
}

fn machine_for(setup: Setup, control: Control) -> Machine {
    let mut m = builtin_at_zero(setup.name).expect("built-in");
    m.control = control;
    m
}

/// The rows at the end of every segment of `program` on `setup` with
/// `control`.
fn ends_on(setup: Setup, control: Control, program: &str) -> Vec<Row> {
    let m = machine_for(setup, control);
    let (rows, alarm) = run_ends(&m, offsets_for(setup), program);
    assert!(
        alarm.is_none(),
        "{} {control:?}: {alarm:?}\n{program}",
        setup.name
    );
    rows
}

/// The tip (relative to G54) and tool direction of machine position `j`
/// on `setup`, by forward kinematics.
fn pose_on(setup: Setup, j: [f64; 5]) -> (Vec3, Vec3) {
    let m = machine_for(setup, Control::Heidenhain);
    let mut joints = [0.0; fiveaxis_machine::MAX_AXES];
    joints[..5].copy_from_slice(&j);
    let p = m.forward(&joints, LENGTH);
    let w = Vec3::new(setup.work[0], setup.work[1], setup.work[2]);
    (p.tip - w, p.dir)
}

fn machine(control: Control) -> Machine {
    machine_for(DMU, control)
}

fn ends(control: Control, program: &str) -> Vec<Row> {
    ends_on(DMU, control, program)
}

fn pose(j: [f64; 5]) -> (Vec3, Vec3) {
    pose_on(DMU, j)
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
                t[0].parse().expect("a written number"),
                t[1].parse().expect("a written number"),
                t[2].parse().expect("a written number"),
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

fn ry(deg: f64) -> nalgebra::Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    nalgebra::Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

// ----- 3+2 on a head / table machine ----------------------------------------------

/// On the B head / C table: the plane turned 30° about Y (Z along
/// (sin 30°, 0, cos 30°)). FANUC: Rz(90°)·Rx(30°)·Rz(−90°) is that turn
/// about Y (I90 J30 K−90); SINUMERIK mode 57 B30; HEIDENHAIN SPB+30. The
/// head reaches it with B +30° (C 0) or B −30° (C 180°): `_DIR` +1 and
/// `SEQ+` pick the higher B, as FANUC's choice is checked to.
#[test]
fn tilted_plane_drilling_position_on_a_head() {
    let fanuc = "G90 G54 G17\nG43 H1 G0 Z100.\nG68.2 X0 Y0 Z0 I90. J30. K-90.\nG53.1\n\
                 G0 X10. Y20. Z5.\nG1 Z-5. F100.\nM30\n";
    let sinumerik = "T1 D1\nG54 G17 G90\nG0 Z100\nCYCLE800(0,\"TC1\",0,57,0,0,0,0,30,0,0,0,0,1)\n\
                     G0 X10 Y20 Z5\nG1 Z-5 F100\nM30\n";
    let turn = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                PLANE SPATIAL SPA+0 SPB+30 SPC+0 TURN FMAX SEQ+\n\
                L X+10 Y+20 Z+5 FMAX\nL Z-5 F100\nEND PGM P MM\n";
    let stay = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                PLANE SPATIAL SPA+0 SPB+30 SPC+0 STAY SEQ+\nL B+Q121 C+Q122 R0 FMAX\n\
                L X+10 Y+20 Z+5 FMAX\nL Z-5 F100\nEND PGM P MM\n";
    let f = ends_on(HEAD_TABLE, Control::Fanuc30i, fanuc);
    let s = ends_on(HEAD_TABLE, Control::Sinumerik, sinumerik);
    let h = ends_on(HEAD_TABLE, Control::Heidenhain, turn);
    let hs = ends_on(HEAD_TABLE, Control::Heidenhain, stay);
    let r = ry(30.0);
    for (fl, sl, hl, hsl, p) in [
        (5, 5, 5, 6, Vec3::new(10.0, 20.0, 5.0)),
        (6, 6, 6, 7, Vec3::new(10.0, 20.0, -5.0)),
    ] {
        let want = after(&f, fl);
        same("SINUMERIK / FANUC", after(&s, sl), want);
        same("HEIDENHAIN TURN / FANUC", after(&h, hl), want);
        same("HEIDENHAIN STAY / FANUC", after(&hs, hsl), want);
        let (tip, dir) = pose_on(HEAD_TABLE, want);
        assert!((tip - r * p).norm() < 1e-9, "tip {tip:?}");
        assert!((dir - r * Vec3::z()).norm() < 1e-9, "dir {dir:?}");
        assert!((want[3] - 30.0).abs() < 1e-9, "{want:?}");
    }
}

// ----- Euler angles: G68.2 I J K and PLANE EULER --------------------------------

/// A general plane: R = Rz(30°)·Rx(−40°)·Rz(15°), FANUC's Euler angles
/// I30 J−40 K15 and PLANE EULER EULPR+30 EULNU−40 EULROT+15 as written;
/// SINUMERIK mode 57 with R = Rx(a)·Ry(b)·Rz(c) decomposed here: b =
/// asin r13, a = atan2(−r23, r33), c = atan2(−r12, r11). On the A/C
/// table only A = −40° is within the travel.
#[test]
fn euler_plane_in_three_controls() {
    let r = rz(30.0) * rx(-40.0) * rz(15.0);
    let b = r[(0, 2)].asin().to_degrees();
    let a = (-r[(1, 2)]).atan2(r[(2, 2)]).to_degrees();
    let c = (-r[(0, 1)]).atan2(r[(0, 0)]).to_degrees();
    let fanuc = "G90 G54 G17\nG43 H1 G0 Z100.\nG68.2 X0 Y0 Z0 I30. J-40. K15.\nG53.1\n\
                 G0 X10. Y20. Z5.\nG1 X-15. Y5. Z-2. F100.\nM30\n";
    let sinumerik = format!(
        "T1 D1\nG54 G17 G90\nG0 Z100\nCYCLE800(0,\"TC1\",0,57,0,0,0,{a:.12},{b:.12},{c:.12},0,0,0,-1)\n\
         G0 X10 Y20 Z5\nG1 X-15 Y5 Z-2 F100\nM30\n"
    );
    let klartext = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                    PLANE EULER EULPR+30 EULNU-40 EULROT+15 TURN FMAX SEQ-\n\
                    L X+10 Y+20 Z+5 FMAX\nL X-15 Y+5 Z-2 F100\nEND PGM P MM\n";
    let f = ends(Control::Fanuc30i, fanuc);
    let s = ends(Control::Sinumerik, &sinumerik);
    let h = ends(Control::Heidenhain, klartext);
    for (line, p) in [
        (5, Vec3::new(10.0, 20.0, 5.0)),
        (6, Vec3::new(-15.0, 5.0, -2.0)),
    ] {
        let want = after(&f, line);
        // SINUMERIK's angles are written to 12 decimals.
        for k in 0..5 {
            assert!(
                (after(&s, line)[k] - want[k]).abs() < 1e-8,
                "SINUMERIK / FANUC: {:?} {want:?}",
                after(&s, line)
            );
        }
        same("HEIDENHAIN / FANUC", after(&h, line), want);
        let (tip, dir) = pose(want);
        assert!((tip - r * p).norm() < 1e-9, "tip {tip:?}");
        assert!((dir - r * Vec3::z()).norm() < 1e-9, "dir {dir:?}");
    }
}

// ----- tool vectors on the head / table machine --------------------------------

#[test]
fn five_axis_path_by_tool_vectors_on_a_head() {
    let m = machine_for(HEAD_TABLE, Control::Heidenhain);
    let positions = [[20.0, 10.0], [35.0, -30.0], [10.0, 60.0]];
    let points = [
        Vec3::new(10.0, 0.0, 5.0),
        Vec3::new(20.0, 10.0, 0.0),
        Vec3::new(30.0, -5.0, -2.0),
    ];
    let mut fanuc = String::from("G90 G54 G17\nG0 X0 Y0 Z100.\nG1 G43.5 H1 X0 Y0 Z100. F1000.\n");
    let mut sinumerik = String::from("T1 D1\nG54 G17 G90\nG0 X0 Y0 Z100\nTRAORI\n");
    let mut klartext =
        String::from("BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL X+0 Y+0 Z+100 R0 FMAX\nM128\n");
    let mut want = Vec::new();
    for (q, p) in positions.iter().zip(points) {
        let mut j = [0.0; fiveaxis_machine::MAX_AXES];
        j[3] = q[0];
        j[4] = q[1];
        let d = m.forward(&j, 0.0).dir;
        let t = [d.x, d.y, d.z].map(|c| format!("{c:+.12}"));
        fanuc.push_str(&format!(
            "G1 X{:.3} Y{:.3} Z{:.3} I{} J{} K{} F1000.\n",
            p.x, p.y, p.z, t[0], t[1], t[2]
        ));
        sinumerik.push_str(&format!(
            "G1 X{:.3} Y{:.3} Z{:.3} A3={} B3={} C3={} F1000\n",
            p.x, p.y, p.z, t[0], t[1], t[2]
        ));
        klartext.push_str(&format!(
            "LN X{:+.3} Y{:+.3} Z{:+.3} TX{} TY{} TZ{} R0 F1000\n",
            p.x, p.y, p.z, t[0], t[1], t[2]
        ));
        let v = Vec3::new(
            t[0].parse().expect("a written number"),
            t[1].parse().expect("a written number"),
            t[2].parse().expect("a written number"),
        );
        want.push((p, v.normalize()));
    }
    klartext.push_str("END PGM P MM\n");
    let s = ends_on(HEAD_TABLE, Control::Sinumerik, &sinumerik);
    let h = ends_on(HEAD_TABLE, Control::Heidenhain, &klartext);
    let f = ends_on(HEAD_TABLE, Control::Fanuc30i, &fanuc);
    for (k, (p, d)) in want.iter().enumerate() {
        let k = k as u32;
        let sj = after(&s, 5 + k);
        same("HEIDENHAIN / SINUMERIK", after(&h, 5 + k), sj);
        same("FANUC / SINUMERIK", after(&f, 4 + k), sj);
        let (tip, dir) = pose_on(HEAD_TABLE, sj);
        assert!((tip - p).norm() < 1e-9, "tip {tip:?} want {p:?}");
        assert!((dir - d).norm() < 1e-9, "dir {dir:?}");
    }
}

// ----- a drilling cycle in the tilted plane ----------------------------------------

/// G81 (FANUC), CYCLE81 (SINUMERIK) and cycle 200 with one plunge
/// (HEIDENHAIN) at X10 Y20 of the plane turned −45° about X, 5 deep from
/// Z0 with 2 mm clearance: the machine stands at the same place at the
/// hole's bottom, R·(10, 20, −5).
#[test]
fn drilling_cycle_in_the_tilted_plane() {
    let fanuc = "G90 G54 G17\nG43 H1 G0 Z100.\nG68.2 X0 Y0 Z0 I0 J-45. K0\nG53.1\n\
                 G0 X10. Y20. Z50.\nG98 G81 X10. Y20. Z-5. R2. F100.\nG80\nM30\n";
    let sinumerik = "T1 D1\nG54 G17 G90\nG0 Z100\nCYCLE800(0,\"TC1\",0,57,0,0,0,-45,0,0,0,0,0,-1)\n\
                     G0 X10 Y20 Z50\nF100\nCYCLE81(50,0,2,-5)\nM30\n";
    let klartext = "BEGIN PGM P MM\nTOOL CALL 1 Z S1000\nL Z+100 R0 FMAX\n\
                    PLANE SPATIAL SPA-45 SPB+0 SPC+0 TURN FMAX SEQ-\n\
                    CYCL DEF 200 DRILLING ~\n Q200=2 ~\n Q201=-5 ~\n Q206=100 ~\n Q202=5 ~\n\
                    Q210=0 ~\n Q203=+0 ~\n Q204=50 ~\n Q211=0\nL X+10 Y+20 Z+50 FMAX\nCYCL CALL\nEND PGM P MM\n";
    let bottom = Vec3::new(10.0, 20.0, -5.0);
    let r = rx(-45.0);
    let mut found = Vec::new();
    for (control, program) in [
        (Control::Fanuc30i, fanuc),
        (Control::Sinumerik, sinumerik),
        (Control::Heidenhain, klartext),
    ] {
        let rows = ends(control, program);
        let at_bottom: Vec<[f64; 5]> = rows
            .iter()
            .map(|row| {
                let mut j = [0.0; 5];
                j.copy_from_slice(&row.joints[..5]);
                j
            })
            .filter(|&j| (pose(j).0 - r * bottom).norm() < 1e-9)
            .collect();
        assert_eq!(at_bottom.len(), 1, "{control:?}: {at_bottom:?}\n{program}");
        found.push(at_bottom[0]);
    }
    same("SINUMERIK / FANUC", found[1], found[0]);
    same("HEIDENHAIN / FANUC", found[2], found[0]);
}
