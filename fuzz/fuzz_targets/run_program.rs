//! The runner takes any bytes as a whole program on the default machine:
//! it ends or alarms, never panics, and every row it yields is finite.
#![no_main]

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{DEFAULT_MACHINE, Offsets, builtin};
use libfuzzer_sys::fuzz_target;

/// Most segments taken from one input: `M99` loops may run forever.
const MAX_SEGMENTS: usize = 10_000;

fuzz_target!(|data: &[u8]| {
    let Some(machine) = builtin(DEFAULT_MACHINE) else {
        return;
    };
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(data),
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
                    let row = segment.row(&machine, s);
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
});
