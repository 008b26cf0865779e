//! The Haas control's own functions (`control = "haas"`, second part):
//! G234 TCPC, G254 / G255 dynamic work offset, G268 / G269 / G253 feature
//! coordinates, G187, G154 / G110 work offsets and Haas's M codes, on the
//! Haas built-in machines.
//!
//! Every expected position is worked out by hand from the manual's
//! definition and the machine's geometry (the built-in's centres of
//! rotation), and judged by forward kinematics: `Machine::forward` of the
//! reported axes must put the tool tip on the hand-computed point of the
//! part. No test calls the kernel's inverse kinematics.
//!
//! The UMC-750 built-in: B about +Y through (−381, −254, −430), C about +Z
//! through X −381, Y −254. A point d from the B centre turns by B = 90° to
//! (d.z, d.y, −d.x); a point turns by C = 90° about the C line from
//! (x, y) to (−y, x) (right-hand rule, the part carried by the axis).

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{
    Alarm, Condition, LengthMode, Row, RunError, RunOptions, Runner, SliceSource, TcpcType,
};
use fiveaxis_machine::{Control, Machine, Offsets, ToolOffset, Vec3};

/// Positions computed by hand and by the kernel agree to this, mm / deg.
const EPS: f64 = 1e-9;
/// Tool 1's length, mm.
const L: f64 = 100.0;
/// G54 on the UMC: on the C axis, 30 mm above the B axis (table frame at
/// B0 C0).
const G54: [f64; 3] = [-381.0, -254.0, -400.0];
/// G55 on the UMC: 40 mm off the C line in +X.
const G55: [f64; 3] = [-341.0, -254.0, -400.0];
/// The UMC's B centre.
const B_CENTER: [f64; 3] = [-381.0, -254.0, -430.0];

fn umc() -> Machine {
    metric("haas-umc750")
}

/// A Haas built-in with Setting 9 = MM: these programs are metric (G21),
/// which a Haas set to inch refuses (the built-ins are inch, the US
/// default).
fn metric(name: &str) -> Machine {
    let mut m = builtin_at_zero(name).expect("built-in");
    m.params.input_unit = fiveaxis_machine::InputUnit::Millimetre;
    m
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: L,
            ..ToolOffset::default()
        },
    );
    o.work[0] = Vec3::from(G54);
    o.work[1] = Vec3::from(G55);
    o.extended_work[0] = Vec3::new(1.0, 0.0, 0.0);
    o.extended_work[6] = Vec3::new(7.0, 0.0, 0.0);
    o.extended_work[98] = Vec3::new(99.0, 0.0, 0.0);
    o
}

struct Run<'m> {
    rows: Vec<Row>,
    alarm: Option<Alarm>,
    runner: Runner<'m, SliceSource<'m>>,
}

fn run_on<'m>(machine: &'m Machine, program: &'m str) -> Run<'m> {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push(seg.row(machine, 1.0)),
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    };
    Run {
        rows,
        alarm,
        runner,
    }
}

#[track_caller]
fn run<'m>(machine: &'m Machine, program: &'m str) -> Vec<Row> {
    let r = run_on(machine, program);
    assert!(r.alarm.is_none(), "unexpected alarm {:?}", r.alarm);
    r.rows
}

#[track_caller]
fn alarm(machine: &Machine, program: &str) -> Alarm {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    loop {
        match runner.next_segment() {
            Ok(Some(_)) => {}
            Ok(None) => panic!("no alarm in {program}"),
            Err(RunError::Alarm { alarm, .. }) => return alarm,
            Err(e) => panic!("{e}"),
        }
    }
}

/// The last row of line `line`.
#[track_caller]
fn end_of(rows: &[Row], line: u32) -> &Row {
    rows.iter()
        .rev()
        .find(|r| r.line == line)
        .unwrap_or_else(|| panic!("no row of line {line}: {rows:#?}"))
}

#[track_caller]
fn assert_close(actual: &[f64], expected: &[f64], what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}");
    for (a, e) in actual.iter().zip(expected) {
        assert!(
            (a - e).abs() < EPS,
            "{what}: got {actual:?}, expected {expected:?}"
        );
    }
}

/// The tip forward kinematics puts at the row's axes, with tool 1.
fn tip(machine: &Machine, row: &Row) -> [f64; 3] {
    let t = machine.forward(&row.joints, L).tip;
    [t.x, t.y, t.z]
}

/// A part point d from the B centre, turned by B = 90° about +Y.
fn b90(p: [f64; 3]) -> [f64; 3] {
    let d = [p[0] - B_CENTER[0], p[1] - B_CENTER[1], p[2] - B_CENTER[2]];
    [B_CENTER[0] + d[2], B_CENTER[1] + d[1], B_CENTER[2] - d[0]]
}

