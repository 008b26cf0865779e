//! Canned cycles for drilling (G73, G74, G76, G80–G89, G98, G99): every
//! elementary move a row of its own, hand-computed from the FANUC 30i
//! operator's manual's descriptions. Tool tips come from the rows (forward
//! kinematics), never from the controller's own arithmetic.

mod common;
use fiveaxis_control::{
    Alarm, Motion, PECK_CLEARANCE, PECK_RETRACT, Row, RunError, RunOptions, Runner, SliceSource,
};
use fiveaxis_machine::{Machine, Offsets, ToolOffset, builtin};

const EPS: f64 = 1e-9;
const R: Motion = Motion::Rapid;
const F: Motion = Motion::Linear;

fn machine(name: &str) -> Machine {
    builtin(name).expect("built-in machine")
}

fn offsets() -> Offsets {
    let mut o = Offsets::default();
    o.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            radius: 5.0,
            ..ToolOffset::default()
        },
    );
    o
}

/// Rows (one per segment, at its end) and the alarm, if any.
fn run_on(program: &str, machine: &Machine) -> (Vec<Row>, Option<Alarm>) {
    let mut runner = Runner::new(
        machine,
        offsets(),
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push(seg.row(machine, 1.0)),
            Ok(None) => return (rows, None),
            Err(RunError::Alarm { alarm, .. }) => return (rows, Some(alarm)),
            Err(e) => panic!("io error {e}"),
        }
    }
}

/// Runs on the three-axis mill and expects no alarm.
fn run(program: &str) -> Vec<Row> {
    let (rows, alarm) = run_on(program, &machine("mill-3axis"));
    assert!(alarm.is_none(), "unexpected alarm {alarm:?}");
    rows
}

/// Rows of lines `from` on, as (line, motion, tip).
fn moves(rows: &[Row], from: u32) -> Vec<(u32, Motion, [f64; 3])> {
    rows.iter()
        .filter(|r| r.line >= from)
        .map(|r| (r.line, r.motion, [r.tip.x, r.tip.y, r.tip.z]))
        .collect()
}

#[track_caller]
fn assert_moves(actual: &[(u32, Motion, [f64; 3])], expected: &[(u32, Motion, [f64; 3])]) {
    assert_eq!(
        actual.len(),
        expected.len(),
        "row count: got {actual:#?}\nexpected {expected:#?}"
    );
    for (k, (a, e)) in actual.iter().zip(expected).enumerate() {
        let close = (0..3).all(|i| (a.2[i] - e.2[i]).abs() < EPS);
        assert!(
            a.0 == e.0 && a.1 == e.1 && close,
            "row {k}: got {a:?}, expected {e:?}\nall rows {actual:#?}"
        );
    }
}

/// The alarm of a program that must stop, with the text its span marks.
#[track_caller]
fn alarm_of(program: &str, machine: &Machine) -> (Alarm, Option<String>) {
    let (_, alarm) = run_on(program, machine);
    let alarm = alarm.expect("an alarm");
    let text = alarm.span.map(|s| {
        let line = program
            .lines()
            .nth(alarm.line as usize - 1)
            .expect("the alarm's line");
        line[s.start as usize - 1..s.end as usize - 1].to_owned()
    });
    (alarm, text)
}

const START: &str = "G90 G17 G0 X0. Y0. Z50.\n";

fn program(body: &str) -> String {
    format!("{START}{body}")
}

// ----- G81, G82, G98 / G99, modality ------------------------------------

#[test]
fn g81_returns_to_the_initial_level_in_g98_and_repeats_on_each_position() {
    let rows = run(&program(
        "G98 G81 X10. Y20. Z-5. R2. F100.\nX30.\nY-10.\nG80\nX0.\n",
    ));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 20.0, 50.0]),
            (2, R, [10.0, 20.0, 2.0]),
            (2, F, [10.0, 20.0, -5.0]),
            (2, R, [10.0, 20.0, 50.0]),
            (3, R, [30.0, 20.0, 50.0]),
            (3, R, [30.0, 20.0, 2.0]),
            (3, F, [30.0, 20.0, -5.0]),
            (3, R, [30.0, 20.0, 50.0]),
            (4, R, [30.0, -10.0, 50.0]),
            (4, R, [30.0, -10.0, 2.0]),
            (4, F, [30.0, -10.0, -5.0]),
            (4, R, [30.0, -10.0, 50.0]),
            // After G80 the group-01 mode (G00) moves again.
            (6, R, [0.0, -10.0, 50.0]),
        ],
    );
    // The feed is the F of the cycle block.
    assert!(
        rows.iter()
            .filter(|r| r.motion == F)
            .all(|r| r.feed == Some(100.0))
    );
}

