//! The runner reads any bytes as a LinuxCNC program (O-words, named
//! parameters, its expressions) on the A/C trunnion with
//! `control = "linuxcnc"`: it ends or alarms, never panics or overflows
//! its stack, and every row it yields is finite.
#![no_main]

mod common;

use fiveaxis_machine::{Machine, builtin_source};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = builtin_source("trunnion-ac") else {
        return;
    };
    let linuxcnc = text.replace("control = \"fanuc30i\"", "control = \"linuxcnc\"");
    if let Ok(machine) = Machine::from_toml(&linuxcnc) {
        common::run_to_end(&machine, data);
    }
});