/// G54 + p.
fn work(p: [f64; 3]) -> [f64; 3] {
    [G54[0] + p[0], G54[1] + p[1], G54[2] + p[2]]
}

// ----- G234 ---------------------------------------------------------------

#[test]
fn g234_tip_follows_the_part_turned_with_the_table() {
    let m = umc();
    // Started at C90: Haas's frame is the table's at rotary position 0
    // whatever the start-up position, so the part point (10, 5) is found
    // turned by C90 about the C line, at (−5, 10).
    let program = "G21 G90 G54\nG0 C90.\nG234 H1 G0 X10. Y5. Z150.\nG0 B90. C0. X10. Y5. Z20.\nG1 X30. F500.\nG49\n";
    let rows = run(&m, program);
    let row = end_of(&rows, 3);
    let expected = [G54[0] - 5.0, G54[1] + 10.0, G54[2] + 150.0 + L, 0.0, 90.0];
    assert_close(&row.joints[..5], &expected, "line 3 axes");
    assert_close(&tip(&m, row), &work([10.0, 5.0, 150.0]), "line 3 tip");
    for (line, p) in [(4, [10.0, 5.0, 20.0]), (5, [30.0, 5.0, 20.0])] {
        let row = end_of(&rows, line);
        // The part point G54 + p, in machine coordinates at B90: the tip;
        // the spindle (gauge point) L above it.
        let t = b90(work(p));
        let expected = [t[0], t[1], t[2] + L, 90.0, 0.0];
        assert_close(&row.joints[..5], &expected, &format!("line {line} axes"));
        assert_close(&tip(&m, row), &work(p), &format!("line {line} tip"));
    }
    // X of the part is machine −Z at B90: line 5 moves Z only.
    let (a, b) = (end_of(&rows, 4), end_of(&rows, 5));
    assert!((a.joints[0] - b.joints[0]).abs() < EPS);
    assert!((b.joints[2] - a.joints[2] + 20.0).abs() < EPS);
    // FANUC's G43.4 (WKP = 0) freezes the frame at start-up instead: at
    // C90 the same words put the tip on the point not turned.
    let mut fanuc = umc();
    fanuc.control = Control::Fanuc30i;
    let rows = run(&fanuc, "G21 G90 G54\nG0 C90.\nG43.4 H1 G0 X10. Y5. Z150.\n");
    let expected = [G54[0] + 10.0, G54[1] + 5.0, G54[2] + 150.0 + L];
    assert_close(&end_of(&rows, 3).joints[..3], &expected, "FANUC");
}

/// The row halfway along the last segment of line `line`.
fn halfway(machine: &Machine, program: &str, line: u32) -> Row {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut found = None;
    while let Some(seg) = runner.next_segment().expect("no alarm") {
        if seg.line == line {
            found = Some(seg.row(machine, 0.5));
        }
    }
    found.unwrap_or_else(|| panic!("no segment of line {line}"))
}

#[test]
fn g234_and_g254_lines_keep_the_tip_on_the_part_s_line() {
    let m = umc();
    // G234: B turns from 0 to 90 while the tip runs from (10, 5, 150) to
    // (10, 5, 20) on the part: halfway, by forward kinematics, it is at
    // (10, 5, 85) whatever the axes do.
    let program = "G21 G90 G54\nG234 H1 G0 X10. Y5. Z150.\nG1 B90. Z20. F500.\n";
    let row = halfway(&m, program, 3);
    assert_close(&tip(&m, &row), &work([10.0, 5.0, 85.0]), "G234 halfway");
    assert!(
        (row.joints[3] - 45.0).abs() < EPS,
        "B halfway: {:?}",
        row.joints
    );
    // G254 at B90: the line X10 → X30, halfway at X20, which is the
    // part point (−20, 5, 20) from the work zero (turned back by B90).
    let program =
        "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG0 B90.\nG254\nG0 X10. Y5. Z20.\nG1 X30. F500.\n";
    let row = halfway(&m, program, 5);
    assert_close(&tip(&m, &row), &work([-20.0, 5.0, 20.0]), "G254 halfway");
}

