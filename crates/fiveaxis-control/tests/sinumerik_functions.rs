//! SINUMERIK functions on the command path: radius compensation, the
//! programmable frame's scale and mirror, CIP / CT / AR circles, CYCLE800
//! (direct angles, retracts, `_DIR`), settable frames written by the
//! program, TOFRAME / PAROT, ORIRESET, ORIMKS and A2 B2 C2. Judged
//! against hand-computed points and the machine's forward kinematics
//! (`Row::tip` and `Row::dir`, `Machine::forward`).

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, AlarmCode, Motion, Row};
use fiveaxis_machine::{Control, Machine, Offsets, ToolOffset, Vec3};

const EPS: f64 = 1e-6;

fn sinumerik(name: &str) -> Machine {
    let mut m = builtin_at_zero(name).expect("built-in");
    m.control = Control::Sinumerik;
    m
}

fn mill() -> Machine {
    sinumerik("mill-3axis")
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    o.work[0] = Vec3::new(100.0, 50.0, 0.0);
    o
}

fn ends(machine: &Machine, program: &str) -> (Vec<Row>, Option<Alarm>) {
    common::run_ends(machine, offsets(), program)
}

fn sampled(machine: &Machine, program: &str, s: &[f64]) -> (Vec<Row>, Option<Alarm>) {
    common::run_sampled(machine, offsets(), program, s)
}

fn ok(machine: &Machine, program: &str) -> Vec<Row> {
    let (rows, alarm) = ends(machine, program);
    assert!(alarm.is_none(), "{alarm:?}");
    rows
}

fn near(a: Vec3, b: Vec3) -> bool {
    (a - b).norm() < EPS
}

fn assert_tip(row: &Row, want: [f64; 3]) {
    let w = Vec3::new(want[0], want[1], want[2]);
    assert!(
        near(row.tip, w),
        "line {}: tip {:?}, want {w:?}",
        row.line,
        row.tip
    );
}

/// The row at the end of line `line`'s last segment.
fn at(rows: &[Row], line: u32) -> &Row {
    rows.iter()
        .rfind(|r| r.line == line)
        .unwrap_or_else(|| panic!("no segment of line {line}"))
}

fn alarm_number(alarm: &Option<Alarm>) -> AlarmCode {
    alarm.as_ref().expect("an alarm").code
}

// ----- radius compensation --------------------------------------------

/// A square 0…50 run clockwise with G41 D1 (radius 5): the tool centre
/// runs outside it, 5 mm away, meeting at the intersections of the
/// offset sides (outside corners of 90°: the intersection, as G451);
/// the NORM start-up ends perpendicular to the first element at its
/// start, the cancel starts perpendicular to the last at its end.
#[test]
fn g41_square_gives_the_offset_path() {
    let program =
        "T1 M6\nD1\nG0 X-20 Y-20 Z5\nG1 G41 X0 Y0 F500\nY50\nX50\nY0\nX0\nG40 X-20 Y-20\nM30\n";
    let rows = ok(&mill(), program);
    let path: Vec<(u32, [f64; 3])> = rows
        .iter()
        .filter(|r| r.line >= 4)
        .map(|r| (r.line, [r.tip.x, r.tip.y, r.tip.z]))
        .collect();
    let want = [
        (4, [-5.0, 0.0, 5.0]),
        (5, [-5.0, 55.0, 5.0]),
        (6, [55.0, 55.0, 5.0]),
        (7, [55.0, -5.0, 5.0]),
        (8, [0.0, -5.0, 5.0]),
        (9, [-20.0, -20.0, 5.0]),
    ];
    assert_eq!(path.len(), want.len(), "{path:?}");
    for ((line, got), (wline, w)) in path.iter().zip(want) {
        assert_eq!(*line, wline, "{path:?}");
        for k in 0..3 {
            assert!((got[k] - w[k]).abs() < EPS, "{path:?}");
        }
    }
}

#[test]
fn g42_runs_on_the_other_side() {
    let program = "T1 M6\nD1\nG0 X-20 Y-20 Z5\nG1 G42 X0 Y0 F500\nY50\nX50\nG40 X70 Y70\nM30\n";
    let rows = ok(&mill(), program);
    // Along Y with the tool right of the contour: X = +5.
    let on_left_edge = rows.iter().find(|r| r.line == 5).expect("line 5");
    assert_tip(on_left_edge, [5.0, 45.0, 5.0]);
}

