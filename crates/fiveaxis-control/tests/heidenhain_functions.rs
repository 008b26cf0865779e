//! HEIDENHAIN Klartext functions on the command path, judged against
//! points worked out by hand in each test (the `why` of every fixture)
//! and the machine's forward kinematics (`Row::tip`, `Row::dir` and
//! `Row::joints`).
//!
//! Programs run on the 3-axis mill (`mill-3axis`, cloned with
//! `control = Heidenhain`) or the built-in `heidenhain-dmu-ac`, both
//! with their reference positions at machine zero. Tool 1 is 100 mm long
//! with a 5 mm radius; G54 (preset 0) is X100 Y50 Z0 on the mill and
//! X0 Y0 Z-300 on the DMU (its Z travel is −650 … 0).
//!
//! Every program is written between `BEGIN PGM` and `END PGM`, so the
//! n-th block of the list handed to [`program`] is line n + 1 of the text.
//! A path block held back for a rounding shows its segment when the next
//! block is read; rows keep their own block's line.
//!
//! A test marked `//! something else than the manual says; the reason gives what was
//! expected and what happens.

mod common;

use common::builtin_at_zero;
use fiveaxis_control::{Alarm, Condition, Motion, Row};
use fiveaxis_machine::{Control, Machine, Offsets, ToolOffset, Vec3};

const EPS: f64 = 1e-6;
const LENGTH: f64 = 100.0;

fn mill() -> Machine {
    let mut m = builtin_at_zero("mill-3axis").expect("built-in");
    m.control = Control::Heidenhain;
    m
}

fn dmu() -> Machine {
    builtin_at_zero("heidenhain-dmu-ac").expect("built-in")
}

fn offsets_with(work: Vec3) -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: LENGTH,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    o.tools.insert(
        2,
        ToolOffset {
            length: 80.0,
            radius: 3.0,
            ..ToolOffset::default()
        },
    );
    o.work[0] = work;
    o.extended_work[0] = Vec3::new(-20.0, 10.0, 5.0);
    o
}

fn offsets_for(machine: &Machine) -> Offsets {
    if machine.rotary.is_empty() {
        offsets_with(Vec3::new(100.0, 50.0, 0.0))
    } else {
        offsets_with(Vec3::new(0.0, 0.0, -300.0))
    }
}

/// The blocks between `BEGIN PGM` and `END PGM`.
fn program(blocks: &[&str]) -> String {
    let mut text = String::from("BEGIN PGM T MM\n");
    for b in blocks {
        text.push_str(b);
        text.push('\n');
    }
    text.push_str("END PGM T MM\n");
    text
}

/// Line of the n-th block (from 1) in [`program`]'s text.
const fn line(block: u32) -> u32 {
    block + 1
}

fn sampled(machine: &Machine, blocks: &[&str], s: &[f64]) -> (Vec<Row>, Option<Alarm>) {
    common::run_sampled(machine, offsets_for(machine), &program(blocks), s)
}

fn ends(machine: &Machine, blocks: &[&str]) -> (Vec<Row>, Option<Alarm>) {
    sampled(machine, blocks, &[1.0])
}

fn ok(machine: &Machine, blocks: &[&str]) -> Vec<Row> {
    let (rows, alarm) = ends(machine, blocks);
    assert!(alarm.is_none(), "{alarm:?}\n{}", program(blocks));
    rows
}

fn alarm_of(machine: &Machine, blocks: &[&str]) -> Alarm {
    let (_, alarm) = ends(machine, blocks);
    alarm.unwrap_or_else(|| panic!("no alarm for\n{}", program(blocks)))
}

fn v(p: [f64; 3]) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

fn assert_tip(row: &Row, want: [f64; 3]) {
    assert!(
        (row.tip - v(want)).norm() < EPS,
        "line {} s {}: tip {:?}, want {want:?}",
        row.line,
        row.s,
        row.tip
    );
}

/// The machine's X, Y, Z in `row` are `want`.
fn assert_linear(row: &Row, want: [f64; 3]) {
    assert!(
        row.joints[..3]
            .iter()
            .zip(want)
            .all(|(j, w)| (j - w).abs() < EPS),
        "line {}: machine X Y Z {:?}, want {want:?}",
        row.line,
        &row.joints[..3]
    );
}

/// The row at the end of line `l`'s last segment.
fn at(rows: &[Row], l: u32) -> &Row {
    rows.iter()
        .rfind(|r| r.line == l)
        .unwrap_or_else(|| panic!("no segment of line {l}"))
}

fn of_line(rows: &[Row], l: u32) -> Vec<&Row> {
    rows.iter().filter(|r| r.line == l).collect()
}

// ----- L: absolute, incremental, feeds ------------------------------------

#[test]
fn l_absolute_then_incremental_and_machine_position() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+10 Y+20 Z+5 R0 FMAX",
            "L IX+5 IY-5 F500",
        ],
    );
    let r = at(&rows, line(2));
    // Why: absolute target; FMAX is a rapid.
    assert_tip(r, [10.0, 20.0, 5.0]);
    assert_eq!(r.motion, Motion::Rapid);
    // Why: the machine stands at G54 + tip + tool length along +Z.
    let want = [110.0, 70.0, 105.0];
    assert_linear(r, want);
    let r = at(&rows, line(3));
    // Why: IX+5 IY-5 from (10, 20).
    assert_tip(r, [15.0, 15.0, 5.0]);
    assert_eq!(r.motion, Motion::Linear);
    assert_eq!(r.feed, Some(500.0));
}

#[test]
fn fmax_holds_for_its_block_only_and_f_auto_is_the_tool_call_feed() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000 F250",
            "L X+0 Y+0 Z+5 R0 F300",
            "L X+20 FMAX",
            "L X+30",
            "L X+40 F AUTO",
        ],
    );
    assert_eq!(at(&rows, line(2)).feed, Some(300.0));
    assert_eq!(at(&rows, line(3)).feed, None);
    // Why: the F300 of line 2 is modal, FMAX was for its block only.
    assert_eq!(at(&rows, line(4)).feed, Some(300.0));
    // Why: F AUTO is the F of the TOOL CALL.
    assert_eq!(at(&rows, line(5)).feed, Some(250.0));
}

#[test]
fn tool_call_length_and_dl_are_active_at_once() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000 DL+2",
            "L X+0 Y+0 Z+5 R0 FMAX",
            "TOOL CALL 2 Z S1000",
            "L Z+5 FMAX",
        ],
    );
    // Why: 100 + DL 2 above the tip at Z5.
    assert!((at(&rows, line(2)).joints[2] - 107.0).abs() < EPS);
    assert_tip(at(&rows, line(2)), [0.0, 0.0, 5.0]);
    // Why: tool 2 is 80 long, no delta.
    assert!((at(&rows, line(4)).joints[2] - 85.0).abs() < EPS);
    assert_tip(at(&rows, line(4)), [0.0, 0.0, 5.0]);
}

#[test]
fn m91_moves_in_machine_coordinates_without_tool_length() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+10 Y+20 Z+5 R0 FMAX",
            "L Z-20 R0 FMAX M91",
            "L X+0 Y+0 FMAX M91",
        ],
    );
    let r = at(&rows, line(3));
    // Why: M91 Z-20 is the machine's Z; X and Y stay at 110, 70.
    let want = [110.0, 70.0, -20.0];
    assert_linear(r, want);
    let r = at(&rows, line(4));
    let want = [0.0, 0.0, -20.0];
    assert_linear(r, want);
    // Why: the tip is the machine position less G54 and the tool length.
    assert_tip(r, [-100.0, -50.0, -120.0]);
}

