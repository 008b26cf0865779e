//! The G-code front end: bytes of one program line in, one [`Block`] of
//! [`Word`]s out.
//!
//! It knows nothing of machines, modes or controls: it only reads the FANUC
//! tape format (ISO 6983 words with FANUC's conventions) and reports what it
//! cannot read as a [`SyntaxError`] with the exact columns. It never panics,
//! whatever the bytes, and it does not allocate once the block's word buffer
//! has grown to the longest block seen.
//!
//! What it reads:
//!
//! * `%` tape marks (a line holding only `%`), `O` program numbers, `N`
//!   sequence numbers;
//! * `( … )` comments, `;` as end of block (the rest of the line is ignored);
//! * `/` block delete at the start of a block (reported, not acted upon);
//! * spaces and tabs anywhere between and inside words (`G 1 X 1 0 . 5`);
//! * numbers with or without a decimal point, signs, decimal G and M codes
//!   (`G43.4`, `G54.1`). Whether a number had a decimal point is kept: the
//!   controller needs it for FANUC's least-input-increment rule.
//!
//! What it refuses with a clear [`SyntaxErrorKind`]: custom macro syntax
//! (`#`, `[`, `]`, `IF`, `WHILE`, `GOTO`, …), letters without a number,
//! malformed numbers, unclosed comments, bytes that are not G-code.
//!
//! # Reading rules in detail
//!
//! * One line is one block. The first `;` ends it wherever it stands, inside
//!   a comment too (so `(A;B)` is an unclosed comment); trailing `\r` and
//!   `\n` are removed.
//! * A line whose first non-blank byte is `%` is a tape mark; the rest of the
//!   line is ignored.
//! * `/` as the first non-blank byte is block delete, optionally followed by
//!   a skip number `1` … `9` that is read and dropped (`/0` and `/12` leave a
//!   stray digit). A `/` anywhere else is an unexpected character.
//! * Comments run from `(` to the first `)`; a `(` inside is plain text. A
//!   comment ends the word before it: `X1(C)0` is `X1` then a stray `0`.
//!   A control's dialect may read them otherwise ([`Syntax`],
//!   [`parse_line_as`]): Haas counts nested parentheses, so `(A (B))` is
//!   one comment.
//! * Letters are case-insensitive; blanks (space, tab) may stand anywhere in
//!   a word, so `G 1` is `G1` and `X1 .5` is `X1.5`.
//! * Numbers are `[+|-] digits [. digits]` with at least one digit and at
//!   most [`MAX_DIGITS`] digits, not counting zeros in front of the integer
//!   part. A lower-case `e` written right after a digit or point is an
//!   exponent and refused (`G1e5`); an upper-case `E` is always the `E`
//!   address (`G1E5` is `G1 E5`).
//! * `N` sets [`Block::sequence`] (an unsigned integer that fits `u32`; a
//!   second `N` in the block is an error); `O` is an ordinary word.
//! * A letter followed by another letter (blanks between them ignored) starts
//!   a word of several letters. It is custom macro syntax when its letters
//!   are a macro keyword (`IF`, `WHILE`, `GOTO`, `DO`, `END`, functions, …)
//!   and an [`UnknownWord`] otherwise (`TRAORI`, `CYCLE800`, the `SUB` of
//!   `o100 sub`). Blanks end such a word, except after a lone letter:
//!   `G O T O` is `GOTO`, `X Y1` is `XY1`, `TRAORI X1` is `TRAORI`.
//! * A line holding `#`, `[` or `]` outside comments is custom macro syntax:
//!   whatever error is found first in it is reported as
//!   [`SyntaxErrorKind::Macro`] at the first of these characters (or at a
//!   keyword met before it).
//! * Columns are 1-based byte columns, end exclusive; the first error of the
//!   line is reported and the block is then left empty.

mod lexer;
mod program_text;