#[test]
fn radius_of_the_edge_in_force_and_d0() {
    // D0: no radius: the path is the contour.
    let program = "T1 M6\nD0\nG0 X-20 Y-20 Z5\nG1 G41 X0 Y0 F500\nY50\nG40 X-20 Y70\nM30\n";
    let rows = ok(&mill(), program);
    let row = rows.iter().find(|r| r.line == 5).expect("line 5");
    assert_tip(row, [0.0, 50.0, 5.0]);
}

// ----- SCALE, MIRROR ----------------------------------------------------

#[test]
fn scale_scales_points_and_later_shifts() {
    let rows = ok(
        &mill(),
        "G0 X0 Y0 Z0\nSCALE X2 Y3\nG1 X10 Y5 F100\nATRANS X5\nG1 X0 Y0\nSCALE\nG1 X10 Y5\nM30\n",
    );
    assert_tip(at(&rows, 3), [20.0, 15.0, 0.0]);
    // ATRANS X5 under SCALE X2: the zero moves 10.
    assert_tip(at(&rows, 5), [10.0, 0.0, 0.0]);
    // SCALE alone: the neutral frame.
    assert_tip(at(&rows, 7), [10.0, 5.0, 0.0]);
}

#[test]
fn mirror_reverses_coordinates_and_the_sense_of_circles() {
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X0 Y0 Z0\nMIRROR X0\nG1 X10 Y5 F100\nG2 X30 Y5 I10 J0\nM30\n",
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let end_line = at(&rows, 3);
    assert_tip(end_line, [-10.0, 5.0, 0.0]);
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
    // G2 from (10, 5) about (20, 5) over the top, mirrored in X: from
    // (−10, 5) about (−20, 5), still over the top, now counter-clockwise.
    assert_tip(arc[0], [-20.0, 15.0, 0.0]);
    assert_tip(arc[1], [-30.0, 5.0, 0.0]);
    assert_eq!(arc[1].motion, Motion::Ccw);
}

#[test]
fn amirror_toggles_and_mirror_swaps_g41() {
    let rows = ok(
        &mill(),
        "G0 X0 Y0 Z0\nMIRROR X0\nAMIRROR X0\nG1 X10 Y5 F100\nM30\n",
    );
    assert_tip(at(&rows, 4), [10.0, 5.0, 0.0]);
    // Under MIRROR X the contour up the Y axis with G41 has the tool on
    // the right as seen in the machine: at X = +5 for a contour at X 0.
    let rows = ok(
        &mill(),
        "T1 M6\nD1\nMIRROR X0\nG0 X20 Y-20 Z5\nG1 G41 X0 Y0 F500\nY50\nG40 X20 Y70\nM30\n",
    );
    let row = rows.iter().find(|r| r.line == 6).expect("line 6");
    assert!((row.tip.x - 5.0).abs() < EPS, "{:?}", row.tip);
}

#[test]
fn arc_under_unequal_scale_is_refused() {
    let (_, alarm) = ends(
        &mill(),
        "G0 X0 Y0 Z0\nSCALE X2 Y3\nG2 X20 Y0 I10 J0 F100\nM30\n",
    );
    assert!(alarm.is_some());
}

#[test]
fn scale_with_rotation_keeps_the_order_t_r_s_m() {
    // TRANS X10, AROT Z90, ASCALE X2: p = T + R·S·p; X1 → (10, 2).
    let rows = ok(
        &mill(),
        "G0 X0 Y0 Z0\nTRANS X10\nAROT Z90\nASCALE X2\nG1 X1 Y0 F100\nM30\n",
    );
    assert_tip(rows.last().expect("a row"), [10.0, 2.0, 0.0]);
}

// ----- CIP, CT, AR ------------------------------------------------------

#[test]
fn cip_in_the_plane_is_a_circle_through_the_point() {
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X0 Y0 Z0\nG1 F100\nCIP X20 Y0 I1=10 J1=10\nM30\n",
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    // Centre (10, 0), radius 10, over the top: clockwise.
    assert_tip(arc[0], [10.0, 10.0, 0.0]);
    assert_tip(arc[1], [20.0, 0.0, 0.0]);
    assert_eq!(arc[1].motion, Motion::Cw);
}