// ----- circles ----------------------------------------------------------------

#[test]
fn c_about_the_pole_counter_clockwise() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+30 Y+0 Z+0 R0 F500",
            "CC X+0 Y+0",
            "C X+0 Y+30 DR+",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let arc = of_line(&rows, line(4));
    // Why: a quarter circle of radius 30 from 0° to 90°: half way at 45°.
    let h = 30.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert_tip(arc[0], [h, h, 0.0]);
    assert_tip(arc[1], [0.0, 30.0, 0.0]);
    assert_eq!(arc[1].motion, Motion::Ccw);
}

#[test]
fn cr_positive_radius_is_the_short_arc_negative_the_long() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "CR X+20 Y+0 R+10 DR+",
            "CR X+0 Y+0 R-15 DR+",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: chord 20 = diameter: the half circle about (10, 0), counter-
    // clockwise from 180° through 270°.
    let half = of_line(&rows, line(3));
    assert_tip(half[0], [10.0, -10.0, 0.0]);
    assert_tip(half[1], [20.0, 0.0, 0.0]);
    // Why: back from (20,0) to (0,0), R15: the centre lies sqrt(15² − 10²)
    // off the chord's middle; counter-clockwise from right to left the
    // short way passes above the chord about a centre below it, so the
    // long way (R−) turns about (10, +11.18) and passes under the chord
    // and up over the top: half way straight above the centre.
    let h = (15.0f64 * 15.0 - 100.0).sqrt();
    let long = of_line(&rows, line(4));
    assert_tip(long[0], [10.0, h + 15.0, 0.0]);
    assert_tip(long[1], [0.0, 0.0, 0.0]);
}

#[test]
fn ct_continues_tangentially() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+20 Y+0",
            "CT X+30 Y+10",
        ],
        &[0.001, 0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: leaving (20,0) along +X towards (30,10): the circle through both
    // with its tangent along X at (20,0) is about (20,10), radius 10; half
    // way is at −45° about the centre.
    let arc = of_line(&rows, line(4));
    let h = 10.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert_tip(arc[1], [20.0 + h, 10.0 - h, 0.0]);
    assert_tip(arc[2], [30.0, 10.0, 0.0]);
    assert_eq!(arc[2].motion, Motion::Ccw);
    // Tangency: just after the start the path has hardly left the X axis
    // (a circle of radius 10 rises by l²/20 over a length l).
    let first = arc[0];
    let l = first.tip.x - 20.0;
    assert!(
        l > 0.0 && (first.tip.y - l * l / 20.0).abs() < 1e-6,
        "{first:?}"
    );
}

#[test]
fn polar_line_and_helix_turns() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+20 Y+0 Z+0 R0 F500",
            "CC X+0 Y+0",
            "CP IPA+720 IZ-4 DR+",
            "LP PR+10 PA+30",
            "CP IPA+450 IZ-5 DR+",
        ],
        &[0.125, 0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: two full turns of radius 20 down 4: an eighth of the way is
    // 90° and 0.5 down, half way one turn and 2 down.
    let helix = of_line(&rows, line(4));
    assert_tip(helix[0], [0.0, 20.0, -0.5]);
    assert_tip(helix[1], [20.0, 0.0, -2.0]);
    assert_tip(helix[2], [20.0, 0.0, -4.0]);
    // Why: PR10 PA30 about the pole.
    let c30 = 30f64.to_radians();
    assert_tip(
        at(&rows, line(5)),
        [10.0 * c30.cos(), 10.0 * c30.sin(), -4.0],
    );
    // Why: 450° from 30°: half way 225° further (255°), the end at 120°.
    let helix = of_line(&rows, line(6));
    let p = |deg: f64, z: f64| {
        let r = deg.to_radians();
        [10.0 * r.cos(), 10.0 * r.sin(), z]
    };
    assert_tip(helix[1], p(255.0, -6.5));
    assert_tip(helix[2], p(120.0, -9.0));
}

// ----- RND and CHF ------------------------------------------------------------

#[test]
fn rnd_between_two_lines() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "RND R10",
            "L X+40 Y+40",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: a left turn of 90° at (40,0): the circle of radius 10 inside it
    // is about (30,10), touching the first line at (30,0) and the second
    // at (40,10); half way round it is at −45° about the centre.
    assert_tip(at(&rows, line(3)), [30.0, 0.0, 0.0]);
    let round = of_line(&rows, line(4));
    let h = 10.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert_tip(round[0], [30.0 + h, 10.0 - h, 0.0]);
    assert_tip(round[1], [40.0, 10.0, 0.0]);
    assert_eq!(round[1].motion, Motion::Ccw);
    assert_tip(at(&rows, line(5)), [40.0, 40.0, 0.0]);
}

#[test]
fn rnd_between_a_line_and_an_arc() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "RND R5",
            "CR X+60 Y+20 R+20 DR-",
        ],
        &[1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: the arc is the clockwise quarter about (60,0) from (40,0) to
    // (60,20): the path turns left onto it. The rounding's centre is 5
    // above the line (y = 5) and 20 + 5 from (60,0):
    // x = 60 − sqrt(25² − 5²) = 60 − sqrt(600). It touches the line below
    // its centre and the arc on the line of centres, at 20/25 of the way
    // from (60,0).
    let x = 60.0 - 600f64.sqrt();
    assert_tip(at(&rows, line(3)), [x, 0.0, 0.0]);
    let touch = [60.0 + (x - 60.0) * 0.8, 5.0 * 0.8, 0.0];
    let round = at(&rows, line(4));
    assert_tip(round, touch);
    assert_eq!(round.motion, Motion::Ccw);
    let arc = at(&rows, line(5));
    assert_tip(arc, [60.0, 20.0, 0.0]);
    assert_eq!(arc.motion, Motion::Cw);
}

#[test]
fn chf_cuts_the_corner_of_two_lines() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "CHF 5",
            "L X+40 Y+40",
        ],
    );
    // Why: the chamfer is 5 along each line from the corner (40,0).
    assert_tip(at(&rows, line(3)), [35.0, 0.0, 0.0]);
    let chamfer = at(&rows, line(4));
    assert_tip(chamfer, [40.0, 5.0, 0.0]);
    assert_eq!(chamfer.motion, Motion::Linear);
    assert_tip(at(&rows, line(5)), [40.0, 40.0, 0.0]);
}

#[test]
fn rnd_feed_is_its_own() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "RND R10 F100",
            "L X+40 Y+40",
        ],
    );
    assert_eq!(at(&rows, line(4)).feed, Some(100.0));
    // Why: the rounding's F holds for the rounding only.
    assert_eq!(at(&rows, line(5)).feed, Some(500.0));
}

// ----- alarms -----------------------------------------------------------------

#[test]
fn c_without_cc_is_refused() {
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+30 Y+0 Z+0 R0 F500",
            "C X+0 Y+30 DR+",
        ],
    );
    assert_eq!(a.condition, Condition::ArcCenterMissing, "{a:?}");
    assert_eq!(a.line, line(3));
}