pub use lexer::{MAX_DIGITS, parse_line, parse_line_as};
pub use program_text::{ProgramText, TextProgram};

/// The reading rules in which controls differ, as data: the front end's
/// dialect. [`Syntax::FANUC`] is what [`parse_line`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Syntax {
    /// A `(` inside a comment opens a nested level, closed by its own `)`;
    /// the comment ends at the `)` that balances the first `(` (Haas: the
    /// NX post writes `(#508= (MILL_.25_PROFILE ))`). Off (FANUC): a `(`
    /// inside a comment is text and the first `)` ends it.
    pub nested_comments: bool,
    /// `;` ends the block (starts a comment to the end of the line) only
    /// outside parentheses; inside a `( … )` comment it is text (LinuxCNC,
    /// overview.adoc "Comments"; Haas, whose G47 engraves `;` from a
    /// comment: NGC mill operator's manual, "Literal Text Engraving").
    /// Off (FANUC): the first `;` ends the block wherever it stands.
    pub semicolon_outside_comments: bool,
    /// A lower-case `e` right after the digits of a number is the next
    /// word's letter (LinuxCNC: `m66e0l0` is `M66 E0 L0`, words are
    /// case-insensitive and numbers have no exponent). Off (FANUC): it is
    /// taken for a floating-point exponent and refused as a malformed
    /// number.
    pub e_after_digits_is_a_word: bool,
}

impl Syntax {
    /// FANUC tape format (also Mitsubishi and Mazak EIA/ISO).
    pub const FANUC: Self = Self {
        nested_comments: false,
        semicolon_outside_comments: false,
        e_after_digits_is_a_word: false,
    };
    /// The Haas control.
    pub const HAAS: Self = Self {
        nested_comments: true,
        semicolon_outside_comments: true,
        e_after_digits_is_a_word: false,
    };
    /// LinuxCNC's RS274/NGC for plain lines (the runner sends lines with
    /// parameters, expressions and o-words to `fiveaxis-macro`'s NGC
    /// reader).
    pub const LINUXCNC: Self = Self {
        nested_comments: false,
        semicolon_outside_comments: true,
        e_after_digits_is_a_word: true,
    };
}

/// Columns of a piece of text inside its line: 1-based, `end` exclusive,
/// counted in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Span {
    /// First column (1-based).
    pub start: u32,
    /// One past the last column.
    pub end: u32,
}

impl Span {
    /// A span from its two columns: `Span::new(4, 9)`.
    pub const fn new(start: u32, end: u32) -> Self {
        Self { start, end }
    }
}

/// A G or M code number split at its decimal point: `G43.4` is
/// `Code { major: 43, minor: 4 }`, `G1` and `G01` are `Code { major: 1, minor: 0 }`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Code {
    /// Digits before the decimal point.
    pub major: u16,
    /// The one digit after the decimal point, 0 when there is none.
    pub minor: u8,
}

impl Code {
    /// A code from its two parts, for matching: `Code::new(43, 4)`.
    pub const fn new(major: u16, minor: u8) -> Self {
        Self { major, minor }
    }
}

impl std::fmt::Display for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.minor == 0 {
            write!(f, "{}", self.major)
        } else {
            write!(f, "{}.{}", self.major, self.minor)
        }
    }
}

/// One address word: a letter and its number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Word {
    /// The address letter, upper case (`b'A'..=b'Z'`).
    pub letter: u8,
    /// The number as written, sign included (`X-1.5` is -1.5, `X100` is 100).
    pub value: f64,
    /// Whether the number was written with a decimal point (`X100.` yes,
    /// `X100` no).
    pub decimal_point: bool,
    /// The code form of the number when it has at most one digit after the
    /// decimal point and no sign (`G43.4`, `M98`); `None` otherwise.
    pub code: Option<Code>,
    /// The value was computed (a macro variable or expression, `P#1`,
    /// `H[#2+1]`), not written on the tape: the rule of the decimal point
    /// does not apply to it, and an address that takes an integer takes it
    /// rounded (FANUC: a variable's value is rounded to the address's
    /// least increment).
    pub computed: bool,
    /// Where the word stands in its line.
    pub span: Span,
}

