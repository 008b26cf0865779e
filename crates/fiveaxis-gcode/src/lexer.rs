//! The hand-written byte scanner behind [`parse_line`].
//!
//! The line is walked once, left to right, with a position into its bytes.
//! Every byte is read through `get` or slice patterns, so no input can index
//! out of bounds, and the only buffers are small arrays on the stack: the
//! sole heap activity is pushing into the block's reused word vector.
//!
//! Words are read in one of two ways, with the same result:
//!
//! * the fast path, [`read_plain_number`], takes the common case of a letter
//!   followed right away by `[+|-] digits [. digits]`, without blanks, that
//!   ends where the general scanner would end it;
//! * the general path, [`read_general_number`], takes everything else:
//!   blanks inside the number, malformed numbers, too many digits, letters
//!   without a number, words of several letters.
//!
//! Both build the number as an integer mantissa and a count of decimals and
//! divide it by an exact power of ten ([`decimal_value`]): since a number
//! has at most [`MAX_DIGITS`] digits, this is correctly rounded and so
//! bit-identical to `str::parse::<f64>` on the same digits.

use crate::{Block, Code, Span, Syntax, SyntaxError, SyntaxErrorKind, UnknownWord, Word};

/// The most digits a number may have. The zeros written in front of the
/// integer part do not count (`X007` has one digit, `G01` one); every other
/// digit does, zeros after the decimal point included (`X0.001` has three).
pub const MAX_DIGITS: usize = 15;

/// Ends the block: the rest of the line is ignored.
const END_OF_BLOCK: u8 = b';';
/// Line terminators a caller may leave at the end of the line.
const LINE_TERMINATORS: [u8; 2] = [b'\r', b'\n'];
/// Bytes that may stand anywhere between and inside words.
const BLANKS: [u8; 2] = [b' ', b'\t'];
/// Opens a comment (FANUC "control out").
const COMMENT_OPEN: u8 = b'(';
/// Closes a comment (FANUC "control in").
const COMMENT_CLOSE: u8 = b')';
/// The tape mark, alone on its line.
const TAPE_MARK: u8 = b'%';
/// Block delete, as the first byte of a block.
const BLOCK_DELETE: u8 = b'/';
/// The lowest and highest optional block skip numbers (`/1` … `/9`).
const SKIP_LEVELS: std::ops::RangeInclusive<u8> = b'1'..=b'9';
/// The address of the sequence number.
const SEQUENCE_LETTER: u8 = b'N';
const DECIMAL_POINT: u8 = b'.';
const PLUS: u8 = b'+';
const MINUS: u8 = b'-';
/// A lower-case `e` written right after the digits of a number is taken for
/// a floating-point exponent (`G1e5`), which G-code does not have.
const EXPONENT: u8 = b'e';
/// Besides letters and digits, identifiers of other dialects may hold `_`.
const IDENTIFIER_PUNCTUATION: u8 = b'_';
/// Custom macro punctuation: `#` variables and `[ ]` expressions.
const MACRO_CHARS: [u8; 3] = [b'#', b'[', b']'];
/// The words of FANUC custom macro B that are made of letters only (and
/// the structured IF's `ELSE` and `ENDIF` of Mitsubishi and Mazak).
const MACRO_KEYWORDS: [&[u8]; 31] = [
    b"IF", b"WHILE", b"GOTO", b"DO", b"END", b"THEN", b"ELSE", b"ENDIF", b"EQ", b"NE", b"GT",
    b"LT", b"GE", b"LE", b"AND", b"OR", b"XOR", b"SIN", b"COS", b"TAN", b"ATAN", b"SQRT", b"ABS",
    b"ROUND", b"FIX", b"FUP", b"BIN", b"BCD", b"POPEN", b"PCLOS", b"DPRNT",
];
/// The powers of ten that `f64` holds exactly: 10^0 … 10^22.
const EXACT_POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];
/// Every integer up to this one is exact in an `f64` (2^53).
const MAX_EXACT_INTEGER: u64 = 1 << f64::MANTISSA_DIGITS;
// A number of `MAX_DIGITS` digits must convert exactly in `decimal_value`:
// its mantissa stays below 10^MAX_DIGITS and its decimals index the table.
// Raising `MAX_DIGITS` past 15 needs another conversion (`str::parse`).
const _: () = assert!(
    MAX_DIGITS < EXACT_POWERS_OF_TEN.len() && 10_u64.pow(MAX_DIGITS as u32) <= MAX_EXACT_INTEGER
);
/// The longest UTF-8 encoding of one character.
const MAX_UTF8_LEN: usize = 4;