#[test]
fn g234_on_the_vf2_with_tr160_turns_the_part_about_the_a_axis() {
    let m = metric("haas-vf2-tr160");
    // G54 on the platter's centre line, 40 mm above the A axis (which
    // runs through Y −203, Z −440). +A turns the part about −X: a point d
    // from the A axis goes at A90 to (d.x, d.z, −d.y).
    let mut o = offsets();
    o.work[0] = Vec3::new(-381.0, -203.0, -400.0);
    let program = "G21 G90 G54\nG234 H1 G0 X10. Y5. Z150.\nG0 A90. X10. Y5. Z20.\n";
    let mut runner = Runner::new(
        &m,
        o,
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut last = None;
    while let Some(seg) = runner.next_segment().expect("no alarm") {
        last = Some(seg.row(&m, 1.0));
    }
    let row = last.expect("rows");
    // The part point (−371, −198, −380); d = (10, 5, 60) → (10, 60, −5).
    let t = [-371.0, -203.0 + 60.0, -440.0 - 5.0];
    assert_close(&row.joints[..5], &[t[0], t[1], t[2] + L, 90.0, 0.0], "axes");
    assert_close(&tip(&m, &row), &[-371.0, -198.0, -380.0], "tip");
}

#[test]
fn g234_is_group_08_and_ended_by_g49_and_g43() {
    let m = umc();
    let modal = |p: &'static str| {
        let r = run_on(&m, p);
        assert!(r.alarm.is_none(), "{p}: {:?}", r.alarm);
        r.runner.controller().modal().length
    };
    assert_eq!(
        modal("G21 G53 G0 Z-300.\nG234 H1\n"),
        LengthMode::Tcpc(TcpcType::Angles)
    );
    assert_eq!(modal("G21 G53 G0 Z-300.\nG234 H1\nG49\n"), LengthMode::Off);
    assert_eq!(
        modal("G21 G53 G0 Z-300.\nG234 H1\nG43 H1\n"),
        LengthMode::Plus
    );
    // H in force from an earlier G43 serves G234.
    assert_eq!(
        modal("G21 G53 G0 Z-300.\nG43 H1\nG234\n"),
        LengthMode::Tcpc(TcpcType::Angles)
    );
}

#[test]
fn g234_alarms() {
    let m = umc();
    // No H at all.
    let a = alarm(&m, "G21 G234\n");
    assert_eq!(a.condition, Condition::NoDataAfterAddress);
    assert!(a.message.contains("G234"), "{}", a.message);
    // P is not a word of G234.
    let a = alarm(&m, "G21 G53 G0 Z-300.\nG234 H1 P1\n");
    assert_eq!(a.condition, Condition::WordNotUsed);
    // Not in the dynamic work offset.
    let a = alarm(&m, "G21 G43 H1 X0. Y0. Z150.\nG254\nG234 H1\n");
    assert_eq!(a.condition, Condition::FeatureNotAllowed);
    assert_eq!(a.line, 3);
    // FANUC has no G234.
    let mut fanuc = umc();
    fanuc.control = Control::Fanuc30i;
    let a = alarm(&fanuc, "G21 G53 G0 Z-300.\nG234 H1\n");
    assert_eq!(a.condition, Condition::ImproperGCode);
}

// ----- G254 / G255 --------------------------------------------------------

#[test]
fn g254_work_zero_follows_the_tilted_table() {
    let m = umc();
    let program = "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG0 B90. C0.\nG254\nG0 X10. Y5.\nZ20.\nG1 X30. F500.\nG255\nG0 B0.\n";
    let rows = run(&m, program);
    // The work zero G54, 30 mm above the B centre, turns by B90 to
    // (−351, −254, −430); X Y Z are taken from it along the machine's
    // axes, the tool along Z.
    let zero = b90(G54);
    assert_close(&zero, &[-351.0, -254.0, -430.0], "turned work zero");
    for (line, p) in [(5, [10.0, 5.0, 20.0]), (6, [30.0, 5.0, 20.0])] {
        let row = end_of(&rows, line);
        let expected = [
            zero[0] + p[0],
            zero[1] + p[1],
            zero[2] + p[2] + L,
            90.0,
            0.0,
        ];
        assert_close(&row.joints[..5], &expected, &format!("line {line} axes"));
        // On the part: turned back by B90, (x, y, z) is (−z, y, x) from
        // the work zero.
        let on_part = work([-p[2], p[1], p[0]]);
        assert_close(&tip(&m, row), &on_part, &format!("line {line} tip"));
    }
    // X of the program is the machine's X: line 6 moves X only.
    let (a, b) = (end_of(&rows, 5), end_of(&rows, 6));
    assert!((b.joints[0] - a.joints[0] - 20.0).abs() < EPS);
    assert!((b.joints[2] - a.joints[2]).abs() < EPS);
    // After G255 the rotary axes move again.
    assert!((end_of(&rows, 8).joints[3]).abs() < EPS);
}

#[test]
fn g254_canned_cycle_drills_along_the_tool() {
    let m = umc();
    let rows = run(
        &m,
        "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG0 B90.\nG254\nG0 X10. Y5. Z20.\nG98 G81 X10. Y5. Z-5. R2. F100.\nG80\n",
    );
    let zero = b90(G54);
    let feeds: Vec<&Row> = rows
        .iter()
        .filter(|r| r.line == 5 && r.motion == fiveaxis_control::Motion::Linear)
        .collect();
    assert_eq!(feeds.len(), 1, "{rows:#?}");
    // The bottom of the hole: the turned work zero + (10, 5, −5), the
    // feed straight down the machine's Z from R.
    let expected = [zero[0] + 10.0, zero[1] + 5.0, zero[2] - 5.0 + L, 90.0, 0.0];
    assert_close(&feeds[0].joints[..5], &expected, "bottom");
    let last = rows.last().expect("rows");
    assert_close(
        &last.joints[..3],
        &[zero[0] + 10.0, zero[1] + 5.0, zero[2] + 20.0 + L],
        "back at the initial level",
    );
}

