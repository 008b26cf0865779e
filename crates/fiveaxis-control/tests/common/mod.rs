//! Running programs in memory for the controller's tests.

#![allow(dead_code)]

use fiveaxis_control::{Alarm, Row, RunError, RunOptions, Runner, Segment, SliceSource};
use fiveaxis_machine::{Machine, Offsets};
use proptest::strategy::Strategy;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// Runs `test` over `strategy` with `config` and panics with proptest's
/// report (the minimal failing input) on failure.
pub fn check<S: Strategy>(
    config: Config,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let mut runner = TestRunner::new(config);
    if let Err(e) = runner.run(&strategy, test) {
        panic!("{e}");
    }
}

/// What a program run in memory gave: its segments, and the alarm that
/// stopped it, if any.
pub struct Outcome {
    pub segments: Vec<Segment>,
    pub alarm: Option<Alarm>,
}

/// Runs `program` on `machine` to its end or its first alarm.
pub fn run(machine: &Machine, offsets: Offsets, program: &str) -> Outcome {
    let mut runner = Runner::new(
        machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut segments = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => segments.push(seg),
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    };
    Outcome { segments, alarm }
}

/// Runs `program` on `machine`, sampling every segment at each of
/// `samples` (values of s); returns the rows and the alarm that stopped the
/// run, if any.
pub fn run_sampled(
    machine: &Machine,
    offsets: Offsets,
    program: &str,
    samples: &[f64],
) -> (Vec<Row>, Option<Alarm>) {
    let out = run(machine, offsets, program);
    let rows = out
        .segments
        .iter()
        .flat_map(|seg| samples.iter().map(|&s| seg.row(machine, s)))
        .collect();
    (rows, out.alarm)
}

/// [`run_sampled`] with the row at the end of every segment.
pub fn run_ends(machine: &Machine, offsets: Offsets, program: &str) -> (Vec<Row>, Option<Alarm>) {
    run_sampled(machine, offsets, program, &[1.0])
}

/// `machine` with its reference positions at machine zero (FANUC's
/// default when No.1240 / No.1241 are 0) instead of where its file puts
/// them, so that a program starts from machine zero: the hand-written
/// positions of these tests are measured from there.
pub fn at_machine_zero(mut machine: Machine) -> Machine {
    machine.params.reference_1 = [0.0; fiveaxis_machine::MAX_AXES];
    machine.params.reference_2 = [0.0; fiveaxis_machine::MAX_AXES];
    machine
}

/// A built-in machine [`at_machine_zero`] (the built-ins start at the top
/// of Z travel). Travels, rotary geometry and parameters are the
/// built-in's.
pub fn builtin_at_zero(name: &str) -> Option<Machine> {
    fiveaxis_machine::builtin(name).map(at_machine_zero)
}
