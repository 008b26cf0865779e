//! Real file formats, as a FANUC control reads a tape or a file: leader
//! before the first `%`, byte-order marks, CR LF and lone CR line ends,
//! tabs, program numbers and names.

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{DEFAULT_MACHINE, Offsets, builtin};

/// The lines of the rows of every block end, the alarm code if one
/// stopped the run, and the runner's notes.
fn run(program: &[u8]) -> (Vec<(u32, f64)>, Option<String>, Vec<String>) {
    let machine = builtin(DEFAULT_MACHINE).expect("built in");
    let mut runner = Runner::new(
        &machine,
        Offsets::default(),
        SliceSource::new(program),
        RunOptions::default(),
    );
    let mut rows = Vec::new();
    let alarm = loop {
        match runner.next_segment() {
            Ok(Some(seg)) => rows.push((seg.line, seg.end[0])),
            Ok(None) => break None,
            Err(RunError::Alarm { alarm, .. }) => break Some(alarm.code.to_string()),
            Err(e) => panic!("read error {e}"),
        }
    };
    (rows, alarm, runner.notes().to_vec())
}

#[test]
fn leader_before_the_first_percent_is_skipped_and_noted() {
    let program =
        b"Information listing\n==========\nDate : 01/02/2020  10:11\n\n%\nO0001\nG0 X1.\nM30\n%\n";
    let (rows, alarm, notes) = run(program);
    assert_eq!(alarm, None);
    assert_eq!(rows, vec![(7, 1.0)]);
    assert!(
        notes[0].contains("lines 1 to 4: leader text before the first %"),
        "{notes:?}"
    );
    // Banners of other CAM systems.
    let (rows, alarm, _) = run(b"****************\n* PART 12 *\n****************\n%\nG0 X2.\n%\n");
    assert_eq!((rows, alarm), (vec![(5, 2.0)], None));
}

#[test]
fn a_program_block_before_the_percent_means_there_is_no_leader() {
    // The block comes first: it runs, and the % after it ends the program.
    let (rows, alarm, notes) = run(b"G0 X1.\n%\nG0 X2.\n");
    assert_eq!((rows, alarm), (vec![(1, 1.0)], None));
    assert!(notes.iter().any(|n| n.contains("closing %")), "{notes:?}");
    // Leader-like garbage without any % is not skipped: it is an alarm.
    let (_, alarm, _) = run(b"=====\nG0 X1.\n");
    assert!(alarm.is_some());
}

#[test]
fn byte_order_mark_and_line_ends_of_every_kind() {
    let (rows, alarm, notes) = run(b"\xef\xbb\xbfG0 X1.\r\nG0 X2.\rG0\tX3.\nG0 X4.");
    assert_eq!(alarm, None);
    assert_eq!(rows, vec![(1, 1.0), (2, 2.0), (3, 3.0), (4, 4.0)]);
    assert!(
        notes.iter().any(|n| n.contains("byte-order mark")),
        "{notes:?}"
    );
    // Lone CR lines count as lines for alarms too.
    let (_, alarm, _) = run(b"G0 X1.\rG0 X1. X2.\r");
    assert_eq!(alarm.as_deref(), Some("PS0009"));
}

#[test]
fn program_numbers_and_names() {
    let (rows, alarm, _) = run(b"%\nO12345678 (EIGHT DIGITS)\nG0 X1.\nM30\n%\n");
    assert_eq!((rows, alarm), (vec![(3, 1.0)], None));
    let (rows, alarm, _) = run(b"%\n<BRACKET_PART>\nG0 X1.\nM30\n%\n");
    assert_eq!((rows, alarm), (vec![(3, 1.0)], None));
    let (rows, alarm, _) = run(b"%\nO<NAMED>\nG0 X1.\nM30\n%\n");
    assert_eq!((rows, alarm), (vec![(3, 1.0)], None));
    // A placeholder left by a post: neither a number nor a name.
    let (rows, alarm, _) = run(b"%\nO ENTER OP AND LAST 3 DIGITS\nG0 X1.\n");
    assert_eq!((rows, alarm.as_deref()), (vec![], Some("PS0009")));
}
