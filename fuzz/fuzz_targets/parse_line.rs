//! The front end reads any bytes as one line without panicking, and a
//! block it has used before reads them the same as a fresh one.
#![no_main]

use fiveaxis_gcode::{Block, parse_line};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut fresh = Block::default();
    let result = parse_line(data, 1, &mut fresh);
    let mut reused = Block::default();
    let _ = parse_line(b"/N1 G1 X2 Y3 Z4 A5 B6 (reuse)", 1, &mut reused);
    assert_eq!(parse_line(data, 1, &mut reused), result);
    assert_eq!(reused, fresh);
});