#[test]
fn g99_returns_to_the_r_point_and_positions_there() {
    let rows = run(&program(
        "G99 G81 X10. Y20. Z-5. R2. F100.\nX30.\nG98 X40.\n",
    ));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 20.0, 50.0]),
            (2, R, [10.0, 20.0, 2.0]),
            (2, F, [10.0, 20.0, -5.0]),
            (2, R, [10.0, 20.0, 2.0]),
            // At the R point: positioning there, no move to R.
            (3, R, [30.0, 20.0, 2.0]),
            (3, F, [30.0, 20.0, -5.0]),
            (3, R, [30.0, 20.0, 2.0]),
            // G98: back to the initial level taken when the cycle began.
            (4, R, [40.0, 20.0, 2.0]),
            (4, F, [40.0, 20.0, -5.0]),
            (4, R, [40.0, 20.0, 50.0]),
        ],
    );
}

#[test]
fn g82_dwells_without_a_row_and_a_group_01_code_cancels_the_cycle() {
    let rows = run(&program(
        "G82 X10. Y0. Z-5. R2. P500 F100.\nG01 X20. F200.\nX30.\n",
    ));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
            (3, F, [20.0, 0.0, 50.0]),
            (4, F, [30.0, 0.0, 50.0]),
        ],
    );
}

#[test]
fn a_block_with_data_only_stores_it_and_z_alone_drills_where_the_tool_is() {
    let rows = run(&program(
        "G81 X10. Y0. Z-5. R2. F100.\nF50.\nZ-8.\nR5. X20.\n",
    ));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
            (4, R, [10.0, 0.0, 2.0]),
            (4, F, [10.0, 0.0, -8.0]),
            (4, R, [10.0, 0.0, 50.0]),
            (5, R, [20.0, 0.0, 50.0]),
            (5, R, [20.0, 0.0, 5.0]),
            (5, F, [20.0, 0.0, -8.0]),
            (5, R, [20.0, 0.0, 50.0]),
        ],
    );
    assert_eq!(rows.iter().filter(|r| r.line == 4).count(), 3);
    assert!(
        rows.iter()
            .filter(|r| r.line == 4 && r.motion == F)
            .all(|r| r.feed == Some(50.0))
    );
}

#[test]
fn a_g81_block_without_position_sets_the_mode_and_stores_the_data() {
    // Lines 2 and 3 have no axis word and no R: nothing moves; line 4
    // drills where the tool stands.
    let rows = run(&program("G81 F100.\nM05\nZ-5. R2.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (4, R, [0.0, 0.0, 2.0]),
            (4, F, [0.0, 0.0, -5.0]),
            (4, R, [0.0, 0.0, 50.0]),
        ],
    );
}

// ----- repeats and G91 --------------------------------------------------

#[test]
fn k_repeats_an_incremental_position_in_g91() {
    // G91: R is from the initial level (50 - 48 = 2), Z from the R point
    // (2 - 7 = -5).
    let rows = run(&program("G91 G81 X10. Z-7. R-48. K3 F100.\n"));
    let mut expected = Vec::new();
    for x in [10.0, 20.0, 30.0] {
        expected.extend([
            (2, R, [x, 0.0, 50.0]),
            (2, R, [x, 0.0, 2.0]),
            (2, F, [x, 0.0, -5.0]),
            (2, R, [x, 0.0, 50.0]),
        ]);
    }
    assert_moves(&moves(&rows, 2), &expected);
}

#[test]
fn g91_g99_repeats_from_the_r_point() {
    let rows = run(&program("G91 G99 G81 Y5. Z-7. R-48. K2 F100.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [0.0, 5.0, 50.0]),
            (2, R, [0.0, 5.0, 2.0]),
            (2, F, [0.0, 5.0, -5.0]),
            (2, R, [0.0, 5.0, 2.0]),
            (2, R, [0.0, 10.0, 2.0]),
            (2, F, [0.0, 10.0, -5.0]),
            (2, R, [0.0, 10.0, 2.0]),
        ],
    );
}

#[test]
fn k_in_g90_drills_the_same_hole_again_and_k0_drills_nothing() {
    let rows = run(&program("G81 X10. Z-5. R2. K2 F100.\nX20. K0\nX30. L1\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
            (4, R, [30.0, 0.0, 50.0]),
            (4, R, [30.0, 0.0, 2.0]),
            (4, F, [30.0, 0.0, -5.0]),
            (4, R, [30.0, 0.0, 50.0]),
        ],
    );
}

// ----- pecking ----------------------------------------------------------

