//! Properties of `parse_line` over generated lines: it never panics, its
//! spans stay inside the line, and words printed in any legal layout read
//! back as written.

use fiveaxis_gcode::{Block, Code, Span, SyntaxError, parse_line};
use proptest::prelude::*;

/// Checks that `span` is a non-empty range of columns of a line of `len`
/// bytes (the end may be one past the last column).
fn assert_span_inside(span: Span, len: usize) -> Result<(), TestCaseError> {
    let last = u32::try_from(len).unwrap_or(u32::MAX).saturating_add(1);
    prop_assert!(span.start >= 1, "{span:?}");
    prop_assert!(span.start < span.end, "{span:?}");
    prop_assert!(span.end <= last, "{span:?} in {len} bytes");
    Ok(())
}

/// Parses `text` twice, into a fresh block and into a reused one, checks
/// that both agree and that every span lies inside the line.
fn check_any_line(text: &[u8]) -> Result<(), TestCaseError> {
    let mut fresh = Block::default();
    let result = parse_line(text, 3, &mut fresh);
    let mut reused = Block::default();
    let _ = parse_line(b"/N1 G1 X2 Y3 Z4 A5 B6 (reuse)", 1, &mut reused);
    prop_assert_eq!(parse_line(text, 3, &mut reused), result);
    prop_assert_eq!(&reused, &fresh);
    prop_assert_eq!(fresh.line, 3);
    match result {
        Ok(()) => {
            for word in &fresh.words {
                prop_assert!(word.letter.is_ascii_uppercase());
                prop_assert!(word.letter != b'N');
                prop_assert!(word.value.is_finite());
                assert_span_inside(word.span, text.len())?;
            }
        }
        Err(SyntaxError { span, .. }) => {
            prop_assert!(fresh.is_empty());
            assert_span_inside(span, text.len())?;
        }
    }
    Ok(())
}

/// A number as generated: its parts, printed and expected separately.
#[derive(Clone, Debug)]
struct Number {
    sign: &'static str,
    integer: String,
    point: bool,
    fraction: String,
}

impl Number {
    /// The text without blanks.
    fn text(&self) -> String {
        let point = if self.point { "." } else { "" };
        format!("{}{}{}{}", self.sign, self.integer, point, self.fraction)
    }

    /// What `str::parse` makes of it.
    fn value(&self) -> f64 {
        let integer = if self.integer.is_empty() {
            "0"
        } else {
            &self.integer
        };
        let sign = if self.sign == "-" { "-" } else { "" };
        format!("{sign}{integer}.{}0", self.fraction)
            .parse()
            .expect("generated numbers are valid")
    }

    /// The code form the front end must give.
    fn code(&self) -> Option<Code> {
        if !self.sign.is_empty() || self.fraction.len() > 1 {
            return None;
        }
        let major = self.integer.parse::<u16>().ok().or_else(|| {
            // Only leading zeros, or too big for `u16`.
            self.integer.bytes().all(|b| b == b'0').then_some(0)
        })?;
        let minor = self.fraction.bytes().next().map_or(0, |b| b - b'0');
        Some(Code::new(major, minor))
    }
}

fn number() -> impl Strategy<Value = Number> {
    (
        prop::sample::select(vec!["", "+", "-"]),
        "[0-9]{0,6}",
        any::<bool>(),
        "[0-9]{0,4}",
    )
        .prop_map(|(sign, mut integer, point, fraction)| {
            let fraction = if point { fraction } else { String::new() };
            if integer.is_empty() && fraction.is_empty() {
                integer.push('0');
            }
            Number {
                sign,
                integer,
                point,
                fraction,
            }
        })
}

/// A word to print: its letter (any case, never `N`) and number.
fn word() -> impl Strategy<Value = (char, Number)> {
    ("[A-MO-Za-mo-z]", number())
        .prop_map(|(letter, number)| (letter.chars().next().expect("one letter"), number))
}

/// Blanks put between the characters of a word.
fn blanks() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec!["", "", "", " ", "\t", "  "])
}