#[test]
fn cip_incremental_intermediate_point_under_g91() {
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X5 Y5 Z0\nG91 G1 F100\nCIP X20 Y0 I1=10 J1=-10\nM30\n",
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    assert_tip(arc[0], [15.0, -5.0, 0.0]);
    assert_tip(arc[1], [25.0, 5.0, 0.0]);
    assert_eq!(arc[1].motion, Motion::Ccw);
}

#[test]
fn cip_in_space() {
    // Three points on the sphere of radius 10 about the origin: the
    // circle's centre is (10, 10, 10)/3, its plane x + y + z = 10; the
    // intermediate point halfway (an equilateral triangle).
    let samples: Vec<f64> = (1..=8).map(|k| f64::from(k) / 8.0).collect();
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X10 Y0 Z0\nG1 F100\nCIP X0 Y0 Z10 I1=0 J1=10 K1=0\nM30\n",
        &samples,
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    assert_eq!(arc.len(), 8);
    let c = Vec3::new(10.0, 10.0, 10.0) / 3.0;
    let r = (Vec3::new(10.0, 0.0, 0.0) - c).norm();
    for row in &arc {
        assert!(((row.tip - c).norm() - r).abs() < EPS, "{:?}", row.tip);
        assert!((row.tip.x + row.tip.y + row.tip.z - 10.0).abs() < EPS);
    }
    assert_tip(arc[3], [0.0, 10.0, 0.0]);
    assert_tip(arc[7], [0.0, 0.0, 10.0]);
}

#[test]
fn cip_on_a_line_is_an_alarm() {
    let (_, alarm) = ends(
        &mill(),
        "G0 X0 Y0 Z0\nG1 F100\nCIP X20 Y0 I1=10 J1=0\nM30\n",
    );
    assert_eq!(alarm_number(&alarm), AlarmCode::sinumerik(14040));
}

#[test]
fn ct_continues_the_tangent() {
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X0 Y0 Z0\nG1 X10 F100\nCT X20 Y10\nCT X10 Y20\nM30\n",
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Tangent +X at (10, 0), end (20, 10): centre (10, 10), a quarter
    // counter-clockwise.
    let h = 10.0 / 2f64.sqrt();
    let a: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    assert_tip(a[0], [10.0 + h, 10.0 - h, 0.0]);
    assert_tip(a[1], [20.0, 10.0, 0.0]);
    assert_eq!(a[1].motion, Motion::Ccw);
    // Then tangent +Y at (20, 10), end (10, 20): the same centre.
    let b: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
    assert_tip(b[0], [10.0 + h, 10.0 + h, 0.0]);
    assert_tip(b[1], [10.0, 20.0, 0.0]);
}

#[test]
fn ct_after_an_arc() {
    // G3 a quarter from (10, 0) about (0, 0) to (0, 10): tangent −X. CT to
    // (−10, 0): centre on the normal at (0, 10) … (0, 0) again.
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X10 Y0 Z0\nG3 X0 Y10 CR=10 F100\nCT X-10 Y0\nM30\n",
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let h = 10.0 / 2f64.sqrt();
    let a: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    assert_tip(a[0], [-h, h, 0.0]);
    assert_tip(a[1], [-10.0, 0.0, 0.0]);
}