#[test]
fn cr_radius_smaller_than_half_the_chord_is_refused() {
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "CR X+30 Y+0 R+10 DR+",
        ],
    );
    assert_eq!(a.condition, Condition::ArcRadiusTolerance, "{a:?}");
    assert_eq!(a.line, line(3));
}

#[test]
fn chf_next_to_an_arc_is_refused() {
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "CHF 5",
            "CR X+60 Y+20 R+20 DR-",
        ],
    );
    assert_eq!(a.condition, Condition::CrcNoIntersection, "{a:?}");
    assert_eq!(a.line, line(4));
}

#[test]
fn rnd_without_a_path_after_it_is_refused() {
    // At the end of the program.
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "RND R5",
        ],
    );
    assert_eq!(a.condition, Condition::CrcNoIntersection, "{a:?}");
    assert_eq!(a.line, line(4));
    // Before a block that is no path.
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "RND R5",
            "TOOL CALL 2 Z",
            "L X+40 Y+40",
        ],
    );
    assert_eq!(a.condition, Condition::CrcNoIntersection, "{a:?}");
    assert_eq!(a.line, line(4));
    // First thing in the program: nothing to round.
    let a = alarm_of(&mill(), &["RND R5", "L X+40 Y+40 F500"]);
    assert_eq!(a.condition, Condition::CrcNoIntersection, "{a:?}");
}

#[test]
fn rnd_larger_than_the_lines_is_refused() {
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+10 Y+0",
            "RND R20",
            "L X+10 Y+10",
        ],
    );
    assert_eq!(a.condition, Condition::CrcNoIntersection, "{a:?}");
}

#[test]
fn plane_without_move_turn_or_stay_is_refused() {
    let a = alarm_of(
        &dmu(),
        &["TOOL CALL 1 Z S1000", "PLANE SPATIAL SPA+30 SPB+0 SPC+0"],
    );
    assert_eq!(a.condition, Condition::FeatureDefinition, "{a:?}");
    assert_eq!(a.line, line(2));
}

#[test]
fn ln_with_a_tool_vector_needs_tcpm() {
    let a = alarm_of(
        &dmu(),
        &["TOOL CALL 1 Z S1000", "LN X+0 Y+0 Z+10 TX+0 TY+0 TZ+1 F500"],
    );
    assert_eq!(a.condition, Condition::TcpcOptionMissing, "{a:?}");
    assert_eq!(a.line, line(2));
}

#[test]
fn an_axis_the_machine_has_not_is_refused() {
    // The DMU has A and C, no B.
    let a = alarm_of(&dmu(), &["TOOL CALL 1 Z S1000", "L B+10 R0 FMAX"]);
    assert_eq!(a.condition, Condition::ImproperAddress, "{a:?}");
    assert_eq!(a.line, line(2));
    // The mill has no rotary axis at all.
    let a = alarm_of(&mill(), &["TOOL CALL 1 Z S1000", "L A+10 R0 FMAX"]);
    assert_eq!(a.condition, Condition::ImproperAddress, "{a:?}");
}

#[test]
fn negative_spindle_speed_is_refused() {
    let a = alarm_of(&mill(), &["TOOL CALL 1 Z S-100"]);
    assert_eq!(a.condition, Condition::ValueOutOfRange, "{a:?}");
    assert_eq!(a.line, line(1));
}

#[test]
fn ct_without_a_path_before_is_refused() {
    let a = alarm_of(&mill(), &["TOOL CALL 1 Z S1000", "CT X+10 Y+10 F500"]);
    assert_eq!(a.condition, Condition::ArcCenterMissing, "{a:?}");
}

// ----- transformations --------------------------------------------------------

#[test]
fn datum_shift_rotation_mirror_and_scaling_each() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 X+50",
            "CYCL DEF 7.2 Y+10",
            "L X+10 Y+5 Z+0 R0 F500",
            "CYCL DEF 10.0 ROTATION",
            "CYCL DEF 10.1 ROT+90",
            "L X+10 Y+5",
            "CYCL DEF 10.0 ROTATION",
            "CYCL DEF 10.1 ROT+0",
            "CYCL DEF 8.0 MIRROR IMAGE",
            "CYCL DEF 8.1 X",
            "L X+10 Y+5",
            "CYCL DEF 8.0 MIRROR IMAGE",
            "CYCL DEF 8.1",
            "CYCL DEF 11.0 SCALING",
            "CYCL DEF 11.1 SCL 2",
            "L X+10 Y+5",
        ],
    );
    // Why: the shift adds (50, 10).
    assert_tip(at(&rows, line(5)), [60.0, 15.0, 0.0]);
    // Why: (10,5) turned 90° about the shifted datum is (−5,10).
    assert_tip(at(&rows, line(8)), [45.0, 20.0, 0.0]);
    // Why: X mirrored about the shifted datum.
    assert_tip(at(&rows, line(13)), [40.0, 15.0, 0.0]);
    // Why: scaled ×2 about the shifted datum.
    assert_tip(at(&rows, line(18)), [70.0, 20.0, 0.0]);
}

#[test]
fn datum_shift_rotation_mirror_and_scaling_together() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 X+50",
            "CYCL DEF 7.2 Y+10",
            "CYCL DEF 8.0 MIRROR IMAGE",
            "CYCL DEF 8.1 X",
            "CYCL DEF 10.0 ROTATION",
            "CYCL DEF 10.1 ROT+90",
            "CYCL DEF 11.0 SCALING",
            "CYCL DEF 11.1 SCL 2",
            "L X+10 Y+5 Z+0 R0 F500",
        ],
    );
    // Why (the kernel's reading of the order, the TNC's sequence of the
    // transformation cycles: shift, mirror, rotation, scaling): the point
    // is scaled (20,10), mirrored in X (−20,10), turned 90° (−10,−20) and
    // shifted (40,−10).
    assert_tip(at(&rows, line(11)), [40.0, -10.0, 0.0]);
}

#[test]
fn datum_shift_incremental_and_reset() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 X+10",
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 IX+5",
            "L X+0 Y+0 Z+0 R0 F500",
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 X+0",
            "L X+0 Y+0",
        ],
    );
    assert_tip(at(&rows, line(6)), [15.0, 0.0, 0.0]);
    assert_tip(at(&rows, line(9)), [0.0, 0.0, 0.0]);
}

#[test]
fn datum_setting_selects_a_preset() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 247 DATUM SETTING ~",
            "  Q339=+1 ;DATUM NUMBER",
            "L X+0 Y+0 Z+0 R0 FMAX",
        ],
    );
    // Why: preset 1 is the offsets file's G54.1 P1 (−20, 10, 5): the
    // machine stands there plus the tool length; the tip is measured from
    // it.
    let r = at(&rows, line(4));
    let want = [-20.0, 10.0, 5.0 + LENGTH];
    assert_linear(r, want);
}

// ----- cycles -----------------------------------------------------------------