#[test]
fn g73_pecks_by_q_and_retracts_d() {
    let d = PECK_RETRACT;
    let rows = run(&program("G73 X10. Y0. Z-5. R2. Q3. F100.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -1.0]),
            (2, R, [10.0, 0.0, -1.0 + d]),
            (2, F, [10.0, 0.0, -4.0]),
            (2, R, [10.0, 0.0, -4.0 + d]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
        ],
    );
}

#[test]
fn g83_returns_to_r_and_comes_back_to_d_above_the_last_depth() {
    let d = PECK_CLEARANCE;
    let rows = run(&program("G99 G83 X10. Y0. Z-5. R2. Q-3. F100.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -1.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, R, [10.0, 0.0, -1.0 + d]),
            (2, F, [10.0, 0.0, -4.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, R, [10.0, 0.0, -4.0 + d]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 2.0]),
        ],
    );
}

#[test]
fn a_peck_that_reaches_the_bottom_exactly_is_the_last() {
    let rows = run(&program("G83 X10. Z-4. R2. Q3. F100.\n"));
    let feeds: Vec<f64> = rows
        .iter()
        .filter(|r| r.motion == F)
        .map(|r| r.tip.z)
        .collect();
    assert_eq!(feeds.len(), 2);
    assert!((feeds[0] + 1.0).abs() < EPS && (feeds[1] + 4.0).abs() < EPS);
}

// ----- tapping and boring -----------------------------------------------

fn feed_out(code: &str, extra: &str) {
    let rows = run(&program(&format!(
        "G98 {code} X10. Y5. Z-5. R2. {extra}F100.\nG99 X20.\n"
    )));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 5.0, 50.0]),
            (2, R, [10.0, 5.0, 2.0]),
            (2, F, [10.0, 5.0, -5.0]),
            (2, F, [10.0, 5.0, 2.0]),
            (2, R, [10.0, 5.0, 50.0]),
            (3, R, [20.0, 5.0, 50.0]),
            (3, R, [20.0, 5.0, 2.0]),
            (3, F, [20.0, 5.0, -5.0]),
            (3, F, [20.0, 5.0, 2.0]),
        ],
    );
}

#[test]
fn g84_taps_in_and_out_at_f() {
    feed_out("G84", "P300 ");
}

#[test]
fn g74_taps_in_and_out_at_f() {
    feed_out("G74", "");
}

#[test]
fn g85_bores_in_and_out_at_f() {
    feed_out("G85", "");
}

#[test]
fn g89_bores_in_dwells_and_out_at_f() {
    feed_out("G89", "P1000 ");
}

#[test]
fn g86_feeds_in_and_rapids_out() {
    let rows = run(&program("G86 X10. Z-5. R2. F100.\nG99 X20.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
            (3, R, [20.0, 0.0, 50.0]),
            (3, R, [20.0, 0.0, 2.0]),
            (3, F, [20.0, 0.0, -5.0]),
            (3, R, [20.0, 0.0, 2.0]),
        ],
    );
}

#[test]
fn g88_feeds_in_and_the_manual_retract_is_a_rapid_to_r() {
    let rows = run(&program("G88 X10. Z-5. R2. P100 F100.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, R, [10.0, 0.0, 50.0]),
        ],
    );
}

#[test]
fn g76_shifts_by_q_in_plus_x_at_the_bottom_and_back_after_the_retract() {
    let rows = run(&program(
        "G99 G76 X10. Y5. Z-5. R2. Q0.5 P100 F100.\nG98 X20.\n",
    ));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 5.0, 50.0]),
            (2, R, [10.0, 5.0, 2.0]),
            (2, F, [10.0, 5.0, -5.0]),
            (2, R, [10.5, 5.0, -5.0]),
            (2, R, [10.5, 5.0, 2.0]),
            (2, R, [10.0, 5.0, 2.0]),
            (3, R, [20.0, 5.0, 2.0]),
            (3, F, [20.0, 5.0, -5.0]),
            (3, R, [20.5, 5.0, -5.0]),
            (3, R, [20.5, 5.0, 50.0]),
            (3, R, [20.0, 5.0, 50.0]),
        ],
    );
}

#[test]
fn g87_back_bores_upwards_and_returns_to_the_initial_level() {
    // R below the hole's top: the tool goes down shifted, bores up to Z.
    let rows = run(&program("G99 G87 X10. Y5. Z-2. R-10. Q-0.5 F100.\n"));
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 5.0, 50.0]),
            (2, R, [10.5, 5.0, 50.0]),
            (2, R, [10.5, 5.0, -10.0]),
            (2, R, [10.0, 5.0, -10.0]),
            (2, F, [10.0, 5.0, -2.0]),
            (2, R, [10.5, 5.0, -2.0]),
            (2, R, [10.5, 5.0, 50.0]),
            (2, R, [10.0, 5.0, 50.0]),
        ],
    );
}

