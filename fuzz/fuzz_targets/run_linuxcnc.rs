//! The runner reads any bytes as a LinuxCNC program (O-words, named
//! parameters, its expressions) on the A/C trunnion with
//! `control = "linuxcnc"`: it ends or alarms, never panics or overflows
//! its stack, and every row it yields is finite.
#![no_main]

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{Machine, Offsets, builtin_source};
use libfuzzer_sys::fuzz_target;

/// Most segments taken from one input.
const MAX_SEGMENTS: usize = 10_000;

fuzz_target!(|data: &[u8]| {
    let Some(text) = builtin_source("trunnion-ac") else {
        return;
    };
    let Ok(machine) = Machine::from_toml(&text.replace(
        "control = \"fanuc30i\"",
        "control = \"linuxcnc\"",
    )) else {
        return;
    };
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(data),
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
            Err(e) => panic!("a program in memory failed to read: {e}"),
        }
    }
});
