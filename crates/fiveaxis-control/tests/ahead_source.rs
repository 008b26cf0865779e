//! The source that reads ahead on a thread of its own gives what a
//! `ReaderSource` on the same text and `parse_line_as` give: the same
//! lines, positions and errors, whatever the jumps, and blocks equal to
//! the line's own reading.

use std::io::Cursor;

use fiveaxis_control::{AheadSource, MAX_LINE_BYTES, ReaderSource, Source};
use fiveaxis_gcode::{Block, Syntax, parse_line_as};
use proptest::prelude::*;

/// One line of a test program: plain blocks, comments, macro text, a
/// number the lexer refuses, blank lines, line ends of every kind.
fn line() -> impl Strategy<Value = Vec<u8>> {
    let body = prop_oneof![
        6 => (-500i32..500, -500i32..500, 0u8..3).prop_map(|(x, y, g)| format!("G{g} X{x}.5 Y{y} Z-1.25").into_bytes()),
        1 => Just(b"N10 G90 (SET ABSOLUTE) M3 S1000".to_vec()),
        1 => Just(b"#1=#1+1".to_vec()),
        1 => Just(b"WHILE[#1LT3]DO1".to_vec()),
        1 => Just(b"X1.2.3".to_vec()),
        1 => Just(b"/ G1 X1 ; end".to_vec()),
        1 => Just(b"%".to_vec()),
        1 => Just(Vec::new()),
    ];
    let end = prop_oneof![Just(&b"\n"[..]), Just(&b"\r\n"[..]), Just(&b"\r"[..])];
    (body, end).prop_map(|(mut body, end)| {
        body.extend_from_slice(end);
        body
    })
}

#[derive(Clone, Debug)]
enum Op {
    /// Read the next line (and its block).
    Read,
    /// Jump to the start of a line seen before (by its rank among them).
    Back(usize),
    /// Jump to one of the last 40 line starts seen.
    BackNear(usize),
}

fn ops() -> impl Strategy<Value = Vec<Op>> {
    prop::collection::vec(
        prop_oneof![
            40 => Just(Op::Read),
            1 => (0usize..10_000).prop_map(Op::Back),
            3 => (0usize..40).prop_map(Op::BackNear),
        ],
        0..1200,
    )
}

/// Runs `ops` on both sources and compares every outcome.
fn compare(text: &[u8], ops: &[Op]) -> Result<(), TestCaseError> {
    let mut reference = ReaderSource::new(Cursor::new(text.to_vec()));
    let mut ahead = AheadSource::new(Cursor::new(text.to_vec()));
    ahead.read_blocks_as(Syntax::FANUC);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let (mut parsed, mut taken) = (Block::default(), Block::default());
    let mut starts = vec![0u64];
    for (k, op) in ops.iter().enumerate() {
        match op {
            Op::Read => {
                let want = reference.read_line(&mut a);
                let got = ahead.read_line(&mut b);
                match (&want, &got) {
                    (Ok(x), Ok(y)) => prop_assert_eq!(x, y, "read {}", k),
                    (Err(x), Err(y)) => prop_assert_eq!(x.to_string(), y.to_string()),
                    _ => prop_assert!(false, "read {}: {:?} against {:?}", k, want, got),
                }
                // After an error the buffer holds nothing of use.
                if want.is_ok() {
                    prop_assert_eq!(&a, &b, "line of read {}", k);
                }
                if matches!(want, Ok(true)) && ahead.take_block(7, &mut taken) {
                    let reading = parse_line_as(Syntax::FANUC, &a, 7, &mut parsed);
                    prop_assert!(
                        reading.is_ok(),
                        "a block read ahead for a line that does not read"
                    );
                    prop_assert_eq!(&taken, &parsed);
                }
            }
            Op::Back(rank) => {
                let to = starts[rank % starts.len()];
                prop_assert!(reference.seek(to).is_ok() && ahead.seek(to).is_ok());
            }
            Op::BackNear(n) => {
                let to = starts[starts.len() - 1 - n % starts.len().min(40)];
                prop_assert!(reference.seek(to).is_ok() && ahead.seek(to).is_ok());
            }
        }
        prop_assert_eq!(
            reference.position(),
            ahead.position(),
            "position after op {}",
            k
        );
        let here = reference.position();
        if !starts.contains(&here) {
            starts.push(here);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn reads_as_the_reader_source_does(
        lines in prop::collection::vec(line(), 0..1500),
        long in prop::option::of(0usize..1500),
        ops in ops(),
    ) {
        let mut lines = lines;
        // Now and then a line too long to read.
        if let Some(at) = long {
            let mut line = vec![b'X'; MAX_LINE_BYTES + 5];
            line.push(b'\n');
            lines.insert(at.min(lines.len()), line);
        }
        compare(&lines.concat(), &ops)?;
    }
}

#[test]
fn a_long_straight_program_comes_with_its_blocks() {
    let lines = 20_000;
    let text: Vec<u8> = (0..lines)
        .flat_map(|k| format!("G1 X{k}.5 Y-{k} F1000.\n").into_bytes())
        .collect();
    let mut ahead = AheadSource::new(Cursor::new(text));
    ahead.read_blocks_as(Syntax::FANUC);
    let (mut line, mut block, mut parsed) = (Vec::new(), Block::default(), Block::default());
    let mut with_blocks = 0;
    let mut read = 0;
    while ahead.read_line(&mut line).unwrap_or(false) {
        read += 1;
        if ahead.take_block(read, &mut block) {
            with_blocks += 1;
            assert!(parse_line_as(Syntax::FANUC, &line, read, &mut parsed).is_ok());
            assert_eq!(block, parsed);
        }
    }
    assert_eq!(read, lines);
    // Only the batches read before the rules arrived lack blocks.
    assert!(
        with_blocks >= lines - 6 * 512,
        "{with_blocks} blocks read ahead"
    );
}

#[test]
fn a_jump_out_of_the_batch_reads_on_directly() {
    let text: Vec<u8> = (0..5_000)
        .flat_map(|k| format!("G1 X{k}\n").into_bytes())
        .collect();
    let mut reference = ReaderSource::new(Cursor::new(text.clone()));
    let mut ahead = AheadSource::new(Cursor::new(text));
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..3_000 {
        assert_eq!(
            reference.read_line(&mut a).ok(),
            ahead.read_line(&mut b).ok()
        );
    }
    // Back to the start (long out of the batch), then forward past the end.
    for to in [0, 4, 30_000, 9] {
        assert!(reference.seek(to).is_ok() && ahead.seek(to).is_ok());
        for _ in 0..10 {
            assert_eq!(
                reference.read_line(&mut a).ok(),
                ahead.read_line(&mut b).ok()
            );
            assert_eq!(a, b);
            assert_eq!(reference.position(), ahead.position());
        }
    }
}
