//! Running programs in memory for the controller's tests.

#![allow(dead_code)]

use fiveaxis_control::{Alarm, Row, RunError, RunOptions, Runner, SliceSource};
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

/// Runs `program` on `machine`, sampling every segment at each of
/// `samples` (values of s); returns the rows and the alarm that stopped the
/// run, if any.
pub fn run_sampled(
    machine: &Machine,
    offsets: Offsets,
    program: &str,
    samples: &[f64],
) -> (Vec<Row>, Option<Alarm>) {
    let mut runner = Runner::new(
        machine,
        offsets,
        SliceSource::new(program.as_bytes()),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.extend(samples.iter().map(|&s| seg.row(machine, s))),
            Ok(None) => return (rows, None),
            Err(RunError::Alarm { alarm, .. }) => return (rows, Some(alarm)),
            Err(RunError::Io(e)) => panic!("a program in memory failed to read: {e}"),
        }
    }
}

/// [`run_sampled`] with the row at the end of every segment.
pub fn run_ends(machine: &Machine, offsets: Offsets, program: &str) -> (Vec<Row>, Option<Alarm>) {
    run_sampled(machine, offsets, program, &[1.0])
}