// ----- planes -----------------------------------------------------------

#[test]
fn g18_drills_along_y_and_shifts_along_z() {
    let rows = run(
        "G90 G18 G0 X0. Y50. Z0.\nG81 X10. Z20. Y-5. R2. F100.\nG80\nG76 Z30. Y-5. R2. Q1. F100.\n",
    );
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [10.0, 50.0, 20.0]),
            (2, R, [10.0, 2.0, 20.0]),
            (2, F, [10.0, -5.0, 20.0]),
            (2, R, [10.0, 50.0, 20.0]),
            (4, R, [10.0, 50.0, 30.0]),
            (4, R, [10.0, 2.0, 30.0]),
            (4, F, [10.0, -5.0, 30.0]),
            (4, R, [10.0, -5.0, 31.0]),
            (4, R, [10.0, 50.0, 31.0]),
            (4, R, [10.0, 50.0, 30.0]),
        ],
    );
}

#[test]
fn g19_drills_along_x_and_shifts_along_y() {
    let rows = run(
        "G90 G19 G0 X50. Y0. Z0.\nG83 Y10. Z20. X-5. R2. Q4. F100.\nG80\nG99 G76 Y30. X-5. R2. Q1. F100.\n",
    );
    let d = PECK_CLEARANCE;
    assert_moves(
        &moves(&rows, 2),
        &[
            (2, R, [50.0, 10.0, 20.0]),
            (2, R, [2.0, 10.0, 20.0]),
            (2, F, [-2.0, 10.0, 20.0]),
            (2, R, [2.0, 10.0, 20.0]),
            (2, R, [-2.0 + d, 10.0, 20.0]),
            (2, F, [-5.0, 10.0, 20.0]),
            (2, R, [50.0, 10.0, 20.0]),
            (4, R, [50.0, 30.0, 20.0]),
            (4, R, [2.0, 30.0, 20.0]),
            (4, F, [-5.0, 30.0, 20.0]),
            (4, R, [-5.0, 31.0, 20.0]),
            (4, R, [2.0, 31.0, 20.0]),
            (4, R, [2.0, 30.0, 20.0]),
        ],
    );
}

#[test]
fn g17_g18_g19_g81_each_drill_along_the_plane_normal() {
    for (plane, start, block, hole) in [
        (
            "G17",
            "X0. Y0. Z50.",
            "X1. Y2. Z-5. R2.",
            [[1.0, 2.0, 50.0], [1.0, 2.0, 2.0], [1.0, 2.0, -5.0]],
        ),
        (
            "G18",
            "X0. Y50. Z0.",
            "Z1. X2. Y-5. R2.",
            [[2.0, 50.0, 1.0], [2.0, 2.0, 1.0], [2.0, -5.0, 1.0]],
        ),
        (
            "G19",
            "X50. Y0. Z0.",
            "Y1. Z2. X-5. R2.",
            [[50.0, 1.0, 2.0], [2.0, 1.0, 2.0], [-5.0, 1.0, 2.0]],
        ),
    ] {
        let rows = run(&format!("G90 {plane} G0 {start}\nG81 {block} F100.\n"));
        assert_moves(
            &moves(&rows, 2),
            &[
                (2, R, hole[0]),
                (2, R, hole[1]),
                (2, F, hole[2]),
                (2, R, hole[0]),
            ],
        );
    }
}

// ----- compensation and limits ------------------------------------------

#[test]
fn tool_length_compensation_applies_to_every_move() {
    let rows = run("G90 G17 G43 H1 G0 X0. Y0. Z50.\nG81 X10. Z-5. R2. F100.\n");
    let m = moves(&rows, 2);
    assert_moves(
        &m,
        &[
            (2, R, [10.0, 0.0, 50.0]),
            (2, R, [10.0, 0.0, 2.0]),
            (2, F, [10.0, 0.0, -5.0]),
            (2, R, [10.0, 0.0, 50.0]),
        ],
    );
    for row in rows.iter().filter(|r| r.line == 2) {
        assert!((row.joints[2] - (row.tip.z + 100.0)).abs() < EPS);
    }
}

