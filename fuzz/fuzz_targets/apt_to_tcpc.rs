//! The APT / CL reader takes any text: it converts it or names the record
//! at fault, never panics, and what it writes runs on the swivel-head
//! machine to its end or an alarm, every row finite.
#![no_main]

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Offsets, builtin};
use fiveaxis_post::apt::to_tcpc;
use libfuzzer_sys::fuzz_target;

/// Most segments taken from one converted program.
const MAX_SEGMENTS: usize = 10_000;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(program) = to_tcpc(text, "fuzz.apt") else {
        return;
    };
    let Some(machine) = builtin("head-table-bc") else {
        return;
    };
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program.as_bytes()),
        RunOptions {
            max_blocks: 200_000,
            ..RunOptions::default()
        },
    );
    for _ in 0..MAX_SEGMENTS {
        match runner.next_segment() {
            Ok(Some(segment)) => {
                let row = segment.row(&machine, 1.0);
                let axes = &row.joints[..machine.axis_count()];
                assert!(
                    axes.iter().chain(row.tip.iter()).all(|x| x.is_finite()),
                    "{row:?}"
                );
            }
            Ok(None) | Err(RunError::Alarm { .. }) => return,
            Err(e) => panic!("a converted program failed to read: {e}"),
        }
    }
});