#[test]
fn g254_work_zero_follows_the_turned_platter() {
    let m = umc();
    // G55 is 40 mm off the C line in X; C90 turns it to (−381, −214).
    let rows = run(
        &m,
        "G21 G90 G55 G43 H1 X0. Y0. Z150.\nG0 B0. C90.\nG254\nG0 X10. Y5. Z20.\nG255\n",
    );
    let row = end_of(&rows, 4);
    let expected = [-381.0 + 10.0, -214.0 + 5.0, G55[2] + 20.0 + L, 0.0, 90.0];
    assert_close(&row.joints[..5], &expected, "axes");
    // On the part: turned back by C90, (x, y) is (y, −x) from G55.
    let on_part = [G55[0] + 5.0, G55[1] - 10.0, G55[2] + 20.0];
    assert_close(&tip(&m, row), &on_part, "tip");
}

#[test]
fn g254_at_rotary_zero_is_plain_length_compensation() {
    let m = umc();
    let rows = run(
        &m,
        "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG254\nG0 X10. Y5. Z20.\n",
    );
    let expected = [G54[0] + 10.0, G54[1] + 5.0, G54[2] + 20.0 + L];
    assert_close(&end_of(&rows, 3).joints[..3], &expected, "axes");
}

#[test]
fn work_offsets_selected_again_in_g254_as_the_nx_umc_post_writes_them() {
    // NX's Haas UMC-750 post: `G254`, then `G54 G90 G00 X… Y…`. Selecting
    // the offset in DWO is accepted; the DWO frame's work zero is the
    // offset now in force, turned with the table.
    let m = umc();
    let rows = run(
        &m,
        "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG0 B90. C0.\nG254\nG54 G90 G00 X10. Y5.\nZ20.\nG255\n",
    );
    let zero = b90(G54);
    let row = end_of(&rows, 5);
    let expected = [zero[0] + 10.0, zero[1] + 5.0, zero[2] + 20.0 + L, 90.0, 0.0];
    assert_close(&row.joints[..5], &expected, "G54 again: axes");
    // On the part: (x, y, z) turned back by B90 is (−z, y, x) from G54.
    assert_close(&tip(&m, row), &work([-20.0, 5.0, 10.0]), "G54 again: tip");
    // Another offset selected in DWO: G55, 40 mm off the C line, turned
    // by C90 to (−381, −214); the same as G55 selected before G254.
    let rows = run(
        &m,
        "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG0 B0. C90.\nG254\nG55 G90 G00 X10. Y5.\nZ20.\nG255\n",
    );
    let row = end_of(&rows, 5);
    let expected = [-381.0 + 10.0, -214.0 + 5.0, G55[2] + 20.0 + L, 0.0, 90.0];
    assert_close(&row.joints[..5], &expected, "G55 in DWO: axes");
    let on_part = [G55[0] + 5.0, G55[1] - 10.0, G55[2] + 20.0];
    assert_close(&tip(&m, row), &on_part, "G55 in DWO: tip");
}

#[test]
fn work_offsets_selected_again_in_g234_as_the_nx_umc_post_writes_them() {
    // NX's form: `G234 H02`, then `G54 G90 X Y Z`. The TCPC frame (the
    // table's at rotary 0) takes the offset in force: the tip lands on
    // G54 + (x, y, z) of the part, then on G55 + (x, y, z) after G55.
    let m = umc();
    let rows = run(
        &m,
        "G21 G90 G53 G0 Z-300.\nG234 H1\nG54 G90 X10. Y5. Z20. B90. C0.\nG55 G90 X10. Y5. Z20.\nG54 X30.\nG49\n",
    );
    for (line, zero, p) in [
        (3, G54, [10.0, 5.0, 20.0]),
        (4, G55, [10.0, 5.0, 20.0]),
        (5, G54, [30.0, 5.0, 20.0]),
    ] {
        let row = end_of(&rows, line);
        let on_part = [zero[0] + p[0], zero[1] + p[1], zero[2] + p[2]];
        assert_close(&tip(&m, row), &on_part, &format!("line {line} tip"));
        assert_close(&row.joints[3..5], &[90.0, 0.0], &format!("line {line} B C"));
    }
}

