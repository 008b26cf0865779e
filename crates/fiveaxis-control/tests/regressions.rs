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
            Err(RunError::Io(e)) => panic!("a program in memory failed to read: {e}"),
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