/// One block (one line) of a program.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Block {
    /// 1-based line number in the program.
    pub line: u32,
    /// The block starts with `/` (block delete). The caller decides whether
    /// to skip it.
    pub block_delete: bool,
    /// The line is a `%` tape mark.
    pub tape_mark: bool,
    /// The words in the order written, comments and the sequence number
    /// (`N`) left out.
    pub words: Vec<Word>,
    /// The `N` sequence number, if any.
    pub sequence: Option<u32>,
    /// The text of the line's first comment, without its parentheses (Haas
    /// G47 engraves it). The buffer is kept from line to line.
    pub comment: Vec<u8>,
    /// The columns of that comment, parentheses included; `None` when the
    /// line has no comment.
    pub comment_span: Option<Span>,
}

impl Block {
    /// Empties the block so that it can be reused for the next line
    /// without giving back its word buffer.
    pub fn clear(&mut self) {
        self.line = 0;
        self.block_delete = false;
        self.tape_mark = false;
        self.words.clear();
        self.sequence = None;
        self.comment.clear();
        self.comment_span = None;
    }

    /// The first word with this letter.
    pub fn word(&self, letter: u8) -> Option<&Word> {
        self.words.iter().find(|w| w.letter == letter)
    }

    /// Whether the block holds no words (blank line, comment only, `%`).
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }
}

/// What kind of text the front end could not read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SyntaxErrorKind {
    /// An address letter with no number after it (`X`, `G`).
    #[error("address `{0}` has no value")]
    MissingValue(char),
    /// A number that cannot be read (`X1.2.3`, `X--1`, `G1e5`).
    #[error("malformed number")]
    BadNumber,
    /// A number with more digits than the control accepts.
    #[error("too many digits")]
    TooManyDigits,
    /// A character that is neither an address, a digit nor G-code
    /// punctuation (shown escaped when it does not print).
    #[error("unexpected character `{}`", .0.escape_debug())]
    UnexpectedChar(char),
    /// A byte that is not part of any UTF-8 text (a binary file, another
    /// encoding).
    #[error("byte 0x{0:02x} is not text (the program must be ASCII or UTF-8)")]
    InvalidByte(u8),
    /// `(` without its `)` on the same line.
    #[error("comment is not closed")]
    UnclosedComment,
    /// Custom macro syntax: `#` variables, `[ ]` expressions, `IF`,
    /// `WHILE`, `GOTO`, `DO`, `END` and functions.
    #[error("custom macro syntax is not supported")]
    Macro,
    /// A word with several letters that is not G-code (Siemens `TRAORI`,
    /// LinuxCNC `o100 sub`, …).
    /// When it looks like a letter O typed for the digit 0 (`G1O X10.`,
    /// `GO1`), the message says so.
    #[error("unknown word `{0}`{hint}", hint = .0.hint())]
    UnknownWord(UnknownWord),
    /// A second `N` sequence number in the same block.
    #[error("more than one sequence number in the block")]
    DuplicateSequence,
}

/// Up to the first 12 bytes of an unrecognised word, for the message, and
/// the digit 0 it may have been meant to hold.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct UnknownWord {
    bytes: [u8; Self::CAPACITY],
    len: u8,
    letter_o: Option<LetterO>,
}

/// A letter O that stands where the digit 0 would make a word: right
/// after a word's number (`G1O` for `G10`, `M3O` for `M30`) or right after
/// an address letter (`GO1` for `G01`).
#[derive(Clone, Copy, PartialEq, Eq)]
struct LetterO {
    /// The O follows the word `quoted` (else it stands inside it).
    after: bool,
    /// The word the O follows, or the word it stands in.
    quoted: Short,
    /// The word with the digit 0 in the O's place.
    meant: Short,
}