#[test]
fn soft_limits_are_checked_on_every_move_of_the_cycle() {
    let (alarm, text) = alarm_of(
        &program("G81 X10. Z-400. R2. F100.\n"),
        &machine("mill-3axis"),
    );
    assert_eq!(alarm.code.to_string(), "OT0501");
    assert_eq!(alarm.line, 2);
    assert_eq!(text.as_deref(), Some("Z-400."));
    // Nothing of the failing block is released.
    let (rows, _) = run_on(
        &program("G81 X10. Z-400. R2. F100.\n"),
        &machine("mill-3axis"),
    );
    assert!(rows.iter().all(|r| r.line == 1));
}

// ----- alarms -----------------------------------------------------------

#[test]
fn a_cycle_without_z_or_r_stops_with_fx0130() {
    let m = machine("mill-3axis");
    let (alarm, text) = alarm_of(&program("G81 X10. R2. F100.\n"), &m);
    assert_eq!(alarm.code.to_string(), "FX0130");
    assert_eq!(text.as_deref(), Some("G81"));
    assert!(alarm.message.contains("Z"), "{}", alarm.message);
    let (alarm, _) = alarm_of(&program("G81 X10. Z-5. F100.\n"), &m);
    assert_eq!(alarm.code.to_string(), "FX0130");
    assert!(alarm.message.contains("R"), "{}", alarm.message);
    // G80 clears the data: the next cycle needs them again.
    let (alarm, _) = alarm_of(&program("G81 X10. Z-5. R2. F100.\nG80\nG82 X20.\n"), &m);
    assert_eq!((alarm.code.to_string().as_str(), alarm.line), ("FX0130", 4));
}

#[test]
fn g73_and_g83_without_q_stop_with_ps0045() {
    let m = machine("mill-3axis");
    let (alarm, text) = alarm_of(&program("G83 X10. Z-5. R2. F100.\n"), &m);
    assert_eq!(alarm.code.to_string(), "PS0045");
    assert_eq!(text.as_deref(), Some("G83"));
    let (alarm, text) = alarm_of(&program("G73 X10. Z-5. R2. Q0 F100.\n"), &m);
    assert_eq!(alarm.code.to_string(), "PS0045");
    assert_eq!(text.as_deref(), Some("Q0"));
}

#[test]
fn too_many_pecks_are_refused() {
    let (alarm, text) = alarm_of(
        &program("G83 X10. Z-250. R2. Q0.001 K9999 F100.\n"),
        &machine("mill-3axis"),
    );
    assert_eq!(alarm.code.to_string(), "FX0014");
    assert_eq!(text.as_deref(), Some("Q0.001"));
}

#[test]
fn bad_dwell_and_repeat_words_stop() {
    let m = machine("mill-3axis");
    let (alarm, text) = alarm_of(&program("G82 X10. Z-5. R2. P1.5 F100.\n"), &m);
    assert_eq!(alarm.code.to_string(), "PS0007");
    assert_eq!(text.as_deref(), Some("P1.5"));
    let (alarm, text) = alarm_of(&program("G81 X10. Z-5. R2. K10000 F100.\n"), &m);
    assert_eq!(alarm.code.to_string(), "FX0014");
    assert_eq!(text.as_deref(), Some("K10000"));
}

#[test]
fn reference_return_in_a_cycle_stops_with_ps0044() {
    let (alarm, text) = alarm_of(
        &program("G81 X10. Z-5. R2. F100.\nG28 Z50.\n"),
        &machine("mill-3axis"),
    );
    assert_eq!(alarm.code.to_string(), "PS0044");
    assert_eq!(text.as_deref(), Some("G28"));
}

#[test]
fn a_cycle_and_a_group_01_code_in_one_block_conflict() {
    let (alarm, text) = alarm_of(
        &program("G01 G81 X10. Z-5. R2. F100.\n"),
        &machine("mill-3axis"),
    );
    assert_eq!(alarm.code.to_string(), "PS0010");
    assert_eq!(text.as_deref(), Some("G81"));
}

#[test]
fn g80_and_a_group_01_code_go_together() {
    let rows = run(&program("G81 X10. Z-5. R2. F100.\nG80 G01 X20. Z40.\n"));
    assert_moves(&moves(&rows, 3), &[(3, F, [20.0, 0.0, 40.0])]);
}

#[test]
fn a_block_held_by_cutter_compensation_c_is_emitted_before_the_cycle() {
    for cancel in ["G40 X20.", "G40 X20.\nM05", "X20.\nG40"] {
        held_block_then_cycle(cancel);
    }
}