/// Reads one line of a program into `block` (cleared first).
///
/// `text` is the line without its line feed (a trailing `\r` or `\n` is
/// removed anyway); `line` is its 1-based number, stored in
/// [`Block::line`]. The rules are those of the crate documentation.
///
/// On error the block is left empty apart from its line number, so that a
/// half-read block cannot be executed by mistake, and the error is the first
/// one in the line.
///
/// # Errors
///
/// A [`SyntaxError`] with the columns of the first text that cannot be read.
pub fn parse_line(text: &[u8], line: u32, block: &mut Block) -> Result<(), SyntaxError> {
    parse_line_as(Syntax::FANUC, text, line, block)
}

/// Reads one line of a program into `block` with the reading rules of
/// `syntax` (a control's dialect of the tape format); otherwise as
/// [`parse_line`].
///
/// # Errors
///
/// A [`SyntaxError`] with the columns of the first text that cannot be read.
pub fn parse_line_as(
    syntax: Syntax,
    text: &[u8],
    line: u32,
    block: &mut Block,
) -> Result<(), SyntaxError> {
    block.clear();
    block.line = line;
    let text = if syntax.semicolon_outside_comments {
        block_text_outside_comments(text, syntax.nested_comments)
    } else {
        block_text(text)
    };
    read_block(text, syntax, block).map_err(|error| {
        block.clear();
        block.line = line;
        macro_line_error(text, syntax, error)
    })
}

/// The part of the line that makes the block: up to the first `;`, without
/// trailing line terminators.
fn block_text(text: &[u8]) -> &[u8] {
    // Most lines have no `;`. Looking for one without stopping at the first
    // lets the compiler compare many bytes at a time.
    let has_end = text
        .iter()
        .fold(false, |found, &b| found | (b == END_OF_BLOCK));
    let mut block = if has_end {
        text.split(|&b| b == END_OF_BLOCK).next().unwrap_or(text)
    } else {
        text
    };
    while let [rest @ .., last] = block {
        if !LINE_TERMINATORS.contains(last) {
            break;
        }
        block = rest;
    }
    block
}

/// The part of the line that makes the block when `;` starts a comment
/// only outside parentheses: up to the first such `;`, without trailing
/// line terminators.
/// With `nested` comments a `(` inside one opens a level its own `)`
/// closes (Haas); otherwise the first `)` ends the comment.
fn block_text_outside_comments(text: &[u8], nested: bool) -> &[u8] {
    let mut depth = 0_usize;
    let mut end = text.len();
    for (i, &b) in text.iter().enumerate() {
        match b {
            COMMENT_OPEN if nested => depth += 1,
            COMMENT_OPEN => depth = 1,
            COMMENT_CLOSE => depth = depth.saturating_sub(1),
            END_OF_BLOCK if depth == 0 => {
                end = i;
                break;
            }
            _ => {}
        }
    }
    let mut block = text.get(..end).unwrap_or(text);
    while let [rest @ .., last] = block {
        if !LINE_TERMINATORS.contains(last) {
            break;
        }
        block = rest;
    }
    block
}