#[test]
fn cycle_200_pecks_at_the_hand_computed_heights() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 200 DRILLING ~",
            "  Q200=2 ;SET-UP CLEARANCE ~",
            "  Q201=-15 ;DEPTH ~",
            "  Q206=150 ;FEED RATE FOR PLNGNG ~",
            "  Q202=5 ;PLUNGING DEPTH ~",
            "  Q210=0 ;DWELL TIME AT TOP ~",
            "  Q203=+0 ;SURFACE COORDINATE ~",
            "  Q204=50 ;2ND SET-UP CLEARANCE ~",
            "  Q211=0 ;DWELL TIME AT BOTTOM",
            "L X+10 Y+10 Z+50 R0 FMAX",
            "CYCL CALL",
        ],
    );
    // Why: to 2 above the surface at rapid, 5 mm pecks at F150 with a
    // rapid back to the clearance and down to 2 above the last depth,
    // then to the 2nd set-up clearance 50.
    let want: [(f64, Option<f64>); 9] = [
        (2.0, None),
        (-5.0, Some(150.0)),
        (2.0, None),
        (-3.0, None),
        (-10.0, Some(150.0)),
        (2.0, None),
        (-8.0, None),
        (-15.0, Some(150.0)),
        (50.0, None),
    ];
    let got: Vec<(f64, Option<f64>)> = of_line(&rows, line(12))
        .iter()
        .map(|r| {
            assert!((r.tip.x - 10.0).abs() < EPS && (r.tip.y - 10.0).abs() < EPS);
            (r.tip.z, r.feed)
        })
        .collect();
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g.0 - w.0).abs() < EPS && g.1 == w.1, "{got:?}");
    }
}

#[test]
fn cycle_207_taps_at_pitch_times_speed() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S500",
            "CYCL DEF 207 RIGID TAPPING NEW ~",
            "  Q200=2 ;SET-UP CLEARANCE ~",
            "  Q201=-20 ;DEPTH ~",
            "  Q239=+1.5 ;THREAD PITCH ~",
            "  Q203=+0 ;SURFACE COORDINATE ~",
            "  Q204=50 ;2ND SET-UP CLEARANCE",
            "L X+10 Y+10 Z+50 R0 FMAX M3",
            "CYCL CALL",
        ],
    );
    // Why: rapid to 2 above, in to −20 and out to 2 at 1.5 mm × 500 rev/min
    // = 750 mm/min, rapid to 50.
    let got: Vec<(f64, Option<f64>)> = of_line(&rows, line(9))
        .iter()
        .map(|r| (r.tip.z, r.feed))
        .collect();
    let want = [
        (2.0, None),
        (-20.0, Some(750.0)),
        (2.0, Some(750.0)),
        (50.0, None),
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g.0 - w.0).abs() < EPS && g.1 == w.1, "{got:?}");
    }
}

const DRILL_SHALLOW: [&str; 9] = [
    "CYCL DEF 200 DRILLING ~",
    "  Q200=2 ;SET-UP CLEARANCE ~",
    "  Q201=-5 ;DEPTH ~",
    "  Q206=150 ;FEED RATE FOR PLNGNG ~",
    "  Q202=5 ;PLUNGING DEPTH ~",
    "  Q210=0 ;DWELL TIME AT TOP ~",
    "  Q203=+0 ;SURFACE COORDINATE ~",
    "  Q204=20 ;2ND SET-UP CLEARANCE ~",
    "  Q211=0 ;DWELL TIME AT BOTTOM",
];

#[test]
fn pattern_def_points_are_drilled_in_order() {
    let mut blocks = vec!["TOOL CALL 1 Z S1000"];
    blocks.extend(DRILL_SHALLOW);
    blocks.extend([
        "PATTERN DEF ~",
        "  POS1 (X+10 Y+20 Z+0) ~",
        "  POS2 (X+30 Y+40 Z+0) ~",
        "  ROW1 (X+0 Y+0 D+10 NUM3 ROT+90 Z+0)",
        "L Z+50 R0 FMAX",
        "CYCL CALL PAT FMAX",
    ]);
    let rows = ok(&mill(), &blocks);
    let call = line(blocks.len() as u32);
    // Why: each hole's bottom is at Z−5; the points are POS1, POS2 and the
    // row of 3 from (0,0) 10 apart along +Y (ROT+90).
    let bottoms: Vec<[f64; 2]> = of_line(&rows, call)
        .iter()
        .filter(|r| (r.tip.z + 5.0).abs() < EPS)
        .map(|r| [r.tip.x, r.tip.y])
        .collect();
    let want = [
        [10.0, 20.0],
        [30.0, 40.0],
        [0.0, 0.0],
        [0.0, 10.0],
        [0.0, 20.0],
    ];
    assert_eq!(bottoms.len(), want.len(), "{bottoms:?}");
    for (g, w) in bottoms.iter().zip(want) {
        assert!(
            (g[0] - w[0]).abs() < EPS && (g[1] - w[1]).abs() < EPS,
            "{bottoms:?}"
        );
    }
}

#[test]
fn pattern_def_surface_adds_to_q203() {
    let mut blocks = vec!["TOOL CALL 1 Z S1000"];
    blocks.extend(DRILL_SHALLOW);
    blocks[7] = "  Q203=+5 ;SURFACE COORDINATE ~";
    blocks.extend([
        "PATTERN DEF ~",
        "  POS1 (X+10 Y+20 Z-2)",
        "L Z+50 R0 FMAX",
        "CYCL CALL PAT FMAX",
    ]);
    let rows = ok(&mill(), &blocks);
    let call = line(blocks.len() as u32);
    // Why (TNC 640 manual, PATTERN DEF: a Z other than 0 "is effective in
    // addition to the workpiece surface Q203"): surface 5 − 2 = 3, depth 5
    // below it.
    let lowest = of_line(&rows, call)
        .iter()
        .map(|r| r.tip.z)
        .fold(f64::INFINITY, f64::min);
    assert!((lowest - (-2.0)).abs() < EPS, "deepest point {lowest}");
}

#[test]
fn m99_calls_the_cycle_at_the_end_of_its_block() {
    let mut blocks = vec!["TOOL CALL 1 Z S1000", "L Z+50 R0 FMAX"];
    blocks.extend(DRILL_SHALLOW);
    blocks.extend(["L X+15 Y+25 FMAX M99", "L X+35 Y+25 FMAX"]);
    let rows = ok(&mill(), &blocks);
    let n = blocks.len() as u32;
    // Why: M99 drills at (15,25) once; the next block does not.
    let at_m99 = of_line(&rows, line(n - 1));
    assert!(
        at_m99
            .iter()
            .any(|r| (r.tip - v([15.0, 25.0, -5.0])).norm() < EPS),
        "no hole bottom at (15, 25)"
    );
    assert!(
        of_line(&rows, line(n))
            .iter()
            .all(|r| (r.tip.z - 20.0).abs() < EPS)
    );
}

// ----- PLANE on the A/C table -------------------------------------------------

#[test]
fn plane_stay_writes_the_positions_for_the_next_l() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+30 SPB+0 SPC+0 STAY",
            "L A+Q120 C+Q122 R0 FMAX",
        ],
    );
    // Why: SPA30 turns the plane about X: its Z is (0, −sin 30°, cos 30°)
    // in the workpiece; STAY moves nothing, the L turns the table so the
    // tool lies along it.
    let r = at(&rows, line(4));
    let s = 30f64.to_radians();
    let want = Vec3::new(0.0, -s.sin(), s.cos());
    assert!(
        (r.dir - want).norm() < 1e-9,
        "dir {:?} want {want:?}",
        r.dir
    );
    // Why: the table turns, the linear axes stay.
    let before = at(&rows, line(2));
    for k in 0..3 {
        assert!((r.joints[k] - before.joints[k]).abs() < EPS);
    }
    // No segment for the STAY block itself.
    assert!(of_line(&rows, line(3)).is_empty());
}