/// What stands between two words: nothing, blanks or a comment, whose text
/// may hold anything but `)` and `;`.
fn separator() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => Just(String::new()),
        3 => blanks().prop_map(String::from),
        1 => "[ \t]?\\([a-zA-Z0-9 #=%/\\[\\](\u{e9}]{0,12}\\)[ \t]?",
    ]
}

/// A word printed with `blanks` picked in turn between its characters.
fn print_word(letter: char, number: &Number, blanks: &[&str]) -> String {
    let mut text = String::from(letter);
    let mut blanks = blanks.iter().cycle();
    for c in number.text().chars() {
        text.push_str(blanks.next().copied().unwrap_or(""));
        text.push(c);
    }
    text
}

/// A whole line of generated words: (text, expected words, sequence).
#[derive(Clone, Debug)]
struct Line {
    text: String,
    words: Vec<(char, Number)>,
    sequence: Option<u32>,
    block_delete: bool,
}

fn line() -> impl Strategy<Value = Line> {
    (
        any::<bool>(),
        prop::option::of(0..100_000u32),
        prop::collection::vec(
            (word(), prop::collection::vec(blanks(), 1..4), separator()),
            0..8,
        ),
        prop::sample::select(vec!["", "\r", " ; X--1 #", ";", " (end)\r"]),
    )
        .prop_map(|(block_delete, sequence, words, ending)| {
            let mut text = String::new();
            if block_delete {
                text.push('/');
            }
            if let Some(sequence) = sequence {
                text.push_str(&format!("N{sequence} "));
            }
            let mut expected = Vec::new();
            for ((letter, number), blanks, separator) in words {
                // A lower-case `e` right after a number is an exponent.
                let after_number = text.ends_with(|c: char| c.is_ascii_digit() || c == '.');
                if letter == 'e' && after_number {
                    text.push(' ');
                }
                text.push_str(&print_word(letter, &number, &blanks));
                text.push_str(&separator);
                expected.push((letter, number));
            }
            text.push_str(ending);
            Line {
                text,
                words: expected,
                sequence,
                block_delete,
            }
        })
}

proptest! {
    #[test]
    fn never_panics_on_any_bytes(text in prop::collection::vec(any::<u8>(), 0..200)) {
        check_any_line(&text)?;
    }

    #[test]
    fn never_panics_on_gcode_like_text(
        text in "[GXYZNOMFSTIJKABgxyz0-9.+\\- \t;()%/#\\[\\]=,eE\r\u{e9}]{0,60}",
    ) {
        check_any_line(text.as_bytes())?;
    }

    #[test]
    fn never_panics_on_words_and_keywords(
        parts in prop::collection::vec(
            prop_oneof![
                Just("GOTO"), Just("IF"), Just("WHILE"), Just("TRAORI"), Just("N"), Just("%"),
                Just("/"), Just("("), Just(")"), Just(";"), Just("#"), Just("1.5"), Just("-"),
                Just("e"), Just(" "), Just("X"), Just("G01"), Just("99999999999999999"),
            ],
            0..16,
        ),
    ) {
        check_any_line(parts.concat().as_bytes())?;
    }

    #[test]
    fn printed_words_read_back(line in line()) {
        let mut block = Block::default();
        let result = parse_line(line.text.as_bytes(), 1, &mut block);
        prop_assert_eq!(result, Ok(()), "{:?}", line.text);
        prop_assert_eq!(block.words.len(), line.words.len(), "{:?}", line.text);
        prop_assert_eq!(block.sequence, line.sequence);
        prop_assert_eq!(block.block_delete, line.block_delete);
        for (word, (letter, number)) in block.words.iter().zip(&line.words) {
            prop_assert_eq!(char::from(word.letter), letter.to_ascii_uppercase());
            prop_assert_eq!(word.value.to_bits(), number.value().to_bits(), "{:?}", number);
            prop_assert_eq!(word.decimal_point, number.point);
            prop_assert_eq!(word.code, number.code(), "{:?}", number);
        }
    }
}