/// Reads the block: tape mark or block delete first, then words and
/// comments up to the end.
fn read_block(text: &[u8], syntax: Syntax, block: &mut Block) -> Result<(), SyntaxError> {
    if read_plain_block(text, block) {
        return Ok(());
    }
    // Whatever the plain reader took is read again.
    block.words.clear();
    block.sequence = None;
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
            let end = skip_comment(text, pos, syntax)?;
            if block.comment_span.is_none() {
                block.comment_span = Some(span(pos, end));
                block.comment.extend_from_slice(&text[pos + 1..end - 1]);
            }
            end
        } else if byte.is_ascii_alphabetic() {
            read_word(text, pos, block, syntax)?
        } else {
            return Err(stray(text, pos));
        };
    }
}

/// The fast path of [`read_block`] for the line most blocks are: words of
/// an upper-case letter and a plain number (`[+|-] digits [. digits]`, at
/// most [`MAX_DIGITS`] digits), separated by blanks or by nothing, one `N`
/// at most. Reads it in one pass and returns true; returns false, at the
/// first byte it does not take (a comment, a lower-case letter, `%`, `/`,
/// a blank inside a number…), for [`read_block`] to read the line its
/// general way. Taken or not, the block is the same (`lexer/equivalence.rs`
/// checks it against the scanner without fast paths).
fn read_plain_block(text: &[u8], block: &mut Block) -> bool {
    // Columns below u32::MAX need no saturation (longer lines go the
    // general way).
    if text.len() >= u32::MAX as usize {
        return false;
    }
    // The byte at `k`, or 0 past the end: 0 is no blank, letter, sign,
    // digit or point, so every test below stops there.
    let at = |k: usize| text.get(k).copied().unwrap_or(0);
    let blank = |b: u8| b == b' ' || b == b'\t';
    let mut i = 0;
    while blank(at(i)) {
        i += 1;
    }
    while i < text.len() {
        let start = i;
        let letter = at(i);
        if !letter.is_ascii_uppercase() {
            return false;
        }
        i += 1;
        let sign = at(i);
        let negative = match sign {
            PLUS => Some(false),
            MINUS => Some(true),
            _ => None,
        };
        i += usize::from(negative.is_some());
        let unsigned = i;
        while at(i) == b'0' {
            i += 1;
        }
        let significant = i;
        let (integer, after) = digits_at(text, i, 0);
        i = after;
        let mut mantissa = integer;
        let integer_digits = i - significant;
        let any_integer_digit = i > unsigned;
        let decimal_point = at(i) == DECIMAL_POINT;
        let mut fraction_digits = 0;
        let mut first_fraction_digit = 0;
        if decimal_point {
            i += 1;
            let fraction = i;
            (mantissa, i) = digits_at(text, fraction, integer);
            fraction_digits = i - fraction;
            if fraction_digits > 0 {
                first_fraction_digit = at(fraction) - b'0';
            }
        }
        // Past MAX_DIGITS the digits may have wrapped: refused before use.
        if (!any_integer_digit && fraction_digits == 0)
            || integer_digits + fraction_digits > MAX_DIGITS
        {
            return false;
        }
        let span = Span::new(start as u32 + 1, i as u32 + 1);
        // The number ends at the end, at the next word's letter, or at
        // blanks before either.
        while blank(at(i)) {
            i += 1;
        }
        if i < text.len() && !at(i).is_ascii_uppercase() {
            return false;
        }
        let Some(magnitude) = decimal_value(mantissa, fraction_digits) else {
            return false;
        };
        if letter == SEQUENCE_LETTER {
            if negative.is_some() || decimal_point || block.sequence.is_some() {
                return false;
            }
            let Ok(sequence) = u32::try_from(integer) else {
                return false;
            };
            block.sequence = Some(sequence);
        } else {
            let code =
                (negative.is_none() && fraction_digits <= 1 && integer <= u64::from(u16::MAX))
                    .then(|| Code::new(integer as u16, first_fraction_digit));
            block.words.push(Word {
                letter,
                value: if negative == Some(true) {
                    -magnitude
                } else {
                    magnitude
                },
                decimal_point,
                code,
                computed: false,
                span,
            });
        }
    }
    true
}