#[test]
fn plane_turn_then_l_in_the_tilted_plane() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+30 SPB+0 SPC+0 TURN FMAX",
            "L X+10 Y+20 Z+5 FMAX",
        ],
    );
    let s = 30f64.to_radians();
    // Why: the plane's axes in the workpiece: X (1,0,0), Y (0, cos, sin),
    // Z (0, −sin, cos); the tip goes to 10·X + 20·Y + 5·Z.
    let want = [
        10.0,
        20.0 * s.cos() - 5.0 * s.sin(),
        20.0 * s.sin() + 5.0 * s.cos(),
    ];
    let r = at(&rows, line(4));
    assert_tip(r, want);
    assert!((r.dir - Vec3::new(0.0, -s.sin(), s.cos())).norm() < 1e-9);
}

#[test]
fn plane_reset_turn_brings_the_rotaries_to_zero() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+30 SPB+0 SPC+45 TURN FMAX",
            "PLANE RESET TURN FMAX",
            "L X+0 Y+0 Z+100 FMAX",
        ],
    );
    let r = at(&rows, line(4));
    assert!(
        r.joints[3].abs() < EPS && r.joints[4].abs() < EPS,
        "{:?}",
        r.joints
    );
    // TURN moves the rotary axes alone: the linear axes stood still in
    // both turns, so turning back puts the tip where it was, and the
    // block after it has nothing to move.
    assert_tip(r, [0.0, 0.0, 100.0]);
    assert!(of_line(&rows, line(5)).is_empty());
}

#[test]
fn plane_move_ends_with_the_tip_where_it_was() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+30 SPB+0 SPC+0 MOVE F1000",
        ],
    );
    let r = at(&rows, line(3));
    assert_tip(r, [0.0, 0.0, 100.0]);
    let s = 30f64.to_radians();
    assert!((r.dir - Vec3::new(0.0, -s.sin(), s.cos())).norm() < 1e-9);
}

#[test]
fn plane_move_dist_swings_the_tip_about_the_point_above_it() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+30 SPB+0 SPC+0 MOVE DIST50 F1000",
        ],
    );
    // Why: the centre of rotation is 50 mm above the tip, (0, 0, 150);
    // it stays, so every tip lies 50 mm from it along the tool, and at
    // the end the tool is along Rx(30)·Z = (0, -sin 30, cos 30): the tip
    // at (0, 25, 150 - 50 cos 30).
    let pivot = Vec3::new(0.0, 0.0, 150.0);
    let turn = of_line(&rows, line(3));
    assert!(turn.len() >= 30, "one step per degree: {}", turn.len());
    for r in &turn {
        assert!((r.tip + 50.0 * r.dir - pivot).norm() < 1e-9, "{:?}", r.tip);
    }
    let s = 30f64.to_radians();
    assert_tip(
        at(&rows, line(3)),
        [0.0, 50.0 * s.sin(), 150.0 - 50.0 * s.cos()],
    );
}

#[test]
fn plane_move_keeps_the_tip_during_the_move() {
    let (rows, alarm) = sampled(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+30 SPB+0 SPC+0 MOVE F1000",
        ],
        &[0.25, 0.5, 0.75, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why (TNC manual, PLANE … MOVE: compensating moves of the linear
    // axes keep the tool tip's position relative to the workpiece): the
    // tip stays at (0, 0, 100) all the way.
    for r in of_line(&rows, line(3)) {
        assert_tip(r, [0.0, 0.0, 100.0]);
    }
}

// ----- more paths -------------------------------------------------------------

#[test]
fn cc_incremental_is_from_the_last_position_and_ctp_is_tangential() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+10 Y+10 Z+0 R0 F500",
            "CC IX+10",
            "LP PR+5 PA+90",
            "L X+0 Y+0",
            "L X+20 Y+0",
            "CC X+20 Y+0",
            "CTP PR+10 PA+90",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: CC IX+10 from (10,10) is the pole (20,10); PR5 PA90 above it.
    assert_tip(at(&rows, line(4)), [20.0, 15.0, 0.0]);
    // Why: leaving (20,0) along +X for (20,10) (PR10 PA90 about (20,0)):
    // the tangent circle is about (20,5) with radius 5, counter-clockwise;
    // half way it is at (25,5).
    let arc = of_line(&rows, line(8));
    assert_tip(arc[0], [25.0, 5.0, 0.0]);
    assert_tip(arc[1], [20.0, 10.0, 0.0]);
    assert_eq!(arc[1].motion, Motion::Ccw);
}

#[test]
fn q_parameters_in_coordinates() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "Q1 = 12.5",
            "Q2 = Q1 * 2",
            "L X+Q1 Y-Q2 Z+0 R0 F500",
        ],
    );
    assert_tip(at(&rows, line(4)), [12.5, -25.0, 0.0]);
}

#[test]
fn inch_program_lengths_are_inches() {
    let text = "BEGIN PGM T INCH\nTOOL CALL 1 Z S1000\nL X+1 Y+2 Z+0.5 R0 F20\nEND PGM T INCH\n";
    let (rows, alarm) = common::run_ends(&mill(), offsets_for(&mill()), text);
    assert!(alarm.is_none(), "{alarm:?}");
    let r = at(&rows, 3);
    // Why: 25.4 mm to the inch; F20 is 508 mm/min.
    assert_tip(r, [25.4, 50.8, 12.7]);
    assert_eq!(r.feed, Some(508.0));
}

#[test]
fn mirror_turns_arcs_over() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 8.0 MIRROR IMAGE",
            "CYCL DEF 8.1 X",
            "L X+30 Y+0 Z+0 R0 F500",
            "CC X+0 Y+0",
            "C X+0 Y+30 DR+",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: every point mirrored in X: the quarter from (30,0) to (0,30)
    // becomes the one from (−30,0) to (0,30), clockwise.
    let arc = of_line(&rows, line(6));
    let h = 30.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert_tip(arc[0], [-h, h, 0.0]);
    assert_tip(arc[1], [0.0, 30.0, 0.0]);
}

#[test]
fn axis_specific_scaling() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 26.0 AXIS-SPECIFIC SCALING",
            "CYCL DEF 26.1 X2 Y3",
            "L X+10 Y+5 Z+1 R0 F500",
        ],
    );
    // Why: X ×2, Y ×3, Z as written.
    assert_tip(at(&rows, line(4)), [20.0, 15.0, 1.0]);
}

#[test]
fn radius_compensation_left_of_the_contour() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X-20 Y-20 Z+0 R0 F500",
            "L X+0 Y+0 RL",
            "L X+0 Y+50",
            "L X+50 Y+50",
        ],
        &[0.5],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: along +Y with the tool left of the contour (radius 5): the
    // centre runs at X−5.
    let mid = of_line(&rows, line(4));
    assert!((mid[0].tip.x + 5.0).abs() < EPS, "{:?}", mid[0].tip);
}