fn held_block_then_cycle(cancel: &str) {
    let text = program(&format!(
        "G41 D1 G01 X10. F100.\nY10.\n{cancel}\nG81 X30. Z-5. R2.\nX40.\n"
    ));
    let rows = run(&text);
    let last = u32::try_from(text.lines().count()).expect("lines");
    let m = moves(&rows, 2);
    let lines: Vec<u32> = m.iter().map(|r| r.0).collect();
    let mut sorted = lines.clone();
    sorted.sort_unstable();
    assert_eq!(lines, sorted, "rows out of order: {m:#?}");
    // The cancel block ends on its programmed point; the cycle goes on
    // from there.
    let (a, b) = (last - 1, last);
    assert_moves(
        &moves(&rows, a),
        &[
            (a, R, [30.0, 10.0, 50.0]),
            (a, R, [30.0, 10.0, 2.0]),
            (a, F, [30.0, 10.0, -5.0]),
            (a, R, [30.0, 10.0, 50.0]),
            (b, R, [40.0, 10.0, 50.0]),
            (b, R, [40.0, 10.0, 2.0]),
            (b, F, [40.0, 10.0, -5.0]),
            (b, R, [40.0, 10.0, 50.0]),
        ],
    );
    let end = m.iter().rfind(|r| r.0 < a).expect("the cancel's row");
    // G40 alone leaves the offset at the last compensated end (X20 Y15):
    // the cycle's positioning is the cancel move.
    let y = if cancel.starts_with("G40 X20.") {
        10.0
    } else {
        15.0
    };
    assert!(
        (end.2[0] - 20.0).abs() < EPS && (end.2[1] - y).abs() < EPS,
        "{cancel}: {m:#?}"
    );
}

#[test]
fn macro_variables_4009_and_4010_give_the_cycle_and_the_return_level() {
    let rows = run(&program(
        "G81 X10. Z-5. R2. F100.\nG99\n#100 = #4009\n#101 = #4010\nG80\nG0 X#100 Y#101\nG84 G98\n#102 = #4009 + #4010\nG80 G0 X#102\n",
    ));
    let last = rows.last().expect("rows");
    assert!((last.tip.x - 182.0).abs() < EPS, "{:?}", last.tip);
    assert!((last.tip.y - 99.0).abs() < EPS, "{:?}", last.tip);
    let row = rows.iter().rfind(|r| r.line == 7).expect("line 7");
    assert!((row.tip.x - 81.0).abs() < EPS && (row.tip.y - 99.0).abs() < EPS);
}

#[test]
fn a_cycle_without_feed_stops_with_ps0011() {
    let (alarm, _) = alarm_of(&program("G81 X10. Z-5. R2.\n"), &machine("mill-3axis"));
    assert_eq!(alarm.code.to_string(), "PS0011");
}

