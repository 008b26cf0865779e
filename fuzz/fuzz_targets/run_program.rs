//! The runner takes any bytes as a whole program on the default machine:
//! it ends or alarms, never panics, and every row it yields is finite.
#![no_main]

mod common;

use fiveaxis_machine::{DEFAULT_MACHINE, builtin};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some(machine) = builtin(DEFAULT_MACHINE) {
        common::run_to_end(&machine, data);
    }
});
