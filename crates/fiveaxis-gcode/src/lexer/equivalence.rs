//! The fast path and the integer number conversion give exactly what the
//! previous scanner gave: the same words, bit-identical values, the same
//! flags, spans and errors.
//!
//! [`reference`] is that previous scanner, frozen: words read only by the
//! general path, numbers converted by `str::parse::<f64>` on their text. The
//! parts of the scanner that did not change (comments, errors, spans) are
//! shared with it.

use proptest::prelude::*;

use super::*;

/// The scanner as it was before the fast path and the integer conversion.
/// Not to be edited: it is the oracle of the tests below.
mod reference {
    use super::super::*;

    /// Room for the text handed to `str::parse`: a sign, the digits, a
    /// leading `0` when no integer digit is left, and the decimal point.
    const NUMBER_TEXT_LEN: usize = MAX_DIGITS + 3;

    pub(super) fn parse_line(text: &[u8], line: u32, block: &mut Block) -> Result<(), SyntaxError> {
        block.clear();
        block.line = line;
        let text = block_text(text);
        read_block(text, block).map_err(|error| {
            block.clear();
            block.line = line;
            macro_line_error(text, Syntax::FANUC, error)
        })
    }

    fn read_block(text: &[u8], block: &mut Block) -> Result<(), SyntaxError> {
        let mut pos = skip_blanks(text, 0);
        match text.get(pos) {
            Some(&TAPE_MARK) => {
                block.tape_mark = true;
                return Ok(());
            }
            Some(&BLOCK_DELETE) => {
                block.block_delete = true;
                pos = skip_block_delete(text, pos);
            }
            _ => {}
        }
        loop {
            pos = skip_blanks(text, pos);
            let Some(&byte) = text.get(pos) else {
                return Ok(());
            };
            pos = if byte == COMMENT_OPEN {
                skip_comment(text, pos, Syntax::FANUC)?
            } else if byte.is_ascii_alphabetic() {
                read_word(text, pos, block)?
            } else {
                return Err(stray(text, pos));
            };
        }
    }

    fn read_word(text: &[u8], start: usize, block: &mut Block) -> Result<usize, SyntaxError> {
        let letter = text.get(start).map_or(b'?', u8::to_ascii_uppercase);
        let value_start = start + 1;
        let next = skip_blanks(text, value_start);
        if text.get(next).is_some_and(u8::is_ascii_alphabetic) {
            return Err(multi_letter_word(text, start));
        }
        let end = number_end(text, value_start, true);
        if end == value_start {
            return Err(no_value(text, start, letter, next));
        }
        let span = span(start, end);
        let number = read_number(text.get(value_start..end).unwrap_or_default())
            .map_err(|kind| SyntaxError::new(kind, span))?;
        if letter == SEQUENCE_LETTER {
            set_sequence(block, &number, span)?;
        } else {
            block.words.push(Word {
                letter,
                value: number.value,
                decimal_point: number.decimal_point,
                code: number.code(),
                computed: false,
                span,
            });
        }
        Ok(end)
    }

    /// The former `Number::read`.
    pub(super) fn read_number(text: &[u8]) -> Result<Number, SyntaxErrorKind> {
        let mut reader = NumberReader::default();
        for &byte in text.iter().filter(|&&b| !is_blank(b)) {
            match byte {
                PLUS | MINUS => reader.sign(byte)?,
                DECIMAL_POINT => reader.point()?,
                b'0'..=b'9' => reader.digit(byte),
                _ => return Err(SyntaxErrorKind::BadNumber),
            }
        }
        reader.finish()
    }

    #[derive(Debug, Default)]
    struct NumberReader {
        text: [u8; NUMBER_TEXT_LEN],
        len: usize,
        signed: bool,
        decimal_point: bool,
        any_digit: bool,
        integer_digits: usize,
        fraction_digits: usize,
        integer: u64,
        first_fraction_digit: u8,
        too_many_digits: bool,
    }

    impl NumberReader {
        fn push(&mut self, byte: u8) {
            if let Some(slot) = self.text.get_mut(self.len) {
                *slot = byte;
                self.len += 1;
            }
        }

        fn sign(&mut self, sign: u8) -> Result<(), SyntaxErrorKind> {
            if self.signed || self.any_digit || self.decimal_point {
                return Err(SyntaxErrorKind::BadNumber);
            }
            self.signed = true;
            if sign == MINUS {
                self.push(MINUS);
            }
            Ok(())
        }

