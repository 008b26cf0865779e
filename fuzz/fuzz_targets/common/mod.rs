//! What every runner target asserts: a program ends or alarms, never
//! panics, and every row it yields is finite.

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets};

/// Most segments taken from one input: `M99` loops may run forever.
const MAX_SEGMENTS: usize = 10_000;

/// Runs `program` on `machine` for at most [`MAX_SEGMENTS`] segments,
/// checking the rows in the middle and at the end of each.
pub fn run_to_end(machine: &Machine, program: &[u8]) {
    let mut runner = Runner::new(
        machine,
        Offsets::default(),
        SliceSource::new(program),
        // Endless loops without movement end at the block budget: a small
        // one keeps every input fast.
        RunOptions {
            max_blocks: 200_000,
            ..RunOptions::default()
        },
    );
    for _ in 0..MAX_SEGMENTS {
        match runner.next_segment() {
            Ok(Some(segment)) => {
                for s in [0.5, 1.0] {
                    let row = segment.row(machine, s);
                    let axes = &row.joints[..machine.axis_count()];
                    assert!(
                        axes.iter()
                            .chain(row.tip.iter())
                            .chain(row.dir.iter())
                            .all(|x| x.is_finite()),
                        "{row:?}"
                    );
                }
            }
            Ok(None) | Err(RunError::Alarm { .. }) => return,
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    }
}
