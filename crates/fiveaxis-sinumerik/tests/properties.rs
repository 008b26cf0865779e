//! Properties of `parse_line` over generated lines: it never panics, it
//! reads a line the same way twice, and its spans stay inside the line.

use fiveaxis_sinumerik::{Span, parse_line};
use proptest::prelude::*;

/// `span` is a non-empty range of columns of a line of `len` bytes (the end
/// may be one past the last column).
fn assert_span_inside(span: Span, len: usize) -> Result<(), TestCaseError> {
    let last = u32::try_from(len).unwrap_or(u32::MAX).saturating_add(1);
    prop_assert!(span.start >= 1, "{span:?}");
    prop_assert!(span.start < span.end, "{span:?}");
    prop_assert!(span.end <= last, "{span:?} in {len} bytes");
    Ok(())
}

fn check(text: &[u8]) -> Result<(), TestCaseError> {
    let first = parse_line(text, 9);
    prop_assert_eq!(&parse_line(text, 9), &first);
    match first {
        Ok(line) => {
            prop_assert_eq!(line.line, 9);
            if let Some(c) = line.comment {
                assert_span_inside(c.span, text.len())?;
            }
            if let Some(n) = line.number {
                assert_span_inside(n.span, text.len())?;
            }
        }
        Err(e) => {
            prop_assert_eq!(e.line, 9);
            assert_span_inside(e.span, text.len())?;
            prop_assert!(!e.message.is_empty());
        }
    }
    Ok(())
}

/// Pieces of SINUMERIK text, glued together at random.
fn piece() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "N10",
        ":20",
        "/",
        "/3",
        "G0",
        "G1",
        "G642",
        "X",
        "Y-",
        "Z=",
        "10",
        "-5.5",
        ".5",
        "EX-3",
        "=",
        "==",
        "<>",
        "<",
        ">=",
        "<<",
        "+",
        "-",
        "*",
        "/",
        "(",
        ")",
        "[",
        "]",
        ",",
        ":",
        ";",
        "\"",
        "\"TXT\"",
        "'H1F'",
        "R1",
        "R[",
        "$AA_IW[X]",
        "$TC_DP3[1,1]",
        "_VAR",
        "AC(",
        "IC(",
        "DC(",
        "CR=",
        "A3=",
        "TURN=",
        "T=\"T1\"",
        "DEF",
        "REAL",
        "INT",
        "STRING[8]",
        "SET(",
        "REP(",
        "IF",
        "ELSE",
        "ENDIF",
        "WHILE",
        "FOR",
        "TO",
        "CASE",
        "OF",
        "DEFAULT",
        "GOTOF",
        "GOTOB",
        "GOTOS",
        "LBL:",
        "LBL",
        "AND",
        "OR",
        "NOT",
        "B_AND",
        "DIV",
        "MOD",
        "SIN(",
        "ATAN2(",
        "CYCLE81(",
        "MCALL",
        "CALL",
        "BLOCK",
        "PROC",
        "VAR",
        "SAVE",
        "TRAORI",
        "TRANS",
        "AROT",
        "RPL=",
        "SUPA",
        "MSG(",
        "ID=",
        "WHENEVER",
        "DO",
        "L100",
        "P3",
        "%",
        "DEFINE",
        "AS",
        "é",
        "\t",
    ])
}

fn siemens_like() -> impl Strategy<Value = String> {
    prop::collection::vec((piece(), prop::bool::ANY), 0..24).prop_map(|parts| {
        let mut s = String::new();
        for (p, space) in parts {
            s.push_str(p);
            if space {
                s.push(' ');
            }
        }
        s
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..160)) {
        check(&bytes)?;
    }

    #[test]
    fn siemens_like_text_never_panics(text in siemens_like()) {
        check(text.as_bytes())?;
    }

    #[test]
    fn printable_text_never_panics(text in "[ -~]{0,120}") {
        check(text.as_bytes())?;
    }
}