/// Steps over `/` and its optional skip number `1` … `9`; `pos` is at `/`.
fn skip_block_delete(text: &[u8], pos: usize) -> usize {
    let after_slash = pos + 1;
    let next = skip_blanks(text, after_slash);
    match text.get(next) {
        Some(level) if SKIP_LEVELS.contains(level) => next + 1,
        _ => after_slash,
    }
}

/// Steps over the comment that opens at `pos`.
fn skip_comment(text: &[u8], pos: usize, syntax: Syntax) -> Result<usize, SyntaxError> {
    comment_end(text, pos, syntax)
        .ok_or_else(|| SyntaxError::new(SyntaxErrorKind::UnclosedComment, span(pos, text.len())))
}

/// The position after the `)` that closes the comment opened at `pos`.
/// FANUC: a `(` inside a comment is plain text, the first `)` closes it.
/// With [`Syntax::nested_comments`] each `(` inside opens a level that its
/// own `)` closes, and the comment ends with the `)` that balances its
/// opening one.
fn comment_end(text: &[u8], pos: usize, syntax: Syntax) -> Option<usize> {
    let body = pos + 1;
    let rest = text.get(body..)?;
    if !syntax.nested_comments {
        let close = rest.iter().position(|&b| b == COMMENT_CLOSE)?;
        return Some(body + close + 1);
    }
    let mut depth = 1_usize;
    for (offset, &byte) in rest.iter().enumerate() {
        if byte == COMMENT_OPEN {
            depth += 1;
        } else if byte == COMMENT_CLOSE {
            depth -= 1;
            if depth == 0 {
                return Some(body + offset + 1);
            }
        }
    }
    None
}