#[test]
fn ar_with_the_end_point() {
    let (rows, alarm) = sampled(
        &mill(),
        "G0 X0 Y0 Z0\nG3 X10 Y10 AR=90 F100\nG0 X0 Y0\nG3 X20 Y0 AR=180\nG0 X0 Y0\nG2 X10 Y10 AR=270\nM30\n",
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let h = 10.0 / 2f64.sqrt();
    // Centre (0, 10).
    let a: Vec<&Row> = rows.iter().filter(|r| r.line == 2).collect();
    assert_tip(a[0], [h, 10.0 - h, 0.0]);
    // Centre (10, 0), below the chord.
    let b: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
    assert_tip(b[0], [10.0, -10.0, 0.0]);
    // G2 over 270°: the centre is (0, 10) again (right of the chord for
    // G2, beyond 180° on the other side), the arc goes round below.
    let c: Vec<&Row> = rows.iter().filter(|r| r.line == 6).collect();
    let mid = Vec3::new(0.0, 10.0, 0.0)
        + 10.0
            * Vec3::new(
                (-90f64 - 135.0).to_radians().cos(),
                (-90f64 - 135.0).to_radians().sin(),
                0.0,
            );
    assert_tip(c[0], [mid.x, mid.y, 0.0]);
    assert_tip(c[1], [10.0, 10.0, 0.0]);
}

#[test]
fn ar_with_the_centre() {
    let rows = ok(&mill(), "G0 X0 Y0 Z0\nG2 I10 J0 AR=90 F100\nM30\n");
    // Centre (10, 0), clockwise 90° from (0, 0): (10, 10).
    assert_tip(rows.last().expect("a row"), [10.0, 10.0, 0.0]);
}

#[test]
fn ar_with_both_or_out_of_range_is_an_alarm() {
    let (_, a) = ends(&mill(), "G0 X0 Y0 Z0\nG2 X10 Y10 I10 AR=90 F100\nM30\n");
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(14040));
    let (_, a) = ends(&mill(), "G0 X0 Y0 Z0\nG2 X10 Y10 AR=400 F100\nM30\n");
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(14040));
}

// ----- CYCLE800 ---------------------------------------------------------

fn dmu() -> Machine {
    sinumerik("sinumerik-dmu-bc")
}

fn joint(m: &Machine, row: &Row, name: char) -> f64 {
    row.joints[m.axis_index(name).expect("an axis")]
}

#[test]
fn cycle800_direct_angles_move_the_axes_and_make_the_frame() {
    let m = dmu();
    let rows = ok(
        &m,
        "G54 G0 X0 Y0 Z100\nCYCLE800(0,\"\",0,192,0,0,0,40,30,0,0,0,0,1)\nG91 G1 Z10 F500\nM30\n",
    );
    let swivel = at(&rows, 2);
    assert!((joint(&m, swivel, 'B') - 40.0).abs() < EPS);
    assert!((joint(&m, swivel, 'C') - 30.0).abs() < EPS);
    // Z of the frame is the tool direction at B40 C30 (forward
    // kinematics): the incremental Z10 moves the tip 10 along it.
    let mv = at(&rows, 3);
    let dir = m.forward(&swivel.joints, 0.0).dir;
    assert!(
        near(mv.tip - swivel.tip, 10.0 * dir),
        "{:?} {:?}",
        mv.tip - swivel.tip,
        dir
    );
    assert!(near(mv.dir, dir));
}

#[test]
fn cycle800_dir_zero_moves_nothing() {
    let m = dmu();
    let (rows, alarm) = ends(
        &m,
        "G54 G0 X0 Y0 Z100\nCYCLE800(0,\"\",0,57,0,0,0,30,0,0,0,0,0,0)\nM30\n",
    );
    assert!(alarm.is_none(), "{alarm:?}");
    assert!(rows.iter().all(|r| r.line != 2));
}

#[test]
fn cycle800_dir_chooses_the_first_axis_solution() {
    let m = sinumerik("trunnion-ac");
    for (dir, higher) in [(1, true), (-1, false)] {
        let program =
            format!("G0 X0 Y0 Z100\nCYCLE800(0,\"\",0,57,0,0,0,20,0,0,0,0,0,{dir})\nM30\n");
        let rows = ok(&m, &program);
        let row = at(&rows, 2);
        let a = joint(&m, row, 'A');
        assert!((a.abs() - 20.0).abs() < 1e-6, "A {a}");
        assert_eq!(a > 0.0, higher, "_DIR {dir}: A {a}");
        // Either way the tool stands along the frame's Z: turned 20°
        // about X from the workpiece's Z.
        let want = Vec3::new(0.0, -(20f64.to_radians().sin()), 20f64.to_radians().cos());
        assert!(near(row.dir, want), "{:?} vs {want:?}", row.dir);
    }
}