#[test]
fn m92_is_measured_from_the_reference_position() {
    let mut m = mill();
    m.params.reference_1[2] = -50.0;
    let (rows, alarm) = common::run_ends(
        &m,
        offsets_for(&m),
        &program(&["TOOL CALL 1 Z S1000", "L Z-20 R0 FMAX M92"]),
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why (the kernel's reading of M92: from reference position 1):
    // −50 − 20.
    assert!((at(&rows, line(2)).joints[2] + 70.0).abs() < EPS);
}

#[test]
fn m126_takes_the_short_way_on_an_endless_axis() {
    let (rows, alarm) = sampled(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "L C+350 FMAX M126",
            "L C+10 FMAX M127",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let c = |r: &Row| fiveaxis_machine::principal(r.joints[4]);
    // Why: from 0 to 350 the short way is −10: half way at −5.
    let turn = of_line(&rows, line(3));
    assert!((c(turn[0]) + 5.0).abs() < EPS, "{:?}", turn[0].joints);
    assert!((c(turn[1]) + 10.0).abs() < EPS, "{:?}", turn[1].joints);
}

#[test]
fn m129_ends_tcpm_and_a_rotary_block_alone_keeps_the_linear_axes() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "M128",
            "L X+10 Y+0 Z+100 A-20 C+0 F1000",
            "M129",
            "L A-30 FMAX",
        ],
    );
    // Why: under M128 the tip is on (10,0,100) with A at −20.
    let r = at(&rows, line(4));
    assert_tip(r, [10.0, 0.0, 100.0]);
    // Why: after M129 only A moves: X, Y, Z stay.
    let s = at(&rows, line(6));
    for k in 0..3 {
        assert!((s.joints[k] - r.joints[k]).abs() < EPS, "{:?}", s.joints);
    }
    assert!((s.joints[3] + 30.0).abs() < EPS);
}

#[test]
fn ln_without_a_vector_keeps_the_orientation() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "M128",
            "LN X+0 Y+0 Z+50 TX+0 TY-0.5 TZ+0.866025403784 F1000",
            "L X+20",
        ],
    );
    let before = at(&rows, line(4));
    let after = at(&rows, line(5));
    assert_tip(after, [20.0, 0.0, 50.0]);
    assert!((after.dir - before.dir).norm() < 1e-9);
    assert!((after.dir - Vec3::new(0.0, -0.5, 0.866025403784).normalize()).norm() < 1e-9);
}

#[test]
fn plane_relativ_turns_about_the_tilted_axes() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA+0 SPB+0 SPC+90 STAY",
            "PLANE RELATIV SPA-30 TURN FMAX",
            "L X+10 Y+0 Z+50 FMAX",
        ],
    );
    // Why: the plane turned 90° about Z, then −30° about its own X (the
    // workpiece's Y): R = Rz(90°)·Rx(−30°); Z = (−½, 0, √3/2), X = (0,1,0).
    let z = Vec3::new(-0.5, 0.0, 3f64.sqrt() / 2.0);
    let r = at(&rows, line(5));
    assert!((r.dir - z).norm() < 1e-9, "{:?}", r.dir);
    let want = Vec3::new(0.0, 10.0, 0.0) + z * 50.0;
    assert_tip(r, [want.x, want.y, want.z]);
}

#[test]
fn cycle_19_tilts_the_plane_for_the_positions_that_follow() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "CYCL DEF 19.0 WORKING PLANE",
            "CYCL DEF 19.1 A-30 C+0",
            "L A-30 C+0 R0 FMAX",
            "L X+10 Y+0 Z+50 FMAX",
        ],
    );
    let r = at(&rows, line(6));
    // Why: with the table at A−30 the tool lies along `dir` (forward
    // kinematics); the table turns about X, which keeps the plane's X the
    // workpiece's X; so X10 Z50 of the plane is (10,0,0) + 50·dir.
    let mut j = [0.0; fiveaxis_machine::MAX_AXES];
    j[3] = -30.0;
    let dir = dmu().forward(&j, 0.0).dir;
    assert!((r.dir - dir).norm() < 1e-9, "{:?}", r.dir);
    let want = Vec3::new(10.0, 0.0, 0.0) + dir * 50.0;
    assert_tip(r, [want.x, want.y, want.z]);
}

#[test]
fn plane_mb_retracts_along_the_tool_first() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA-30 SPB+0 SPC+0 TURN MB50 FMAX",
        ],
    );
    // Why (TNC manual, MB: retraction along the tool axis, away from the
    // workpiece, before tilting): the tool stands vertical at Z100, so MB50
    // lifts the tip to Z150 before the table turns.
    let segs = of_line(&rows, line(3));
    assert!(segs.len() >= 2, "{segs:?}");
    assert_tip(segs[0], [0.0, 0.0, 150.0]);
}

#[test]
fn plane_mb_max_retracts_to_the_end_of_travel() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA-30 SPB+0 SPC+0 TURN MB MAX FMAX",
        ],
    );
    // Why: up along the vertical tool to the Z travel's end, machine Z 0.
    let segs = of_line(&rows, line(3));
    assert!(segs[0].joints[2].abs() < EPS, "{:?}", segs[0].joints);
}

#[test]
fn table_rot_turns_the_table_for_the_plane_x() {
    let run = |ending: &str| {
        let plane = format!("PLANE SPATIAL SPA+0 SPB+0 SPC+30 TURN FMAX {ending}");
        ok(
            &dmu(),
            &[
                "TOOL CALL 1 Z S1000",
                "L X+0 Y+0 Z+100 R0 FMAX",
                &plane,
                "L X+0 Y+0 Z+100 FMAX",
                "L X+10 Y+0 Z+100 FMAX",
            ],
        )
    };
    // Why: the machine's X moved by a move of 10 along the plane's X: with
    // TABLE ROT the table turns the plane's X onto the machine's X, with
    // COORD ROT it stays and the plane's X is 30° off it.
    for (ending, want) in [
        ("TABLE ROT", [10.0, 0.0]),
        (
            "COORD ROT",
            [
                10.0 * 30f64.to_radians().cos(),
                10.0 * 30f64.to_radians().sin(),
            ],
        ),
    ] {
        let rows = run(ending);
        // The L to (0,0,100) may move nothing (the point is on the C axis).
        let a = rows
            .iter()
            .rfind(|r| r.line <= line(4))
            .expect("a segment before line 5");
        let b = at(&rows, line(5));
        let d = [b.joints[0] - a.joints[0], b.joints[1] - a.joints[1]];
        assert!(
            (d[0] - want[0]).abs() < EPS && (d[1] - want[1]).abs() < EPS,
            "{ending}: machine X, Y moved {d:?}, want {want:?}"
        );
    }
}