/// Reads the word whose letter is at `start` and returns where it ends.
fn read_word(
    text: &[u8],
    start: usize,
    block: &mut Block,
    syntax: Syntax,
) -> Result<usize, SyntaxError> {
    let letter = text.get(start).map_or(b'?', u8::to_ascii_uppercase);
    let exponent = !syntax.e_after_digits_is_a_word;
    let (number, end) = match read_plain_number(text, start + 1, exponent) {
        Some(plain) => plain,
        None => read_general_number(text, start, letter, exponent)?,
    };
    let span = span(start, end);
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

/// The fast path of [`read_word`]: the number written right after the
/// letter, from `start`, and where it ends, when it is plainly
/// `[+|-] digits [. digits]` with no blank inside, at least one digit and at
/// most [`MAX_DIGITS`] of them, and nothing after it that the general
/// scanner would take as more of the number: a sign, a point or an exponent
/// `e` right after it, a digit, sign or point after blanks.
///
/// `None` sends the word to [`read_general_number`], which then gives the
/// same result as before this fast path existed (or the error).
fn read_plain_number(text: &[u8], start: usize, exponent: bool) -> Option<(Number, usize)> {
    let bytes = text.get(start..)?;
    // One pass over the bytes by index: sign, zeros in front, integer
    // digits, point, fraction digits.
    let mut i = 0;
    let sign = match bytes.first() {
        Some(&sign @ (PLUS | MINUS)) => {
            i = 1;
            Some(sign)
        }
        _ => None,
    };
    let unsigned = i;
    while bytes.get(i) == Some(&b'0') {
        i += 1;
    }
    let significant = i;
    let (integer, after_integer) = digits_at(bytes, i, 0);
    let integer_digits = after_integer - significant;
    let any_integer_digit = after_integer > unsigned;
    let (decimal_point, mantissa, fraction_digits, first_fraction_digit, after) =
        if bytes.get(after_integer) == Some(&DECIMAL_POINT) {
            let fraction = after_integer + 1;
            let (mantissa, after) = digits_at(bytes, fraction, integer);
            let first = match bytes.get(fraction) {
                Some(&digit @ b'0'..=b'9') if after > fraction => digit - b'0',
                _ => 0,
            };
            (true, mantissa, after - fraction, first, after)
        } else {
            (false, integer, 0, 0, after_integer)
        };
    if !(any_integer_digit || fraction_digits > 0)
        || integer_digits + fraction_digits > MAX_DIGITS
        || !ends_plain_number(bytes.get(after..).unwrap_or_default(), exponent)
    {
        return None;
    }
    let magnitude = decimal_value(mantissa, fraction_digits)?;
    let number = Number {
        value: if sign == Some(MINUS) {
            -magnitude
        } else {
            magnitude
        },
        signed: sign.is_some(),
        decimal_point,
        integer,
        fraction_digits,
        first_fraction_digit,
    };
    Some((number, start + after))
}

/// Reads the ASCII digits of `bytes` from `from`, written after those of
/// `value`: the new value and where the digits end. The value wraps past
/// 19 digits; callers refuse more than [`MAX_DIGITS`].
fn digits_at(bytes: &[u8], from: usize, mut value: u64) -> (u64, usize) {
    let mut i = from;
    while let Some(&byte) = bytes.get(i) {
        let digit = byte.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        value = value.wrapping_mul(10).wrapping_add(u64::from(digit));
        i += 1;
    }
    (value, i)
}

/// Whether the plain number followed by `after` ends there for
/// [`number_end`] too: nothing follows, or something that is not part of a
/// number, possibly after blanks. An `e` right after the number is an
/// exponent; after blanks it is the `E` address.
fn ends_plain_number(after: &[u8], exponent: bool) -> bool {
    match after {
        [] => true,
        [EXPONENT, ..] => !exponent,
        [blank, ..] if is_blank(*blank) => after
            .iter()
            .find(|&&byte| !is_blank(byte))
            .is_none_or(|&byte| !is_number_byte(byte)),
        [byte, ..] => !is_number_byte(*byte),
    }
}

/// The general path of [`read_word`], for the word whose letter is at
/// `start`: blanks anywhere in the number, and every error.
fn read_general_number(
    text: &[u8],
    start: usize,
    letter: u8,
    exponent: bool,
) -> Result<(Number, usize), SyntaxError> {
    let value_start = start + 1;
    let next = skip_blanks(text, value_start);
    if text.get(next).is_some_and(u8::is_ascii_alphabetic) {
        return Err(multi_letter_word(text, start));
    }
    let end = number_end(text, value_start, exponent);
    if end == value_start {
        return Err(no_value(text, start, letter, next));
    }
    let number = Number::read(text.get(value_start..end).unwrap_or_default())
        .map_err(|kind| SyntaxError::new(kind, span(start, end)))?;
    Ok((number, end))
}

/// Stores the `N` number of the block.
fn set_sequence(block: &mut Block, number: &Number, span: Span) -> Result<(), SyntaxError> {
    let sequence = number
        .sequence()
        .ok_or(SyntaxError::new(SyntaxErrorKind::BadNumber, span))?;
    if block.sequence.is_some() {
        return Err(SyntaxError::new(SyntaxErrorKind::DuplicateSequence, span));
    }
    block.sequence = Some(sequence);
    Ok(())
}

/// The error for a letter at `start` with no number after it; `next` is the
/// first non-blank position after the letter.
fn no_value(text: &[u8], start: usize, letter: u8, next: usize) -> SyntaxError {
    match text.get(next) {
        None | Some(&COMMENT_OPEN) => SyntaxError::new(
            SyntaxErrorKind::MissingValue(char::from(letter)),
            span(start, start + 1),
        ),
        Some(_) => stray(text, next),
    }
}

/// The error for a word of several letters starting at `start`: a custom
/// macro keyword, or a word of another dialect.
///
/// The name is made of runs of letters. Blanks end it, except after a run
/// of a single letter, so that spaced-out letters stay together (`G O T O`
/// is `GOTO`, `X Y1` is `XY1`) while `TRAORI X1` names `TRAORI` only. The
/// identifier then goes on with the letters, digits and `_` written right
/// after its last letter (`CYCLE800`).
fn multi_letter_word(text: &[u8], start: usize) -> SyntaxError {
    let mut name = NameBuffer::default();
    let mut letters = 0;
    let mut pos = start;
    loop {
        let run_start = pos;
        while let Some(&letter) = text.get(pos).filter(|b| b.is_ascii_alphabetic()) {
            name.push(letter);
            pos += 1;
        }
        letters += pos - run_start;
        let next = skip_blanks(text, pos);
        if pos - run_start != 1 || !text.get(next).is_some_and(u8::is_ascii_alphabetic) {
            break;
        }
        pos = next;
    }
    let letters_end = pos;
    if letters == name.len && is_macro_keyword(name.as_bytes()) {
        return SyntaxError::new(SyntaxErrorKind::Macro, span(start, letters_end));
    }
    let mut end = letters_end;
    while let Some(&byte) = text.get(end).filter(|&&b| is_identifier(b)) {
        name.push(byte);
        end += 1;
    }
    let word = match letter_o(text, start, name.as_bytes()) {
        Some(before) => UnknownWord::with_letter_o(name.as_bytes(), before),
        None => UnknownWord::new(name.as_bytes()),
    };
    SyntaxError::new(SyntaxErrorKind::UnknownWord(word), span(start, end))
}

/// Whether the unknown word `name` at `start` looks like a letter O typed
/// for the digit 0: `Some(Some(word))` when it starts with an O written
/// right after the number of `word` (`G1O X10.`: `G1`), `Some(None)` when
/// its second letter is an O written right after its address letter and
/// only digits follow (`GO1`). Error path only.
fn letter_o<'t>(text: &'t [u8], start: usize, name: &[u8]) -> Option<Option<&'t [u8]>> {
    let is_o = |at: usize| text.get(at).is_some_and(|b| b.eq_ignore_ascii_case(&b'O'));
    if is_o(start) {
        // Back over the number before it to its address letter.
        let mut from = start;
        while from > 0 && text.get(from - 1).is_some_and(|&b| is_number_byte(b)) {
            from -= 1;
        }
        let digits = text.get(from..start).unwrap_or_default();
        let letter = from.checked_sub(1).and_then(|at| text.get(at));
        let numbered = digits.iter().any(u8::is_ascii_digit);
        return (numbered && letter.is_some_and(u8::is_ascii_alphabetic))
            .then(|| text.get(from - 1..start));
    }
    let digits_after = name
        .get(2..)
        .is_some_and(|r| r.iter().all(u8::is_ascii_digit));
    (is_o(start + 1) && name.len() >= 2 && digits_after).then_some(None)
}

