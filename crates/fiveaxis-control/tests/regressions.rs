//! Regression tests for behaviour once found wrong while writing the
//! golden and property tests; each says what the control does.

use fiveaxis_control::{Alarm, Row, RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Control, DEFAULT_MACHINE, Offsets, ToolOffset, builtin};

/// Runs `program` on the default machine (the A/C trunnion, C rollover)
/// with `control`'s behaviour and H1 = 100 mm: the rows of every block end,
/// and the alarm if one stopped it.
fn run_on(control: Control, program: &str) -> (Vec<Row>, Option<Alarm>) {
    let mut machine = builtin(DEFAULT_MACHINE).expect("the default machine is built in");
    machine.control = control;
    let mut offsets = Offsets::default();
    offsets.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            ..ToolOffset::default()
        },
    );
    let source = SliceSource::new(program.as_bytes());
    let mut runner = Runner::new(&machine, offsets, source, RunOptions::default());
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(segment)) => rows.push(segment.row(&machine, 1.0)),
            Ok(None) => return (rows, None),
            Err(RunError::Alarm { alarm, .. }) => return (rows, Some(alarm)),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    }
}

fn run(program: &str) -> (Vec<Row>, Option<Alarm>) {
    run_on(Control::Fanuc30i, program)
}

#[test]
fn g27_finds_a_rollover_axis_at_its_reference_position_modulo_360() {
    // C 0 -> 180 -> 0 turns the shorter way both times (+180, +180): the
    // table stands at 0 degrees (machine position 360 unwrapped), which is
    // reference position 1 of a rollover axis (FANUC 1008#0 ROA, 1260 =
    // 360): G27 C0 must not raise PS0092.
    let (rows, alarm) = run("G0 C180.\nC0.\nG27 C0.\nM30\n");
    assert_eq!(rows.len(), 2);
    assert_eq!(alarm, None, "G27 on a rollover axis at 0 degrees");
}

#[test]
fn g27_after_g28_on_a_rollover_axis_passes() {
    // G28 C0 returns C to reference position 1; the check that follows
    // it must pass whatever way round the table turned.
    let (_, alarm) = run("G0 C180.\nC0.\nG28 C0.\nG27 C0.\nM30\n");
    assert_eq!(alarm, None, "G27 right after G28 on a rollover axis");
}

#[test]
fn mitsubishi_g44_cancels_length_compensation_instead_of_subtracting_it() {
    // functions.md (seed 004): on Mitsubishi G44 is the cancel of TCPC and
    // tool length compensation. With axis words it cancels, then moves:
    // Z50. lands the gauge point at Z 50, not at 50 - H1 = -50.
    let (rows, alarm) = run_on(Control::Mitsubishi, "G43 H1 G0 Z50.\nG44 Z50.\nM30\n");
    assert_eq!(alarm, None);
    let z: Vec<f64> = rows.iter().map(|row| row.joints[2]).collect();
    assert_eq!(z, [150.0, 50.0], "machine Z after G43 H1 Z50. and G44 Z50.");
    // And the tip is reported without a tool length.
    assert_eq!(rows[1].tip.z, 50.0);
}

#[test]
fn mitsubishi_g44_alone_cancels_without_moving() {
    // functions.md: G44 alone cancels without a compensation movement.
    let (rows, alarm) = run_on(Control::Mitsubishi, "G43 H1 G0 Z50.\nG44\nM30\n");
    assert_eq!(alarm, None);
    assert_eq!(rows.len(), 1, "G44 alone moved: {rows:?}");
}