#[test]
fn cycles_drill_along_the_programming_frame_under_tcpc() {
    // 3+2 drilling as the NX posts write it: the table tilted, G43.4 on,
    // the cycle in the programming frame (here WKP = 1: the frame does not
    // turn, so its Z is the tool axis). Every row's tip, computed back by
    // forward kinematics, lies on the hole's line in that frame.
    let mut m = machine("trunnion-bc");
    m.params.programming_frame = fiveaxis_machine::ProgrammingFrame::Workpiece;
    let (rows, alarm) = run_on(
        "G90 G0 X0. Y0. Z100. B-30. C45.\nG43.4 H1 X10. Y5.\nZ20.\nG98 G81 Z-5. R2. F100.\nG80\n",
        &m,
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let drill: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
    assert_eq!(drill.len(), 3, "{rows:?}");
    // The tip in the frame that does not turn: the table's rotation
    // applied to the reported (table-frame) tip.
    for (row, z) in drill.iter().zip([2.0, -5.0, 20.0]) {
        let table = m.chain(fiveaxis_machine::Side::Table, &row.joints);
        let tip = table.transform_point(&row.tip.into()).coords;
        assert!(
            (tip.x - 10.0).abs() < 1e-9 && (tip.y - 5.0).abs() < 1e-9,
            "{tip:?}"
        );
        assert!((tip.z - z).abs() < 1e-9, "{tip:?} vs {z}");
        // The tool points along the frame's Z throughout.
        let dir = table.transform_vector(&row.dir);
        assert!((dir.z - 1.0).abs() < 1e-9, "{dir:?}");
        assert_eq!((row.joints[3], row.joints[4]), (-30.0, 45.0));
    }
}

/// Rows at `s` = 0.5 and 1 of every segment, and the alarm, if any.
fn halves_on(program: &str, machine: &Machine) -> (Vec<(Row, Row)>, Option<Alarm>) {
    let out = common::run(machine, offsets(), program);
    let rows = out
        .segments
        .iter()
        .map(|seg| (seg.row(machine, 0.5), seg.row(machine, 1.0)))
        .collect();
    (rows, out.alarm)
}

fn near(a: &fiveaxis_machine::Vec3, b: &fiveaxis_machine::Vec3) -> bool {
    (a - b).norm() < 1e-9
}

#[test]
fn rotary_words_in_a_cycle_block_under_tcpc_turn_the_tool_and_the_hole_runs_along_it() {
    // `G98 G81 X Y Z <rotary words> R F` inside G43.4 (the form NX's Mori
    // Seiki NMV post writes): the rotary axes turn with the positioning,
    // the hole bottom is the programmed tip X Y Z, R and the initial level
    // lie on the tool's line through it. The programming frame is the
    // table's at rotary 0 (WKP = 0), so the tool is tilted in it; tips
    // and directions come from forward kinematics (the rows).
    use fiveaxis_machine::Vec3;
    for (name, words, angles) in [
        ("trunnion-bc", "B-30. C45.", [(3, -30.0), (4, 45.0)]),
        ("head-table-bc", "B30. C45.", [(3, 30.0), (4, 45.0)]),
        ("head-head-ca", "C45. A30.", [(3, 45.0), (4, 30.0)]),
    ] {
        let m = machine(name);
        let program = format!(
            "G90 G0 X0. Y0. Z100.\nG43.4 H1 Z50.\nG98 G81 X10. Y5. Z-5. {words} R2. F100.\nX20.\nG80\n"
        );
        let (rows, alarm) = halves_on(&program, &m);
        assert!(alarm.is_none(), "{name}: {alarm:?}");
        let p0 = Vec3::new(0.0, 0.0, 50.0);
        for (line, x) in [(3, 10.0), (4, 20.0)] {
            let hole: Vec<&(Row, Row)> = rows.iter().filter(|r| r.1.line == line).collect();
            assert_eq!(hole.len(), 4, "{name} line {line}: {hole:?}");
            let dir = hole[3].1.dir;
            assert!(dir.z < 0.95, "{name}: the tool is tilted, {dir:?}");
            let bottom = Vec3::new(x, 5.0, -5.0);
            let initial = bottom + (p0 - bottom).dot(&dir) * dir;
            let at = |level: f64| bottom + (level + 5.0) * dir;
            // Positioning at the initial level, R, the bottom, back.
            for (row, want) in hole.iter().zip([initial, at(2.0), bottom, initial]) {
                assert!(
                    near(&row.1.tip, &want),
                    "{name} {line}: {:?} vs {want:?}",
                    row.1.tip
                );
                for (i, angle) in angles {
                    assert!((row.1.joints[i] - angle).abs() < 1e-9, "{name}: {row:?}");
                }
                assert!(near(&row.1.dir, &dir), "{name}: {row:?}");
            }
            // The feed runs on the tool's line: its middle too.
            let middle = hole[2].0.tip;
            assert!(near(&middle, &at(-1.5)), "{name}: {middle:?}");
        }
        // The first positioning turned the rotary axes with the tip
        // straight in the frame: from where it stood to the initial level.
        let first = rows.iter().find(|r| r.1.line == 3).expect("positioning");
        let bottom = Vec3::new(10.0, 5.0, -5.0);
        let target = bottom + (p0 - bottom).dot(&first.1.dir) * first.1.dir;
        assert!(
            near(&first.0.tip, &((p0 + target) / 2.0)),
            "{name}: {first:?}"
        );
    }
}

#[test]
fn the_nx_nmv_block_drills_at_the_programmed_tip_with_the_table_turned() {
    // The NX NMV post's block in the metric form of the corpus program,
    // on a B/C trunnion whose programming frame does not turn (WKP = 1):
    // the tool stays the frame's Z, the table turns to B90 C180 on the
    // way to the hole, the hole is X Y with its bottom at Z, dwell P.
    let mut m = machine("trunnion-bc");
    m.params.programming_frame = fiveaxis_machine::ProgrammingFrame::Workpiece;
    let (rows, alarm) = run_on(
        "G90 G0 X0. Y0. Z100.\nG43.4 H1 Z50.\nG98 G82 X-25. Y-21.336 Z-7. B90. C180. R3. F250. P5\nG80\n",
        &m,
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let hole: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    assert_eq!(hole.len(), 4, "{hole:?}");
    for (row, z) in hole.iter().zip([50.0, 3.0, -7.0, 50.0]) {
        let table = m.chain(fiveaxis_machine::Side::Table, &row.joints);
        let tip = table.transform_point(&row.tip.into()).coords;
        assert!(
            (tip.x + 25.0).abs() < 1e-9
                && (tip.y + 21.336).abs() < 1e-9
                && (tip.z - z).abs() < 1e-9,
            "{tip:?} vs {z}"
        );
        assert!((table.transform_vector(&row.dir).z - 1.0).abs() < 1e-9);
        assert_eq!((row.joints[3], row.joints[4]), (90.0, 180.0));
    }
}

#[test]
fn g91_under_a_tilted_tool_measures_r_and_z_along_it() {
    // G91: R from the initial level and Z from R, along the tool; the
    // plane increment repeated K times moves the hole by the increment's
    // part square to the tool (the levels stay the same).
    use fiveaxis_machine::Vec3;
    let m = machine("trunnion-bc");
    let (rows, alarm) = run_on(
        "G90 G0 X0. Y0. Z100.\nG43.4 H1 Z50.\nG0 B-30. C45.\nG91 G98 G81 X10. Y5. Z-7. R-48. K2 F100.\nG80\n",
        &m,
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let hole: Vec<&Row> = rows.iter().filter(|r| r.line == 4).collect();
    assert_eq!(hole.len(), 8, "{hole:?}");
    let dir = hole[0].dir;
    assert!(dir.z < 0.95, "{dir:?}");
    for k in [0, 4] {
        let (at, r, bottom, back) = (
            hole[k].tip,
            hole[k + 1].tip,
            hole[k + 2].tip,
            hole[k + 3].tip,
        );
        assert!(near(&(r - at), &(-48.0 * dir)), "{k}: {at:?} {r:?}");
        assert!(near(&(bottom - r), &(-7.0 * dir)), "{k}: {r:?} {bottom:?}");
        assert!(near(&back, &at), "{k}");
    }
    let step = Vec3::new(10.0, 5.0, 0.0);
    let square = step - step.dot(&dir) * dir;
    assert!(near(&(hole[6].tip - hole[2].tip), &square), "{hole:?}");
    // The first positioning starts at the tip (0, 0, 50) and stays at
    // its level along the tool.
    assert!(((hole[0].tip - Vec3::new(0.0, 0.0, 50.0)).dot(&dir)).abs() < 1e-9);
}

#[test]
fn g76_under_a_tilted_tool_shifts_square_to_it() {
    use fiveaxis_machine::Vec3;
    let m = machine("head-table-bc");
    let (rows, alarm) = run_on(
        "G90 G0 X0. Y0. Z100.\nG43.4 H1 Z50.\nG99 G76 X10. Y5. Z-5. B30. C0. R2. Q1. F100.\nG80\n",
        &m,
    );
    assert!(alarm.is_none(), "{alarm:?}");
    let hole: Vec<&Row> = rows.iter().filter(|r| r.line == 3).collect();
    // Positioning, R, bottom, shift, out shifted, shift back.
    assert_eq!(hole.len(), 6, "{hole:?}");
    let dir = hole[2].dir;
    let shift = hole[3].tip - hole[2].tip;
    assert!((shift.norm() - 1.0).abs() < 1e-9, "{shift:?}");
    assert!(
        shift.dot(&dir).abs() < 1e-9 && shift.x > 0.8,
        "{shift:?} {dir:?}"
    );
    assert!(near(&hole[2].tip, &Vec3::new(10.0, 5.0, -5.0)));
    assert!(near(
        &hole[5].tip,
        &(Vec3::new(10.0, 5.0, -5.0) + 7.0 * dir)
    ));
}

#[test]
fn cycles_are_refused_with_rotary_words_in_g43_5_and_under_cutter_compensation() {
    let (alarm, text) = alarm_of(
        "G90 G0 X0. Y0. Z50.\nG43.5 H1 Z50.\nG81 X10. A5. Z-5. R2. F100.\n",
        &machine("trunnion-ac"),
    );
    assert_eq!(alarm.code.to_string(), "FX0073");
    assert_eq!(text.as_deref(), Some("A5."));
    let (alarm, _) = alarm_of(
        &program("G41 D1 G01 X10. F100.\nG81 X20. Z-5. R2.\n"),
        &machine("mill-3axis"),
    );
    assert_eq!(alarm.code.to_string(), "FX0133");
    let (alarm, _) = alarm_of(
        &program("G41 D1 G01 X10. I0. J0. K1. F100.\nG81 X20. Z-5. R2.\n"),
        &machine("mill-3axis"),
    );
    assert_eq!(alarm.code.to_string(), "FX0133");
}

#[test]
fn cycle_words_outside_a_cycle_still_alarm() {
    let (alarm, text) = alarm_of(&program("G80 X10. R2.\n"), &machine("mill-3axis"));
    assert_eq!(alarm.code.to_string(), "FX0012");
    assert_eq!(text.as_deref(), Some("R2."));
}