/// The error for a byte that cannot start anything at `pos`.
fn stray(text: &[u8], pos: usize) -> SyntaxError {
    if text.get(pos).is_some_and(|b| MACRO_CHARS.contains(b)) {
        return SyntaxError::new(SyntaxErrorKind::Macro, span(pos, pos + 1));
    }
    let (character, len) = decode_char(text, pos);
    let kind = match text.get(pos) {
        // Not text at all: say which byte, not a replacement character.
        Some(&byte) if character == char::REPLACEMENT_CHARACTER && len == 1 => {
            SyntaxErrorKind::InvalidByte(byte)
        }
        _ => SyntaxErrorKind::UnexpectedChar(character),
    };
    SyntaxError::new(kind, span(pos, pos + len))
}

/// In a line written in custom macro syntax (one with `#`, `[` or `]`
/// outside comments), any error is the macro syntax's fault: it is reported
/// as [`SyntaxErrorKind::Macro`] at the first of these characters. A macro
/// keyword found first keeps its own span.
fn macro_line_error(text: &[u8], syntax: Syntax, error: SyntaxError) -> SyntaxError {
    if error.kind == SyntaxErrorKind::Macro {
        return error;
    }
    match first_macro_char(text, syntax) {
        Some(pos) => SyntaxError::new(SyntaxErrorKind::Macro, span(pos, pos + 1)),
        None => error,
    }
}