        fn point(&mut self) -> Result<(), SyntaxErrorKind> {
            if self.decimal_point {
                return Err(SyntaxErrorKind::BadNumber);
            }
            self.decimal_point = true;
            if self.integer_digits == 0 {
                self.push(b'0');
            }
            self.push(DECIMAL_POINT);
            Ok(())
        }

        fn digit(&mut self, digit: u8) {
            self.any_digit = true;
            let value = digit - b'0';
            if self.decimal_point {
                if self.fraction_digits == 0 {
                    self.first_fraction_digit = value;
                }
                self.fraction_digits += 1;
            } else if value == 0 && self.integer_digits == 0 {
                return;
            } else {
                self.integer_digits += 1;
                self.integer = self
                    .integer
                    .saturating_mul(10)
                    .saturating_add(u64::from(value));
            }
            if self.integer_digits + self.fraction_digits > MAX_DIGITS {
                self.too_many_digits = true;
            } else {
                self.push(digit);
            }
        }

        fn finish(mut self) -> Result<Number, SyntaxErrorKind> {
            if !self.any_digit {
                return Err(SyntaxErrorKind::BadNumber);
            }
            if self.too_many_digits {
                return Err(SyntaxErrorKind::TooManyDigits);
            }
            if self.integer_digits == 0 && !self.decimal_point {
                self.push(b'0');
            }
            let value = self
                .text
                .get(..self.len)
                .and_then(|text| std::str::from_utf8(text).ok())
                .and_then(|text| text.parse::<f64>().ok())
                .ok_or(SyntaxErrorKind::BadNumber)?;
            Ok(Number {
                value,
                signed: self.signed,
                decimal_point: self.decimal_point,
                integer: self.integer,
                fraction_digits: self.fraction_digits,
                first_fraction_digit: self.first_fraction_digit,
            })
        }
    }
}

/// A word with its value as bits, so that `-0.0` and `0.0` differ.
type ExactWord = (u8, u64, bool, Option<Code>, Span);

/// Everything `parse` makes of a line, compared exactly.
#[derive(Debug, PartialEq)]
struct Outcome {
    result: Result<(), SyntaxError>,
    line: u32,
    block_delete: bool,
    tape_mark: bool,
    sequence: Option<u32>,
    words: Vec<ExactWord>,
}

fn outcome(parse: fn(&[u8], u32, &mut Block) -> Result<(), SyntaxError>, text: &[u8]) -> Outcome {
    let mut block = Block::default();
    let result = parse(text, 9, &mut block);
    Outcome {
        result,
        line: block.line,
        block_delete: block.block_delete,
        tape_mark: block.tape_mark,
        sequence: block.sequence,
        words: block
            .words
            .iter()
            .map(|w| (w.letter, w.value.to_bits(), w.decimal_point, w.code, w.span))
            .collect(),
    }
}

fn check_line(text: &[u8]) -> Result<(), TestCaseError> {
    prop_assert_eq!(
        outcome(parse_line, text),
        outcome(reference::parse_line, text),
        "{:?}",
        String::from_utf8_lossy(text)
    );
    Ok(())
}

/// A number's fields, with its value as bits.
fn exact_number(number: &Number) -> (u64, bool, bool, u64, usize, u8) {
    (
        number.value.to_bits(),
        number.signed,
        number.decimal_point,
        number.integer,
        number.fraction_digits,
        number.first_fraction_digit,
    )
}

/// A number without blanks: a sign or not, zeros in front, then 1 to
/// `max_digits` digits, some of them after the point when there is one.
fn plain_number(max_digits: usize) -> impl Strategy<Value = String> {
    (
        prop::sample::select(vec!["", "+", "-"]),
        "0{0,3}",
        prop::string::string_regex(&format!("[0-9]{{1,{max_digits}}}")).expect("a valid regex"),
        any::<bool>(),
        any::<prop::sample::Index>(),
    )
        .prop_map(|(sign, zeros, digits, point, split)| {
            if point {
                let (integer, fraction) = digits.split_at(split.index(digits.len() + 1));
                format!("{sign}{zeros}{integer}.{fraction}")
            } else {
                format!("{sign}{zeros}{digits}")
            }
        })
}