#[test]
fn g254_alarms() {
    let m = umc();
    // Rotary motion in DWO.
    let a = alarm(&m, "G21 G43 H1 X0. Y0. Z150.\nG254\nG0 B10.\n");
    assert_eq!((a.condition, a.line), (Condition::FeatureNotAllowed, 3));
    assert!(a.message.contains("G255"), "{}", a.message);
    // Not in TCPC.
    let a = alarm(&m, "G21 G53 G0 Z-300.\nG234 H1\nG254\n");
    assert_eq!((a.condition, a.line), (Condition::FeatureNotAllowed, 3));
    // Not in the feature coordinate system.
    let a = alarm(&m, "G21 G268 J30.\nG254\n");
    assert_eq!((a.condition, a.line), (Condition::FeatureNotAllowed, 2));
    // G269 and G69 do not end DWO: still no rotary motion.
    let a = alarm(&m, "G21 G43 H1 X0. Y0. Z150.\nG254\nG269\nG69\nG0 C10.\n");
    assert_eq!((a.condition, a.line), (Condition::FeatureNotAllowed, 5));
    // G255 without G254 is nothing.
    run(&m, "G21 G255\nG0 C10.\n");
}

// ----- G268 / G269 / G253 -------------------------------------------------

#[test]
fn g268_feature_frame_and_g253_point_the_tool_along_its_z() {
    let m = umc();
    // J90 about Y: the feature's Z is the part's +X. G253 tilts B to 90
    // and turns C to 180 (B −90 is beyond the stroke).
    let program = "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG268 X0. Y0. Z0. I0. J90. K0. Q123\nG253\nG0 X10. Y5. Z20.\nG269\n";
    let rows = run(&m, program);
    let row = end_of(&rows, 4);
    // R = Ry(90): (10, 5, 20) → (20, 5, −10) on the part.
    let q = work([20.0, 5.0, -10.0]);
    assert_close(&tip(&m, row), &q, "tip");
    let dir = m.forward(&row.joints, L).dir;
    assert_close(&[dir.x, dir.y, dir.z], &[1.0, 0.0, 0.0], "tool direction");
    // By hand: C180 takes (x, y) about the C line to (−x, −y), then B90
    // about the B centre.
    let c180 = [2.0 * G54[0] - q[0], 2.0 * G54[1] - q[1], q[2]];
    let t = b90(c180);
    assert_close(
        &row.joints[..5],
        &[t[0], t[1], t[2] + L, 90.0, 180.0],
        "axes",
    );
}

#[test]
fn g268_q_is_the_order_of_the_turns_about_the_fixed_axes() {
    let m = umc();
    // I90 J90: Q123 turns about X first (Z → −Y), then about Y (−Y
    // stays): the feature Z is −Y. Q213 turns about Y first (Z → +X),
    // then about X (+X stays): the feature Z is +X.
    for (q, z) in [("Q123", [0.0, -1.0, 0.0]), ("Q213", [1.0, 0.0, 0.0])] {
        let program = format!("G21 G90 G54 G43 H1 X0. Y0. Z150.\nG268 I90. J90. {q}\nG253\n");
        let rows = run(&m, Box::leak(program.into_boxed_str()));
        let dir = m.forward(&end_of(&rows, 3).joints, L).dir;
        assert_close(&[dir.x, dir.y, dir.z], &z, q);
    }
    // Q left out is Q123.
    let rows = run(
        &m,
        "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG268 I90. J90.\nG253\n",
    );
    let dir = m.forward(&end_of(&rows, 3).joints, L).dir;
    assert_close(&[dir.x, dir.y, dir.z], &[0.0, -1.0, 0.0], "default");
}

#[test]
fn g268_alarms() {
    let m = umc();
    for q in ["Q124", "Q12", "Q1234", "Q112", "Q12.3"] {
        let a = alarm(&m, &format!("G21 G268 J30. {q}\n"));
        assert!(
            matches!(
                a.condition,
                Condition::FeatureDefinition
                    | Condition::ValueOutOfRange
                    | Condition::DecimalPointNotAllowed
            ),
            "{q}: {a:?}"
        );
    }
    // G253 needs G268.
    let a = alarm(&m, "G21 G253\n");
    assert_eq!(a.condition, Condition::FeatureNotAllowed);
    // G269 under TCPC.
    let a = alarm(&m, "G21 G53 G0 Z-300.\nG268 J30.\nG234 H1\nG269\n");
    assert_eq!((a.condition, a.line), (Condition::FeatureNotAllowed, 4));
}

// ----- G187 ---------------------------------------------------------------