#[test]
fn cycle800_retract_along_the_tool() {
    let m = dmu();
    // _FR 5: by _FR_I along the tool (vertical here): Z up 20.
    let rows = ok(
        &m,
        "G0 X0 Y0 Z100\nCYCLE800(5,\"\",0,57,0,0,0,0,0,0,0,0,0,0,20)\nM30\n",
    );
    let r = at(&rows, 2);
    assert!((joint(&m, r, 'Z') - 120.0).abs() < EPS);
    // _FR 4: to the end of travel (Z max 500).
    let rows = ok(
        &m,
        "G0 X0 Y0 Z100\nCYCLE800(4,\"\",0,57,0,0,0,0,0,0,0,0,0,0)\nM30\n",
    );
    let r = at(&rows, 2);
    assert!((joint(&m, r, 'Z') - 500.0).abs() < EPS);
    let (_, a) = ends(&m, "CYCLE800(3,\"\",0,57,0,0,0,0,0,0,0,0,0,0)\nM30\n");
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(61186));
}

#[test]
fn cycle800_direct_angles_outside_the_limits() {
    let (_, a) = ends(
        &dmu(),
        "CYCLE800(0,\"\",0,192,0,0,0,-40,0,0,0,0,0,1)\nM30\n",
    );
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(61190));
    let (_, a) = ends(
        &mill(),
        "CYCLE800(0,\"\",0,192,0,0,0,10,0,0,0,0,0,1)\nM30\n",
    );
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(61153));
}

// ----- TOFRAME, TOROT, PAROT --------------------------------------------

#[test]
fn toframe_puts_z_along_the_tool() {
    let m = dmu();
    let rows = ok(
        &m,
        "G54 G0 X0 Y0 Z100\nG0 G53 B60 C20\nTOFRAME\nG91 G1 Z10 F500\nTOROTOF\nG1 Z10\nM30\n",
    );
    let before = at(&rows, 2);
    let dir = m.forward(&before.joints, 0.0).dir;
    let moved = at(&rows, 4);
    assert!(near(moved.tip - before.tip, 10.0 * dir));
    // TOROTOF: Z is the workpiece's again.
    let after = at(&rows, 6);
    let dz = after.joints[2] - moved.joints[2];
    assert!((dz - 10.0).abs() < EPS, "{dz}");
}

#[test]
fn parot_turns_the_workpiece_coordinates_with_the_table() {
    let m = dmu();
    // C at 90: without PAROT X10 is machine X; with it, X of the
    // workpiece on the turned table.
    let rows = ok(
        &m,
        "G54 G0 X0 Y0 Z100\nG0 G53 C90\nG1 X10 F500\nPAROT\nG1 X20 Y0\nPAROTOF\nM30\n",
    );
    let plain = at(&rows, 3);
    // (G54: the work zero at (100, 50).)
    assert!((plain.joints[0] - 110.0).abs() < EPS && (plain.joints[1] - 50.0).abs() < EPS);
    let turned = at(&rows, 5);
    assert_tip(turned, [20.0, 0.0, 100.0]);
}

// ----- settable frames --------------------------------------------------

#[test]
fn uifr_written_by_the_program_holds_at_the_next_g54() {
    let rows = ok(
        &mill(),
        "G54 G0 X0 Y0 Z0\n$P_UIFR[1]=CTRANS(X,10,Y,20):CROT(Z,30)\nG0 X0 Y0\nG54\nG0 X10 Y0\nG55 G0 X0 Y0\nM30\n",
    );
    // Before G54 is selected again: the offsets file's (100, 50).
    let first = rows.iter().rfind(|r| r.line == 3);
    assert!(first.is_none_or(|r| near(r.joints_xyz(), Vec3::new(100.0, 50.0, 0.0))));
    let row = at(&rows, 5);
    let (s, c) = 30f64.to_radians().sin_cos();
    let want = Vec3::new(10.0 + 10.0 * c, 20.0 + 10.0 * s, 0.0);
    assert!(near(row.joints_xyz(), want), "{:?}", row.joints);
    // G55: the offsets file's (zero).
    let g55 = at(&rows, 6);
    assert!(near(g55.joints_xyz(), Vec3::zeros()));
}

#[test]
fn pframe_written_and_read() {
    let rows = ok(
        &mill(),
        "DEF FRAME F1\nG0 X0 Y0 Z0\n$P_PFRAME=CTRANS(X,5)\nG0 X1\nATRANS Y3\nF1=$P_PFRAME\nTRANS\n$P_PFRAME=F1\nG0 X0 Y0\nM30\n",
    );
    let x1 = at(&rows, 4);
    assert_tip(x1, [6.0, 0.0, 0.0]);
    // Read back after ATRANS, written again after TRANS: (5, 3).
    let last = rows.last().expect("a row");
    assert_tip(last, [5.0, 3.0, 0.0]);
}