/// A few bytes of ASCII text, kept without allocating.
#[derive(Clone, Copy, PartialEq, Eq, Default)]
struct Short {
    bytes: [u8; Short::CAPACITY],
    len: u8,
}

impl Short {
    const CAPACITY: usize = UnknownWord::CAPACITY + 1;

    /// `parts` one after the other, upper case; `None` when they do not
    /// fit.
    fn of(parts: &[&[u8]]) -> Option<Self> {
        let mut short = Self::default();
        for &byte in parts.iter().flat_map(|p| p.iter()) {
            let slot = short.bytes.get_mut(usize::from(short.len))?;
            *slot = byte.to_ascii_uppercase();
            short.len += 1;
        }
        Some(short)
    }

    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or("?")
    }
}

/// The hint of an [`UnknownWord`]'s message: nothing, or what a letter O
/// may have been meant to be.
#[derive(Clone, Copy, Debug)]
pub struct Hint<'a>(Option<&'a LetterO>);

impl std::fmt::Display for Hint<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Some(o) = self.0 else { return Ok(()) };
        let place = if o.after { "after" } else { "in" };
        write!(
            f,
            ": `O` {place} `{}` is the letter O; did you mean the digit 0 (`{}`)?",
            o.quoted.as_str(),
            o.meant.as_str()
        )
    }
}

impl std::fmt::Debug for LetterO {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:?} for {:?}",
            self.quoted.as_str(),
            self.meant.as_str()
        )
    }
}

impl UnknownWord {
    /// How many bytes of the word are kept.
    pub const CAPACITY: usize = 12;

    /// Keeps the first 12 bytes of `text` (ASCII expected; other bytes are
    /// shown as `?`).
    pub fn new(text: &[u8]) -> Self {
        let mut bytes = [0u8; Self::CAPACITY];
        let len = text.len().min(Self::CAPACITY);
        for (dst, &src) in bytes.iter_mut().zip(&text[..len]) {
            *dst = if src.is_ascii_graphic() { src } else { b'?' };
        }
        Self {
            bytes,
            len: len as u8,
            letter_o: None,
        }
    }

    /// The word `text` (its first 12 bytes), which would be a word with
    /// the digit 0 where it has a letter O: after the word `before`
    /// (`G1` + `OX10`: `G10`), or, without `before`, as its second letter
    /// (`GO1`: `G01`).
    pub fn with_letter_o(text: &[u8], before: Option<&[u8]>) -> Self {
        let mut word = Self::new(text);
        word.letter_o = match before {
            Some(before) => {
                Short::of(&[before])
                    .zip(Short::of(&[before, b"0"]))
                    .map(|(quoted, meant)| LetterO {
                        after: true,
                        quoted,
                        meant,
                    })
            }
            None => {
                let (first, rest) = (text.get(..1), text.get(2..));
                first.zip(rest).and_then(|(first, rest)| {
                    Some(LetterO {
                        after: false,
                        quoted: Short::of(&[word.as_str().as_bytes()])?,
                        meant: Short::of(&[first, b"0", rest])?,
                    })
                })
            }
        };
        word
    }

    /// The hint its message carries (empty when there is none).
    pub fn hint(&self) -> Hint<'_> {
        Hint(self.letter_o.as_ref())
    }

    /// The kept text.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or("?")
    }
}

impl std::fmt::Display for UnknownWord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::fmt::Debug for UnknownWord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

/// Text the front end could not read, with where it stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{kind}")]
pub struct SyntaxError {
    /// What is wrong.
    pub kind: SyntaxErrorKind,
    /// Where, in the line.
    pub span: Span,
}

impl SyntaxError {
    /// An error of `kind` at `span`.
    pub const fn new(kind: SyntaxErrorKind, span: Span) -> Self {
        Self { kind, span }
    }
}
