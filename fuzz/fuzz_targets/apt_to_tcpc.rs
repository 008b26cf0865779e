//! The APT / CL reader takes any text: it converts it or names the record
//! at fault, never panics, and what it writes runs on the swivel-head
//! machine to its end or an alarm, every row finite.
#![no_main]

mod common;

use fiveaxis_machine::builtin;
use fiveaxis_post::apt::to_tcpc;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(program) = to_tcpc(text, "fuzz.apt") else {
        return;
    };
    if let Some(machine) = builtin("head-table-bc") {
        common::run_to_end(&machine, program.as_bytes());
    }
});