#[test]
fn m89_calls_the_cycle_after_every_positioning_block() {
    let mut blocks = vec!["TOOL CALL 1 Z S1000", "L Z+50 R0 FMAX"];
    blocks.extend(DRILL_SHALLOW);
    blocks.extend([
        "L X+10 Y+10 FMAX M89",
        "L X+20 Y+10 FMAX",
        "CYCL DEF 200 DRILLING ~",
        "  Q200=2 ;SET-UP CLEARANCE ~",
        "  Q201=-8 ;DEPTH ~",
        "  Q206=150 ;FEED RATE FOR PLNGNG ~",
        "  Q202=8 ;PLUNGING DEPTH ~",
        "  Q203=+0 ;SURFACE COORDINATE ~",
        "  Q204=20 ;2ND SET-UP CLEARANCE",
        "L X+30 Y+10 FMAX",
    ]);
    let rows = ok(&mill(), &blocks);
    let n = blocks.len() as u32;
    let bottom = |l: u32| {
        of_line(&rows, line(l))
            .iter()
            .map(|r| r.tip.z)
            .fold(f64::INFINITY, f64::min)
    };
    // Why: M89 calls the cycle at (10,10) and after the next position;
    // a new CYCL DEF ends the modal call (the kernel's reading), so the
    // last block only positions.
    assert!((bottom(n - 9) + 5.0).abs() < EPS);
    assert!((bottom(n - 8) + 5.0).abs() < EPS);
    assert!((bottom(n) - 20.0).abs() < EPS);
}

#[test]
fn cycl_call_without_a_cycle_is_refused() {
    let a = alarm_of(
        &mill(),
        &["TOOL CALL 1 Z S1000", "L Z+50 R0 FMAX", "CYCL CALL"],
    );
    assert_eq!(a.condition, Condition::CycleDataMissing, "{a:?}");
    assert_eq!(a.line, line(3));
}

#[test]
fn cp_against_its_direction_is_refused() {
    let a = alarm_of(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+20 Y+0 Z+0 R0 F500",
            "CC X+0 Y+0",
            "CP IPA-90 DR+",
        ],
    );
    assert_eq!(a.condition, Condition::ArcRadiusTolerance, "{a:?}");
    assert_eq!(a.line, line(4));
}

#[test]
fn plane_without_seq_takes_the_shorter_way() {
    // Why (TNC manual, PLANE without SEQ: of the solutions within the
    // travel the one reached by the shorter path): from A0 C0 a plane
    // turned ±20° about X is reached with C at 0 (A ±20) rather than C 180
    // (A ∓20); forward kinematics checks the tool's direction.
    for spa in [20.0f64, -20.0] {
        let plane = format!("PLANE SPATIAL SPA{spa:+} SPB+0 SPC+0 TURN FMAX");
        let rows = ok(
            &dmu(),
            &["TOOL CALL 1 Z S1000", "L X+0 Y+0 Z+100 R0 FMAX", &plane],
        );
        let r = at(&rows, line(3));
        let s = spa.to_radians();
        assert!((r.dir - Vec3::new(0.0, -s.sin(), s.cos())).norm() < 1e-9);
        assert!(
            fiveaxis_machine::principal(r.joints[4]).abs() < EPS,
            "SPA{spa}: {:?}",
            r.joints
        );
    }
}

#[test]
fn tool_call_dr_widens_the_radius_compensation() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000 DR+1",
            "L X-20 Y-20 Z+0 R0 F500",
            "L X+0 Y+0 RL",
            "L X+0 Y+50",
            "L X+50 Y+50",
        ],
        &[0.5],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: radius 5 + DR 1.
    let mid = of_line(&rows, line(4));
    assert!((mid[0].tip.x + 6.0).abs() < EPS, "{:?}", mid[0].tip);
}

#[test]
fn pattern_circle_points() {
    let mut blocks = vec!["TOOL CALL 1 Z S1000"];
    blocks.extend(DRILL_SHALLOW);
    blocks.extend([
        "PATTERN DEF ~",
        "  CIRC1 (X+50 Y+50 D+20 START+0 NUM4 Z+0)",
        "L Z+50 R0 FMAX",
        "CYCL CALL PAT FMAX",
    ]);
    let rows = ok(&mill(), &blocks);
    let call = line(blocks.len() as u32);
    // Why: four holes on a circle of diameter 20 about (50,50), from 0°
    // every 90°.
    let bottoms: Vec<[f64; 2]> = of_line(&rows, call)
        .iter()
        .filter(|r| (r.tip.z + 5.0).abs() < EPS)
        .map(|r| [r.tip.x, r.tip.y])
        .collect();
    let want = [[60.0, 50.0], [50.0, 60.0], [40.0, 50.0], [50.0, 40.0]];
    assert_eq!(bottoms.len(), want.len(), "{bottoms:?}");
    for (g, w) in bottoms.iter().zip(want) {
        assert!(
            (g[0] - w[0]).abs() < EPS && (g[1] - w[1]).abs() < EPS,
            "{bottoms:?}"
        );
    }
}

#[test]
fn drilling_in_a_tilted_plane() {
    let mut blocks = vec![
        "TOOL CALL 1 Z S1000",
        "L X+0 Y+0 Z+100 R0 FMAX",
        "PLANE SPATIAL SPA-30 SPB+0 SPC+0 TURN FMAX",
        "L X+10 Y+20 Z+50 FMAX",
    ];
    blocks.extend(DRILL_SHALLOW);
    blocks.push("CYCL CALL");
    let rows = ok(&dmu(), &blocks);
    let call = line(blocks.len() as u32);
    // Why: the hole's bottom is Z−5 of the plane at X10 Y20:
    // R·(10, 20, −5) with R = Rx(−30°), the tool along R·ez throughout.
    let s = (-30f64).to_radians();
    let r = |p: [f64; 3]| {
        [
            p[0],
            p[1] * s.cos() - p[2] * s.sin(),
            p[1] * s.sin() + p[2] * s.cos(),
        ]
    };
    let rows = of_line(&rows, call);
    assert!(
        rows.iter()
            .any(|row| (row.tip - v(r([10.0, 20.0, -5.0]))).norm() < EPS),
        "no row at the hole's bottom"
    );
    for row in rows {
        assert!((row.dir - v(r([0.0, 0.0, 1.0]))).norm() < 1e-9);
    }
}

#[test]
fn increments_after_a_rounding_start_from_the_corner() {
    let rows = ok(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+0 R0 F500",
            "L X+40 Y+0",
            "RND R10",
            "L IY+40",
        ],
    );
    // Why: IY+40 counts from the programmed corner (40,0), not from where
    // the rounding leaves the line.
    assert_tip(at(&rows, line(5)), [40.0, 40.0, 0.0]);
}

#[test]
fn cc_alone_is_the_last_programmed_position() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+10 Y+10 Z+0 R0 F500",
            "CC",
            "L X+30 Y+10",
            "C X+10 Y+30 DR+",
        ],
        &[0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: the pole is (10,10); the quarter of radius 20 from 0° to 90°.
    let h = 20.0 * std::f64::consts::FRAC_1_SQRT_2;
    let arc = of_line(&rows, line(5));
    assert_tip(arc[0], [10.0 + h, 10.0 + h, 0.0]);
}

#[test]
fn c_to_its_own_start_is_a_full_circle() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+30 Y+0 Z+0 R0 F500",
            "CC X+0 Y+0",
            "C X+30 Y+0 DR+",
        ],
        &[0.25, 0.5, 1.0],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: end = start: the whole circle, a quarter at (0,30), half at
    // (−30,0).
    let arc = of_line(&rows, line(4));
    assert_tip(arc[0], [0.0, 30.0, 0.0]);
    assert_tip(arc[1], [-30.0, 0.0, 0.0]);
    assert_tip(arc[2], [30.0, 0.0, 0.0]);
}