#[test]
fn g187_smoothness_is_kept_and_moves_nothing() {
    let m = umc();
    let accuracy = |p: &'static str| {
        let r = run_on(&m, p);
        assert!(r.alarm.is_none(), "{p}: {:?}", r.alarm);
        assert!(r.rows.is_empty(), "{p}");
        r.runner.controller().modal().accuracy
    };
    assert_eq!(accuracy("G21\n").smoothness, 0);
    let a = accuracy("G21 G187 P3 E0.01\n");
    assert_eq!((a.smoothness, a.corner_rounding), (3, Some(0.01)));
    // Inch (Setting 9 = INCH, the built-in's own): E0.001 in is 0.0254 mm.
    let inch = builtin_at_zero("haas-umc750").expect("built-in");
    let r = run_on(&inch, "G20 G187 P1 E.001\n");
    assert!(r.alarm.is_none(), "{:?}", r.alarm);
    let a = r.runner.controller().modal().accuracy;
    assert_eq!(a.smoothness, 1);
    assert!((a.corner_rounding.expect("E") - 0.0254).abs() < EPS);
    // G187 alone returns to the settings.
    let a = accuracy("G21 G187 P2 E0.05\nG187\n");
    assert_eq!((a.smoothness, a.corner_rounding), (0, None));
    for bad in ["G187 P4", "G187 P0", "G187 P2 E0", "G187 E-1."] {
        let a = alarm(&m, &format!("G21 {bad}\n"));
        assert_eq!(a.condition, Condition::ValueOutOfRange, "{bad}");
    }
}

// ----- G154 / G110 --------------------------------------------------------

#[test]
fn g154_and_g110_select_the_additional_work_offsets() {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in");
    m.control = Control::Haas;
    let x = |p: &'static str| run(&m, p)[0].joints[0];
    assert!((x("G154 P7 G0 X0.\n") - 7.0).abs() < EPS);
    assert!((x("G110 G0 X0.\n") - 1.0).abs() < EPS);
    assert!((x("G154 P99 G0 X0.\n") - 99.0).abs() < EPS);
    assert!((x("G154 P1 G0 X0.\n") - 1.0).abs() < EPS);
    // #14001 + 20 (P - 1): G154 P7's X is #14121; #4014 reads 154.
    assert!((x("#1=#14121\nG53 G0 X#1\n") - 7.0).abs() < EPS);
    assert!((x("G154 P7\n#1=#4014\nG53 G0 X#1\n") - 154.0).abs() < EPS);
    let a = alarm(&m, "G154 G0 X0.\n");
    assert_eq!(a.condition, Condition::NoDataAfterAddress);
    let a = alarm(&m, "G154 P100 G0 X0.\n");
    assert_eq!(a.condition, Condition::IllegalOffsetNumber);
    let a = alarm(&m, "G154 P0 G0 X0.\n");
    assert_eq!(a.condition, Condition::IllegalOffsetNumber);
    // FANUC: no G154, G54.1 P stops at 48.
    m.control = Control::Fanuc30i;
    assert_eq!(alarm(&m, "G154 P7\n").condition, Condition::ImproperGCode);
    assert_eq!(alarm(&m, "G110\n").condition, Condition::ImproperGCode);
    let a = alarm(&m, "G54.1 P49\n");
    assert_ne!(a.condition, Condition::ImproperGCode);
}

// ----- M codes ------------------------------------------------------------

#[test]
fn haas_m10_to_m13_are_the_fourth_and_fifth_axis_brakes() {
    let m = umc();
    let a = alarm(&m, "G21 M10\nG0 B10.\n");
    assert_eq!((a.condition, a.line), (Condition::ClampedAxisMoved, 2));
    assert!(a.message.contains("M11"), "{}", a.message);
    let a = alarm(&m, "G21 M12\nG0 C10.\n");
    assert_eq!((a.condition, a.line), (Condition::ClampedAxisMoved, 2));
    assert!(a.message.contains("M13"), "{}", a.message);
    // The other axis is free; unclamping frees it.
    run(&m, "G21 M10\nG0 C10.\nM11\nG0 B10.\nM12 M13\nG0 C20.\n");
    // On the VF-2 with TR160 the fourth axis is A, the fifth B.
    let vf = metric("haas-vf2-tr160");
    let a = alarm(&vf, "G21 M10\nG0 A10.\n");
    assert_eq!(a.condition, Condition::ClampedAxisMoved);
    let a = alarm(&vf, "G21 M12\nG0 B10.\n");
    assert_eq!(a.condition, Condition::ClampedAxisMoved);
    let r = run_on(&vf, "G21 M10 M12\n");
    let clamped: Vec<char> = r.runner.controller().clamped_axes().collect();
    assert_eq!(clamped, ['A', 'B']);
}

#[test]
fn haas_standard_m_codes_run_and_others_are_refused() {
    let m = umc();
    let r = run_on(
        &m,
        "G21 T1 M06\nS1000 M03\nM08\nM88\nM89\nM83\nM84\nM31\nM33\nM19\nM16\nM05\nM09\nM01\nM00\nM30\n",
    );
    assert!(r.alarm.is_none(), "{:?}", r.alarm);
    assert!(!r.runner.controller().coolant());
    // M29 is not Haas's rigid tapping (G84 taps rigidly by itself).
    let a = alarm(&m, "M29\n");
    assert_eq!(a.condition, Condition::UnsupportedMCode);
}