/// The first `#`, `[` or `]` outside comments, looked for up to an unclosed
/// comment.
fn first_macro_char(text: &[u8], syntax: Syntax) -> Option<usize> {
    let mut pos = 0;
    while let Some(&byte) = text.get(pos) {
        if byte == COMMENT_OPEN {
            pos = comment_end(text, pos, syntax)?;
        } else if MACRO_CHARS.contains(&byte) {
            return Some(pos);
        } else {
            pos += 1;
        }
    }
    None
}

/// The position after the last byte of the number that starts at `start`:
/// digits, points and signs, blanks between them, and an exponent `e`
/// written right after a digit or point (so that it is refused whole).
/// Equal to `start` when no number is written there.
fn number_end(text: &[u8], start: usize, exponent_allowed: bool) -> usize {
    let mut end = start;
    let mut after_digit = false;
    for (pos, &byte) in text.iter().enumerate().skip(start) {
        if is_blank(byte) {
            after_digit = false;
            continue;
        }
        let exponent = exponent_allowed && byte == EXPONENT && after_digit;
        if !(is_number_byte(byte) || exponent) {
            break;
        }
        after_digit = byte.is_ascii_digit() || byte == DECIMAL_POINT;
        end = pos + 1;
    }
    end
}

/// A number read from its text.
#[derive(Clone, Copy, Debug)]
struct Number {
    value: f64,
    /// A `+` or `-` was written.
    signed: bool,
    decimal_point: bool,
    /// The integer part, saturated (only compared with small limits).
    integer: u64,
    fraction_digits: usize,
    /// The first digit after the decimal point, 0 when there is none.
    first_fraction_digit: u8,
}

impl Number {
    /// Reads `[+|-] digits [. digits]` with blanks anywhere and at least one
    /// digit.
    fn read(text: &[u8]) -> Result<Self, SyntaxErrorKind> {
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

    /// The G or M code form: no sign, at most one digit after the point and
    /// an integer part that fits `u16`.
    fn code(&self) -> Option<Code> {
        if self.signed || self.fraction_digits > 1 {
            return None;
        }
        let major = u16::try_from(self.integer).ok()?;
        Some(Code::new(major, self.first_fraction_digit))
    }

    /// The sequence number form: an unsigned integer that fits `u32`.
    fn sequence(&self) -> Option<u32> {
        if self.signed || self.decimal_point {
            return None;
        }
        u32::try_from(self.integer).ok()
    }
}

/// The state of [`Number::read`]: what was seen so far.
#[derive(Debug, Default)]
struct NumberReader {
    signed: bool,
    negative: bool,
    decimal_point: bool,
    any_digit: bool,
    /// Integer digits counted, leading zeros left out.
    integer_digits: usize,
    fraction_digits: usize,
    /// The integer part, saturated (only compared with small limits).
    integer: u64,
    /// All the digits as one integer, as long as there are at most
    /// [`MAX_DIGITS`] of them.
    mantissa: u64,
    first_fraction_digit: u8,
    too_many_digits: bool,
}

impl NumberReader {
    /// A sign is only valid before everything else.
    fn sign(&mut self, sign: u8) -> Result<(), SyntaxErrorKind> {
        if self.signed || self.any_digit || self.decimal_point {
            return Err(SyntaxErrorKind::BadNumber);
        }
        self.signed = true;
        self.negative = sign == MINUS;
        Ok(())
    }

    fn point(&mut self) -> Result<(), SyntaxErrorKind> {
        if self.decimal_point {
            return Err(SyntaxErrorKind::BadNumber);
        }
        self.decimal_point = true;
        Ok(())
    }