#[test]
fn m91_ignores_the_tilted_plane() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA-30 SPB+0 SPC+0 TURN FMAX",
            "L X+10 Y+20 Z+50 FMAX",
            "L Z-10 R0 FMAX M91",
        ],
    );
    // Why: M91 Z−10 is the machine's Z; X, Y and the rotaries stay.
    let before = at(&rows, line(4));
    let r = at(&rows, line(5));
    assert_linear(r, [before.joints[0], before.joints[1], -10.0]);
    assert!((r.joints[3] - before.joints[3]).abs() < EPS);
}

#[test]
fn m128_in_a_tilted_plane_keeps_its_coordinates() {
    let with_m128 = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "PLANE SPATIAL SPA-30 SPB+0 SPC+0 TURN FMAX",
            "M128",
            "L X+10 Y+20 Z+5 FMAX",
        ],
    );
    // Why (TNC manual, M128 with a tilted plane: coordinates in the tilted
    // system): X10 Y20 Z5 of the plane Rx(−30°).
    let s = (-30f64).to_radians();
    let want = [
        10.0,
        20.0 * s.cos() - 5.0 * s.sin(),
        20.0 * s.sin() + 5.0 * s.cos(),
    ];
    assert_tip(at(&with_m128, line(5)), want);
}

/// The C/A fork head (C on the carriage carries A) as a HEIDENHAIN
/// machine: C ±360°, A ±110°.
fn fork_head() -> Machine {
    let mut m = builtin_at_zero("head-head-ca").expect("built-in");
    m.control = Control::Heidenhain;
    m
}

#[test]
fn seq_is_the_sign_of_the_master_axis_on_a_fork_head() {
    // Why (TNC manual, SEQ: \"SEQ+ positions the master axis so that it
    // assumes a positive angle; the master axis is the 2nd rotary axis
    // seen from the table or the 1st seen from the tool\"): on the fork
    // head A is next to the tool. SPB−30 points the tool to (−sin 30°, 0,
    // cos 30°): Rz(C)·Rx(A)·ez = that for C −90° A +30° and for C +90°
    // A −30° (forward kinematics checks the direction).
    for (seq, want_a) in [("SEQ+", 30.0), ("SEQ-", -30.0)] {
        let plane = format!("PLANE SPATIAL SPA+0 SPB-30 SPC+0 TURN FMAX {seq}");
        let (rows, alarm) = common::run_ends(
            &fork_head(),
            offsets_with(Vec3::new(0.0, 0.0, -100.0)),
            &program(&["TOOL CALL 1 Z S1000", "L X+0 Y+0 Z+100 R0 FMAX", &plane]),
        );
        assert!(alarm.is_none(), "{alarm:?}");
        let r = at(&rows, line(3));
        let s = 30f64.to_radians();
        assert!((r.dir - Vec3::new(-s.sin(), 0.0, s.cos())).norm() < 1e-9);
        let m = fork_head();
        let k = (0..2)
            .find(|&k| m.rotary[k].name == 'A')
            .expect("an A axis");
        let a = r.joints[m.rotary_index(k)];
        assert!((a - want_a).abs() < EPS, "{seq}: {:?}", r.joints);
    }
}

#[test]
fn block_numbers_and_comments_change_nothing() {
    let text = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000 ; the mill\n2 L X+10 Y+20 Z+5 R0 FMAX\n\
                3 L IX+5 F500 ; across\n4 END PGM T MM\n";
    let (rows, alarm) = common::run_ends(&mill(), offsets_for(&mill()), text);
    assert!(alarm.is_none(), "{alarm:?}");
    assert_tip(at(&rows, 3), [10.0, 20.0, 5.0]);
    assert_tip(at(&rows, 4), [15.0, 20.0, 5.0]);
}

#[test]
fn negative_tool_call_feed_is_refused() {
    // Why: a feed is positive (as the L block's own F and the S of the
    // same block are checked).
    let (_, alarm) = ends(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000 F-100",
            "L X+0 Y+0 Z+5 R0 FMAX",
            "L X+10 F AUTO",
        ],
    );
    let a = alarm.expect("an alarm");
    assert_eq!(a.line, line(1), "{a:?}");
}

#[test]
fn mirror_mirrors_the_compensated_path() {
    let (rows, alarm) = sampled(
        &mill(),
        &[
            "TOOL CALL 1 Z S1000",
            "CYCL DEF 8.0 MIRROR IMAGE",
            "CYCL DEF 8.1 X",
            "L X-20 Y-20 Z+0 R0 F500",
            "L X+0 Y+0 RL",
            "L X+0 Y+50",
            "L X+50 Y+50",
        ],
        &[0.5],
    );
    assert!(alarm.is_none(), "{alarm:?}");
    // Why: without the mirror the centre runs at X−5 (left of the contour
    // going +Y); the mirror mirrors the whole tool path: X+5.
    let mid = of_line(&rows, line(6));
    assert!((mid[0].tip.x - 5.0).abs() < EPS, "{:?}", mid[0].tip);
}

#[test]
fn datum_shift_of_a_rotary_axis() {
    let rows = ok(
        &dmu(),
        &[
            "TOOL CALL 1 Z S1000",
            "L X+0 Y+0 Z+100 R0 FMAX",
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 C+30",
            "L C+10 R0 FMAX",
            "L C+0 FMAX",
            "L X+5 C+20 FMAX",
        ],
    );
    // Why: C is measured from the shifted datum: C10 is the machine's 40,
    // with or without linear axes in the block.
    let c = |l: u32| fiveaxis_machine::principal(at(&rows, line(l)).joints[4]);
    assert!((c(5) - 40.0).abs() < EPS, "{}", c(5));
    assert!((c(6) - 30.0).abs() < EPS, "{}", c(6));
    assert!((c(7) - 50.0).abs() < EPS, "{}", c(7));
}

#[test]
fn fn18_reads_the_transformations_and_limits() {
    let rows = ok(
        &mill(),
        &[
            "CYCL DEF 7.0 DATUM SHIFT",
            "CYCL DEF 7.1 X+10",
            "CYCL DEF 10.0 ROTATION",
            "CYCL DEF 10.1 ROT+30",
            "CYCL DEF 32.0 TOLERANCE",
            "CYCL DEF 32.1 T0.05",
            "FN 18: SYSREAD Q1 = ID220 NR2 IDX1",
            "FN 18: SYSREAD Q2 = ID210 NR2",
            "FN 18: SYSREAD Q3 = ID214 NR8",
            "FN 18: SYSREAD Q4 = ID230 NR3 IDX3",
            "L X+Q1 Y+Q2 Z+Q3 R0 FMAX",
        ],
    );
    // Why: Q1 = the shift 10, Q2 = the rotation 30, Q3 = the tolerance
    // 0.05, Q4 = Z's upper limit; the point (10, 30, 0.05) turned by 30°
    // and shifted by 10 in X.
    let (s, c) = 30f64.to_radians().sin_cos();
    assert_tip(
        at(&rows, line(11)),
        [10.0 + 10.0 * c - 30.0 * s, 10.0 * s + 30.0 * c, 0.05],
    );
    let alarm = alarm_of(&mill(), &["FN 18: SYSREAD Q1 = ID9999 NR1"]);
    assert!(alarm.message.contains("ID9999"), "{}", alarm.message);
}