/// Runs `program` on `machine` with H1 = 100 mm, setup error set 1 =
/// rotation −30° about Y, and `--step` rows: the rows of every block (from
/// its start, s = 0) and the alarm, if one stopped it.
fn run_stepped(
    machine: &fiveaxis_machine::Machine,
    program: &str,
    step: f64,
    step_angle: f64,
) -> (Vec<Vec<Row>>, Option<Alarm>) {
    let mut offsets = Offsets::default();
    offsets.tools.insert(
        1,
        ToolOffset {
            length: 100.0,
            ..ToolOffset::default()
        },
    );
    offsets.setup_error.insert(
        1,
        fiveaxis_machine::SetupErrorSet {
            rotation: fiveaxis_machine::Vec3::new(0.0, -30.0, 0.0),
            ..Default::default()
        },
    );
    let options = RunOptions {
        interpolation: Some(fiveaxis_control::Interpolation { step, step_angle }),
        ..RunOptions::default()
    };
    let source = SliceSource::new(program.as_bytes());
    let mut runner = Runner::new(machine, offsets, source, options);
    let mut blocks = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => {
                let n = seg.rows;
                blocks.push(
                    (0..=n)
                        .map(|i| seg.row(machine, f64::from(i) / f64::from(n)))
                        .collect(),
                );
            }
            Ok(None) => return (blocks, None),
            Err(RunError::Alarm { alarm, .. }) => return (blocks, Some(alarm)),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    }
}

#[test]
fn tcpc_rows_on_a_workpiece_frame_with_a_setup_error_start_where_the_last_block_ended() {
    // Found by the robustness issue: the tip path of a G43.4 block on a
    // turning programming frame (WKP = 1) took the setup error in the
    // machine frame, the block ends in the table frame, so the rows of
    // line 4 started 26.6 mm away from line 3's end.
    let mut machine = builtin(DEFAULT_MACHINE).expect("built in");
    machine.params.programming_frame = fiveaxis_machine::ProgrammingFrame::Workpiece;
    let program = "G0 X0 Y0 Z100. A0 C0\nG54.4 P1\nG43.4 H1 X0 Y0 Z0 A-10. C0\nG1 X-50. F1000.\n";
    let (blocks, alarm) = run_stepped(&machine, program, 10.0, 1.0);
    assert_eq!(alarm, None);
    for pair in blocks.windows(2) {
        let (end, start) = (pair[0].last().expect("rows"), &pair[1][0]);
        for i in 0..machine.axis_count() {
            assert!(
                (end.joints[i] - start.joints[i]).abs() < 1e-9,
                "line {} starts away from line {}: {:?} vs {:?}",
                start.line,
                end.line,
                start.joints,
                end.joints
            );
        }
    }
    for rows in &blocks {
        for pair in rows.windows(2) {
            assert!(
                (pair[1].tip - pair[0].tip).norm() <= 10.0 + 1e-6,
                "line {}: rows {:?} and {:?} are more than a step apart",
                pair[0].line,
                pair[0].tip,
                pair[1].tip
            );
        }
    }
}

#[test]
fn posture_control_ending_next_to_the_singular_tilt_keeps_the_step_or_alarms() {
    // Found by the robustness issue: C must turn 28.6 degrees within the
    // last millionth of the block; with the row cap reached the last
    // interpolated row was 28.6 degrees and 19 mm from the end row.
    let machine = builtin("head-table-bc").expect("built in");
    let program =
        "G0 X0 Y0 Z100. B0 C0\nG43.4 H1 P1 X0 Y0 Z50. B-20. C0\nG1 Y-40. B-.000001 C30. F100.\n";
    let (blocks, alarm) = run_stepped(&machine, program, 10.0, 10.0);
    let code = alarm.as_ref().map(|a| a.code.to_string());
    assert_eq!(code.as_deref(), Some("FX0101"), "{alarm:?}");
    assert_eq!(alarm.map(|a| a.line), Some(3));
    assert!(
        blocks.iter().all(|rows| rows[0].line != 3),
        "rows of the failing block left"
    );
}

#[test]
fn a_g53_move_in_cutter_compensation_is_where_the_next_block_starts() {
    // Found by the never-panic property: cutter compensation ended its
    // path at the G53 block but the next block started from the program
    // position before it, snapping A from 1 back to 0.
    for last in ["G40 Y0", "G0 Y0", "G41 D0 I0 J0 K1. Y0"] {
        let (rows, alarm) = run(&format!("G41 D0\nG53 A1.\n{last}\n"));
        assert_eq!(alarm, None, "{last}");
        assert!(rows.iter().all(|r| r.joints[3] == 1.0), "{last}: {rows:?}");
    }
}