    /// Takes one ASCII digit. Too many digits are only noted, so that a
    /// malformed number is still reported as such.
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
            self.mantissa = self.mantissa * 10 + u64::from(value);
        }
    }

    fn finish(&self) -> Result<Number, SyntaxErrorKind> {
        if !self.any_digit {
            return Err(SyntaxErrorKind::BadNumber);
        }
        if self.too_many_digits {
            return Err(SyntaxErrorKind::TooManyDigits);
        }
        let magnitude = decimal_value(self.mantissa, self.fraction_digits)
            .ok_or(SyntaxErrorKind::TooManyDigits)?;
        Ok(Number {
            value: if self.negative { -magnitude } else { magnitude },
            signed: self.signed,
            decimal_point: self.decimal_point,
            integer: self.integer,
            fraction_digits: self.fraction_digits,
            first_fraction_digit: self.first_fraction_digit,
        })
    }
}

/// `mantissa / 10^decimals`, correctly rounded, hence bit-identical to
/// `str::parse::<f64>` on the same digits: both operands are exact (the
/// mantissa is at most 2^53, the power of ten at most 10^22) and an IEEE
/// division rounds its exact quotient correctly. `None` outside that
/// range, which a number of at most [`MAX_DIGITS`] digits never reaches.
fn decimal_value(mantissa: u64, decimals: usize) -> Option<f64> {
    if mantissa > MAX_EXACT_INTEGER {
        return None;
    }
    let power = EXACT_POWERS_OF_TEN.get(decimals)?;
    // Exact: the mantissa is at most 2^53.
    let mantissa = mantissa as f64;
    Some(mantissa / power)
}

/// The upper-case text of an unknown word, cut at [`UnknownWord::CAPACITY`].
#[derive(Debug, Default)]
struct NameBuffer {
    bytes: [u8; UnknownWord::CAPACITY],
    len: usize,
}

impl NameBuffer {
    fn push(&mut self, byte: u8) {
        if let Some(slot) = self.bytes.get_mut(self.len) {
            *slot = byte.to_ascii_uppercase();
            self.len += 1;
        }
    }

    fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or_default()
    }
}

fn is_macro_keyword(name: &[u8]) -> bool {
    MACRO_KEYWORDS.contains(&name)
}

fn is_blank(byte: u8) -> bool {
    BLANKS.contains(&byte)
}

fn is_number_byte(byte: u8) -> bool {
    byte.is_ascii_digit() || matches!(byte, DECIMAL_POINT | PLUS | MINUS)
}

fn is_identifier(byte: u8) -> bool {
    byte.is_ascii_alphanumeric() || byte == IDENTIFIER_PUNCTUATION
}

fn skip_blanks(text: &[u8], mut pos: usize) -> usize {
    while text.get(pos).is_some_and(|&b| is_blank(b)) {
        pos += 1;
    }
    pos
}

/// The character at `pos` and its length in bytes; an invalid UTF-8 byte is
/// `U+FFFD` one byte long.
fn decode_char(text: &[u8], pos: usize) -> (char, usize) {
    let rest = text.get(pos..).unwrap_or_default();
    let head = rest.get(..MAX_UTF8_LEN).unwrap_or(rest);
    let valid = match std::str::from_utf8(head) {
        Ok(valid) => valid,
        Err(error) => head
            .get(..error.valid_up_to())
            .and_then(|bytes| std::str::from_utf8(bytes).ok())
            .unwrap_or_default(),
    };
    valid
        .chars()
        .next()
        .map_or((char::REPLACEMENT_CHARACTER, 1), |c| (c, c.len_utf8()))
}

/// The span of bytes `start..end` (0-based, end exclusive) in columns.
fn span(start: usize, end: usize) -> Span {
    Span::new(column(start), column(end))
}

/// The 1-based column of the byte at 0-based `index`, saturated.
fn column(index: usize) -> u32 {
    u32::try_from(index).unwrap_or(u32::MAX).saturating_add(1)
}

#[cfg(test)]
mod equivalence;
#[cfg(test)]
mod tests;