#[test]
fn haas_m97_calls_a_local_subprogram_by_sequence_number() {
    // The manual's pattern: M97 P1000 L… runs N1000 up to its M99, L
    // times, then the block after the call.
    let mut m = builtin_at_zero("mill-3axis").expect("built-in");
    m.control = Control::Haas;
    let program = "G21 G53 G0 X0. Y0. Z0.\nM97 P1000 L3\nG53 G0 X-5.\nM30\nN1000 G91 G1 X1. F100.\nG90\nM99\n";
    let rows = run(&m, program);
    let path: Vec<(u32, f64)> = rows.iter().map(|r| (r.line, r.joints[0])).collect();
    assert_eq!(path, [(5, 1.0), (5, 2.0), (5, 3.0), (3, -5.0)]);
    // L left out is once.
    let rows = run(
        &m,
        "G21 G53 G0 X0. Y0. Z0.\nM97 P20\nM30\nN20 G91 G1 X1. F100.\nG90\nM99\n",
    );
    assert_eq!(rows.len(), 1);
    let a = alarm(&m, "M97\n");
    assert_eq!(a.condition, Condition::SubprogramNumberMissing);
    let a = alarm(&m, "M97 P2000\nM30\n");
    assert_eq!(a.condition, Condition::ProgramNotFound);
    // FANUC has no M97.
    m.control = Control::Fanuc30i;
    let a = alarm(&m, "M97 P1000\nM30\nN1000 M99\n");
    assert_eq!(a.condition, Condition::UnsupportedMCode);
}

#[test]
fn haas_tool_variables_and_g10_follow_haas_s_numbering() {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in");
    m.control = Control::Haas;
    let x = |p: &'static str| run(&m, p)[0].joints[0];
    // #2001 + n - 1: length (tool 1 = 100 mm); #2201: length wear.
    assert!((x("G21\n#1=#2001\nG53 G0 X#1\n") - L).abs() < EPS);
    // G10 L1 (Haas: as L11) writes the wear that #2201 reads.
    assert!((x("G21 G10 L1 P1 R0.5\n#1=#2201\nG53 G0 X#1\n") - 0.5).abs() < EPS);
    assert!((x("G21 G10 L11 P1 R0.25\n#1=#2201\nG53 G0 X#1\n") - 0.25).abs() < EPS);
    // #2401: the radius, #2601 its wear.
    assert!((x("G21 G10 L12 P1 R4.\n#1=#2401\nG53 G0 X#1\n") - 4.0).abs() < EPS);
    assert!((x("G21 G10 L13 P1 R0.1\n#1=#2601\nG53 G0 X#1\n") - 0.1).abs() < EPS);
    // G10 L20 P1-P99: G154 P1-P99.
    assert!((x("G21 G10 L20 P50 X12.\nG154 P50 G0 X0.\n") - 12.0).abs() < EPS);
    let a = alarm(&m, "G21 G10 L20 P100 X1.\n");
    assert_eq!(a.condition, Condition::IllegalG10P);
    // FANUC: #2001 is the length wear (0 here), #2201 the length.
    let mut m = m.clone();
    m.control = Control::Fanuc30i;
    let x = |p: &'static str| run(&m, p)[0].joints[0];
    assert!((x("G21\n#1=#2001+1.\nG53 G0 X#1\n") - 1.0).abs() < EPS);
    assert!((x("G21\n#1=#2201\nG53 G0 X#1\n") - L).abs() < EPS);
    assert_eq!(
        alarm(&m, "G21 G10 L20 P49 X1.\n").condition,
        Condition::IllegalG10P
    );
}

// ----- random cases, judged by forward kinematics -------------------------

/// The rotation of `deg` degrees about unit axis `k` (0 X, 1 Y, 2 Z),
/// right-hand rule, as a matrix written out by hand.
fn about(k: usize, deg: f64) -> [[f64; 3]; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    match k {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn apply(a: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn transpose(a: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}

/// Rows of a program run with the soft limits lifted (the random cases
/// test positions, not travels).
fn run_lifted(machine: &Machine, program: &str) -> Result<Vec<Row>, Alarm> {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions {
            lift_soft_limits: true,
            ..RunOptions::default()
        },
    );
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push(seg.row(machine, 1.0)),
            Ok(None) => return Ok(rows),
            Err(RunError::Alarm { alarm, .. }) => return Err(alarm),
            Err(e) => panic!("{e}"),
        }
    }
}