/// A number as `printf` would write a coordinate: up to 6 integer digits
/// and 0 to 6 decimals.
fn coordinate() -> impl Strategy<Value = String> {
    (-999_999.0..999_999.0f64, 0..7usize, any::<bool>()).prop_map(|(value, decimals, point)| {
        let text = format!("{value:.decimals$}");
        if point && decimals == 0 {
            text + "."
        } else {
            text
        }
    })
}

/// A realistic line: words of coordinates and codes between blanks or
/// comments, now and then with blanks inside a word.
fn realistic_line() -> impl Strategy<Value = String> {
    let word = (
        "[GMXYZABCFIJKNSTgxyz]",
        prop_oneof![
            coordinate(),
            plain_number(MAX_DIGITS),
            "[0-9]{1,3}(\\.[0-9])?"
        ],
        prop::sample::select(vec!["", "", "", "", " ", "\t"]),
        prop::sample::select(vec![" ", " ", "", "\t", "  ", " (c) ", "(c)"]),
    )
        .prop_map(|(letter, number, inside, after)| format!("{letter}{inside}{number}{after}"));
    (
        prop::collection::vec(word, 0..8),
        prop::sample::select(vec!["", "", "\r", " ;x", " e", "e", "1", " .5", " -", "#"]),
    )
        .prop_map(|(words, ending)| words.concat() + ending)
}

proptest! {
    #[test]
    fn plain_numbers_match_str_parse(text in plain_number(MAX_DIGITS)) {
        let (number, end) = read_plain_number(text.as_bytes(), 0, true)
            .ok_or_else(|| TestCaseError::fail(format!("{text:?} is not plain")))?;
        let expected: f64 = text.parse().map_err(|e| TestCaseError::fail(format!("{e}")))?;
        prop_assert_eq!(number.value.to_bits(), expected.to_bits(), "{:?}", text);
        prop_assert_eq!(end, text.len());
    }

    #[test]
    fn plain_numbers_match_the_reference(
        text in plain_number(MAX_DIGITS + 3),
        after in "[ \tXe(=.+-]{0,2}",
    ) {
        let line = format!("{text}{after}");
        let bytes = line.as_bytes();
        if let Some((number, end)) = read_plain_number(bytes, 0, true) {
            prop_assert_eq!(end, number_end(bytes, 0, true), "{:?}", line);
            let expected = reference::read_number(&bytes[..end])
                .map_err(|e| TestCaseError::fail(format!("{line:?}: {e}")))?;
            prop_assert_eq!(exact_number(&number), exact_number(&expected), "{:?}", line);
        }
        check_line(format!("X{line}").as_bytes())?;
    }

    #[test]
    fn general_numbers_match_the_reference(text in "[0-9 .+\\-]{0,24}") {
        let new = Number::read(text.as_bytes()).map(|n| exact_number(&n));
        let old = reference::read_number(text.as_bytes()).map(|n| exact_number(&n));
        prop_assert_eq!(new, old, "{:?}", text);
    }

    #[test]
    fn realistic_lines_match_the_reference(text in realistic_line()) {
        check_line(text.as_bytes())?;
    }

    #[test]
    fn gcode_like_text_matches_the_reference(
        text in "[GXYZNOMgxyz0-9.+\\- \t;()%/#\\[\\]=eE\r]{0,40}",
    ) {
        check_line(text.as_bytes())?;
    }

    #[test]
    fn any_bytes_match_the_reference(text in prop::collection::vec(any::<u8>(), 0..80)) {
        check_line(&text)?;
    }
}

#[test]
fn edge_cases_match_the_reference() {
    for text in [
        "G1 X123.456 Y-45.678 Z12.5 A-30.125 C270.25",
        "X-0",
        "X-0.000",
        "X+.5",
        "X5.",
        "X.",
        "X-",
        "X-.",
        "X1 .5",
        "X1 - 2",
        "X1 e5",
        "X1e5",
        "X1.e5",
        "X1 \t",
        "X1(c)0",
        "X1=2",
        "X123456789012345",
        "X1234567890123456",
        "X0.000000000000001",
        "X0.0000000000000001",
        "X00000000000000000001.5",
        "X999999999999999 Y.999999999999999",
        "X12345678901234567.8.9",
        "N4294967295",
        "N4294967296",
        "N1 G1 N2",
        "N1.",
        "G65535 G65536 G43.4 G1.50",
        "G1 X#1",
    ] {
        let text = text.as_bytes();
        assert_eq!(
            outcome(parse_line, text),
            outcome(reference::parse_line, text),
            "{:?}",
            String::from_utf8_lossy(text)
        );
    }
}