// ----- orientation --------------------------------------------------------

#[test]
fn orireset_needs_traori() {
    let (_, a) = ends(&dmu(), "ORIRESET(30,0)\nM30\n");
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(14101));
}

#[test]
fn orireset_turns_the_axes_about_the_tip() {
    let m = dmu();
    let mut o = offsets();
    o.tools.insert(
        2,
        ToolOffset {
            length: 100.0,
            ..ToolOffset::default()
        },
    );
    let (rows, alarm) = common::run_ends(
        &m,
        o,
        "T2 M6\nD1\nTRAORI\nG54 G0 X0 Y0 Z50\nORIRESET(30,45)\nM30\n",
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let before = at(&rows, 4);
    let after = at(&rows, 5);
    assert!((joint(&m, after, 'B') - 30.0).abs() < EPS);
    assert!((joint(&m, after, 'C') - 45.0).abs() < EPS);
    // The tip stays (forward kinematics with the tool length).
    let tip = |r: &Row| m.forward(&r.joints, 100.0).tip;
    assert!(
        near(tip(before), tip(after)),
        "{:?} {:?}",
        tip(before),
        tip(after)
    );
}

#[test]
fn euler_angles_a2_b2_c2() {
    let m = dmu();
    // ORIEULER (default): Z, X′, Z″: the tool along
    // (sin a sin b, −cos a sin b, cos b).
    let rows = ok(&m, "TRAORI\nG54 G1 X0 Y0 Z50 A2=30 B2=40 C2=0 F1000\nM30\n");
    let (a, b) = (30f64.to_radians(), 40f64.to_radians());
    let want = Vec3::new(a.sin() * b.sin(), -a.cos() * b.sin(), b.cos());
    let row = rows.last().expect("a row");
    assert!(near(m.forward(&row.joints, 0.0).dir, want), "{:?}", row.dir);
    // ORIRPY: about X, then Y, then Z of the fixed frame: A2 turns about
    // X by 30: the tool along (0, −sin 30, cos 30).
    let rows = ok(
        &m,
        "TRAORI\nORIRPY\nG54 G1 X0 Y0 Z50 A2=30 B2=0 C2=0 F1000\nM30\n",
    );
    let want = Vec3::new(0.0, -0.5, 3f64.sqrt() / 2.0);
    assert!(
        near(rows.last().expect("a row").dir, want),
        "{:?}",
        rows.last().expect("a row").dir
    );
}

#[test]
fn orimks_reads_the_vector_in_the_machine_frame() {
    let m = dmu();
    let s = 0.5f64.sqrt();
    let wks = ok(
        &m,
        "TRAORI\nG54\nROT Z90\nG1 X0 Y0 Z50 A3=0 B3=-1 C3=1 F1000\nM30\n",
    );
    // ORIWKS: the vector turns with the frame: (0, −1, 1) → (1, 0, 1).
    assert!(near(wks.last().expect("a row").dir, Vec3::new(s, 0.0, s)));
    let mks = ok(
        &m,
        "TRAORI\nORIMKS\nG54\nROT Z90\nG1 X0 Y0 Z50 A3=0 B3=-1 C3=1 F1000\nM30\n",
    );
    assert!(near(mks.last().expect("a row").dir, Vec3::new(0.0, -s, s)));
}

trait XyzOf {
    fn joints_xyz(&self) -> Vec3;
}

impl XyzOf for Row {
    fn joints_xyz(&self) -> Vec3 {
        Vec3::new(self.joints[0], self.joints[1], self.joints[2])
    }
}

#[test]
fn lead_and_tilt_relative_to_the_path() {
    let m = dmu();
    // Moving along +X on a surface with normal Z: LEAD 20 leans the tool
    // towards +X, TILT then turns it about X.
    let rows = ok(
        &m,
        "TRAORI\nG54 G0 X0 Y0 Z50\nG1 X50 LEAD=20 TILT=0 F1000\nG1 X100 LEAD=0 TILT=30\nM30\n",
    );
    let (s, c) = 20f64.to_radians().sin_cos();
    assert!(
        near(at(&rows, 3).dir, Vec3::new(s, 0.0, c)),
        "{:?}",
        at(&rows, 3).dir
    );
    let (s, c) = 30f64.to_radians().sin_cos();
    assert!(
        near(at(&rows, 4).dir, Vec3::new(0.0, -s, c)),
        "{:?}",
        at(&rows, 4).dir
    );
    let (_, a) = ends(&m, "TRAORI\nG54 G0 X0 Y0 Z50\nG1 Z10 LEAD=20 F1000\nM30\n");
    assert_eq!(alarm_number(&a), AlarmCode::sinumerik(14104));
}

#[test]
fn drilling_cycle_and_position_reads_under_scale() {
    // Under SCALE X2 the cycle drills where the scaled point is, and
    // $AA_IW reads the program's coordinate.
    let rows = ok(
        &mill(),
        "G0 X0 Y0 Z50 F200\nSCALE X2 Y2\nG0 X10 Y5\nR1=$AA_IW[X]\nG0 X=R1+1\nCYCLE81(10,0,2,-5,0)\nM30\n",
    );
    assert_tip(at(&rows, 5), [22.0, 10.0, 50.0]);
    let drill = rows.iter().filter(|r| r.line == 6).collect::<Vec<_>>();
    assert!(
        drill
            .iter()
            .all(|r| near(Vec3::new(r.tip.x, r.tip.y, 0.0), Vec3::new(22.0, 10.0, 0.0)))
    );
    assert!(drill.iter().any(|r| (r.tip.z + 5.0).abs() < EPS));
}

#[test]
fn circles_out_of_range_are_alarms_not_panics() {
    for program in [
        "G0 X0 Y0 Z0\nG1 F100\nCIP X1E300 Y1E300 I1=-1E300 J1=1E300\nM30\n",
        "G0 X0 Y0 Z0\nG1 F100\nCIP X1E-300 Y0 Z1E-300 I1=1E-300 J1=1E-300\nM30\n",
        "G0 X0 Y0 Z0\nG1 X1 F100\nCT X1E300 Y1E-300\nM30\n",
        "G0 X0 Y0 Z0\nG3 X1E300 Y1 AR=0.0000001 F100\nM30\n",
        "G0 X0 Y0 Z0\nCT X10 Y10\nM30\n",
    ] {
        let (_, alarm) = ends(&mill(), program);
        assert!(alarm.is_some(), "{program}");
    }
}

#[test]
fn frame_components_read_and_written() {
    let rows = ok(
        &mill(),
        "G0 X0 Y0 Z0\nR1=$P_UIFR[1,X,TR]\n$P_UIFR[2,Y,TR]=R1+7\nG55\nG0 X0 Y0\nTRANS X3\nR2=$P_PFRAME[X,TR]\n$P_PFRAME[Y,TR]=R2*2\nG0 X0 Y0\nM30\n",
    );
    // $P_UIFR[1] is the offsets file's G54 (100, 50): G55 becomes (0, 107).
    assert!(near(at(&rows, 5).joints_xyz(), Vec3::new(0.0, 107.0, 0.0)));
    // The programmable frame (3, 6) inside it.
    assert!(near(at(&rows, 9).joints_xyz(), Vec3::new(3.0, 113.0, 0.0)));
}

// ----- orientation interpolation -----------------------------------------

/// `ORIVECT` turns the tool on the great circle between the block's end
/// vectors: half way the direction is their normalised mean. `ORIAXES`
/// moves the rotary axes linearly: half way the axes stand at the mean of
/// their end angles, and the direction is the machine's there (forward
/// kinematics), off the great circle for this move.
#[test]
fn orivect_turns_on_the_great_circle_and_oriaxes_moves_the_axes_linearly() {
    let m = dmu();
    let a = Vec3::new(1.0, 0.0, 1.0).normalize();
    let b = Vec3::new(0.0, 1.0, 1.0).normalize();
    for (mode, great_circle) in [("ORIVECT", true), ("ORIAXES", false)] {
        let program = format!(
            "TRAORI\n{mode}\nG1 X0 Y0 Z50 A3=1 B3=0 C3=1 F1000\nG1 X20 A3=0 B3=1 C3=1\nM30\n"
        );
        let (rows, alarm) = sampled(&m, &program, &[0.0, 0.5, 1.0]);
        assert!(alarm.is_none(), "{mode}: {alarm:?}");
        let of_line: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
        let (start, mid, end) = (of_line[0], of_line[1], of_line[2]);
        assert!(near(start.dir, a), "{mode}: start {:?}", start.dir);
        assert!(near(end.dir, b), "{mode}: end {:?}", end.dir);
        // The tip is on the programmed line whatever the orientation does.
        assert!(
            near(mid.tip, Vec3::new(10.0, 0.0, 50.0)),
            "{mode}: tip {:?}",
            mid.tip
        );
        let bisector = (a + b).normalize();
        if great_circle {
            assert!(near(mid.dir, bisector), "{mode}: mid {:?}", mid.dir);
        } else {
            for axis in ['B', 'C'] {
                let (s, e) = (joint(&m, start, axis), joint(&m, end, axis));
                let mid_angle = joint(&m, mid, axis);
                assert!(
                    (mid_angle - (s + e) / 2.0).abs() < 1e-9,
                    "{mode}: {axis} half way {mid_angle}, ends {s} and {e}"
                );
            }
            let dir = m.forward(&mid.joints, 0.0).dir;
            assert!(near(mid.dir, dir), "{mode}: {:?} vs {dir:?}", mid.dir);
            assert!(!near(mid.dir, bisector), "{mode}: on the great circle");
        }
    }
}

/// `$P_GG[n]` gives the active G function of group n by its place in the
/// group: G710 is 4th in group 13, G91 2nd in 14, G1 2nd in 1, G18 2nd
/// in 6, G94 2nd in 15.
#[test]
fn p_gg_gives_each_groups_active_function() {
    let rows = ok(
        &mill(),
        "G710 G91 G18 G94 G1 X1 F100\n\
         R1=$P_GG[13] R2=$P_GG[14] R3=$P_GG[1] R4=$P_GG[6] R5=$P_GG[15]\n\
         G90 G17 X=R1*10+R2 Y=R3*10+R4 Z=R5\nM30\n",
    );
    assert_tip(at(&rows, 3), [42.0, 22.0, 2.0]);
}

/// `CYCLE832(_TOL, _TOLM)` puts the control's smoothing in force with its
/// tolerance (under G70 in inches), `CYCLE832()` or a units digit 0 of
/// `_TOLM` takes it off: kept in the modal state as FANUC's `G05.1 Q1`,
/// the path unchanged.
#[test]
fn cycle832_is_kept_in_the_modal_state_and_leaves_the_path() {
    use fiveaxis_control::{ContourControl, RunOptions, Runner, SliceSource};
    let m = mill();
    let modal_after = |program: &str| {
        let mut runner = Runner::new(
            &m,
            offsets(),
            SliceSource::new(program.as_bytes()),
            RunOptions::default(),
        );
        let mut out = Vec::new();
        while runner.fill(&mut out, 64).expect("no alarm") {}
        let accuracy = runner.controller().modal().accuracy;
        (accuracy.contour, accuracy.corner_rounding, out.len())
    };
    let (on, tolerance, n) = modal_after("G1 X1 F100\nCYCLE832(0.02,1,1)\nG1 X2\nM30\n");
    assert_eq!((on, tolerance), (ContourControl::AiContour, Some(0.02)));
    let (_, _, plain) = modal_after("G1 X1 F100\nG1 X2\nM30\n");
    assert_eq!(n, plain, "CYCLE832 moved something");
    let (on, _, _) = modal_after("G70\nCYCLE832(0.001,1,1)\nM30\n");
    assert_eq!(on, ContourControl::AiContour);
    let (_, tolerance, _) = modal_after("G70\nCYCLE832(0.001,1,1)\nM30\n");
    assert!((tolerance.unwrap_or(0.0) - 0.0254).abs() < 1e-12);
    for off in ["CYCLE832()", "CYCLE832(0.02,0,1)"] {
        let (on, tolerance, _) = modal_after(&format!("CYCLE832(0.02,1,1)\n{off}\nM30\n"));
        assert_eq!((on, tolerance), (ContourControl::Off, None), "{off}");
    }
}