/// Distance of two points.
fn gap(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// Rounding of the random cases (values printed with 4 decimals), mm.
const RANDOM_EPS: f64 = 1e-7;

#[test]
fn random_g254_g234_and_g268_points_land_where_the_manual_puts_them() {
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngSeed, TestRunner};
    let m = umc();
    let config = Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x0254_0234),
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner = TestRunner::new(config);
    let p = || -80.0f64..80.0;
    let strategy = (-30.0f64..110.0, 0.0f64..360.0, (p(), p(), p()));
    runner
        .run(&strategy, |(b, c, (x, y, z))| {
            let (b, c) = ((b * 1e4).round() / 1e4, (c * 1e4).round() / 1e4);
            let (x, y, z) = (
                (x * 1e4).round() / 1e4,
                (y * 1e4).round() / 1e4,
                (z * 1e4).round() / 1e4,
            );
            // The table's turn at B, C: the part is carried by C, C by B
            // (bed outwards), both about lines through the centres.
            let rot = mul(&about(1, b), &about(2, c));
            // G254: on the part the point is G54 + rot⁻¹ (x, y, z).
            let program = format!(
                "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG0 B{b:.4} C{c:.4}\nG254\nG0 X{x:.4} Y{y:.4} Z{z:.4}\n"
            );
            let rows = run_lifted(&m, &program).map_err(|a| TestCaseError::fail(format!("{a:?}")))?;
            let back = apply(&transpose(&rot), [x, y, z]);
            let want = work(back);
            let got = tip(&m, end_of(&rows, 4));
            prop_assert!(gap(got, want) < RANDOM_EPS, "G254 {got:?} vs {want:?}");
            // The tool along the machine's Z: on the part, rot⁻¹ Z.
            let dir = m.forward(&end_of(&rows, 4).joints, L).dir;
            let z_back = apply(&transpose(&rot), [0.0, 0.0, 1.0]);
            prop_assert!(gap([dir.x, dir.y, dir.z], z_back) < RANDOM_EPS);
            // G234: on the part the point is G54 + (x, y, z) itself.
            let program = format!(
                "G21 G90 G54\nG234 H1 G0 X0. Y0. Z150.\nG0 B{b:.4} C{c:.4} X{x:.4} Y{y:.4} Z{z:.4}\n"
            );
            let rows = run_lifted(&m, &program).map_err(|a| TestCaseError::fail(format!("{a:?}")))?;
            let got = tip(&m, end_of(&rows, 3));
            prop_assert!(gap(got, work([x, y, z])) < RANDOM_EPS, "G234 {got:?}");
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    // G268 with random angles and orders: the point G54 + origin + R p,
    // R the turns in the order Q names about the fixed axes; G253 points
    // the tool along R Z.
    let mut runner = TestRunner::new(Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x0268_0253),
        failure_persistence: None,
        ..Config::default()
    });
    let orders = ["123", "132", "213", "231", "312", "321"];
    let judged = std::cell::Cell::new(0u32);
    let a = || -60.0f64..60.0;
    let strategy = (
        (a(), a(), a()),
        0usize..6,
        (p(), p(), p()),
        (-20.0f64..20.0, -20.0f64..20.0, -20.0f64..20.0),
    );
    runner
        .run(&strategy, |((i, j, k), q, (x, y, z), (ox, oy, oz))| {
            let r4 = |v: f64| (v * 1e4).round() / 1e4;
            let (i, j, k, x, y, z, ox, oy, oz) =
                (r4(i), r4(j), r4(k), r4(x), r4(y), r4(z), r4(ox), r4(oy), r4(oz));
            let order = orders[q];
            let angles = [i, j, k];
            let mut r = about(0, 0.0);
            for d in order.bytes() {
                let axis = usize::from(d - b'1');
                r = mul(&about(axis, angles[axis]), &r);
            }
            let program = format!(
                "G21 G90 G54 G43 H1 X0. Y0. Z150.\nG268 X{ox:.4} Y{oy:.4} Z{oz:.4} I{i:.4} J{j:.4} K{k:.4} Q{order}\nG253\nG0 X{x:.4} Y{y:.4} Z{z:.4}\n"
            );
            let rows = match run_lifted(&m, &program) {
                Ok(rows) => rows,
                // A tool direction the B stroke cannot reach is the
                // control's alarm, not a wrong position.
                Err(a) if a.condition == Condition::ToolDirectionUnreachable => return Ok(()),
                Err(a) => return Err(TestCaseError::fail(format!("{a:?}"))),
            };
            let rp = apply(&r, [x, y, z]);
            let want = work([ox + rp[0], oy + rp[1], oz + rp[2]]);
            let got = tip(&m, end_of(&rows, 4));
            prop_assert!(gap(got, want) < RANDOM_EPS, "G268 Q{order} {got:?} vs {want:?}");
            let dir = m.forward(&end_of(&rows, 4).joints, L).dir;
            let rz = apply(&r, [0.0, 0.0, 1.0]);
            prop_assert!(gap([dir.x, dir.y, dir.z], rz) < RANDOM_EPS, "G268 Q{order} dir");
            judged.set(judged.get() + 1);
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    // Most directions within 60° per angle are reachable: the test judges.
    assert!(judged.get() >= 32, "only {} cases judged", judged.get());
}
