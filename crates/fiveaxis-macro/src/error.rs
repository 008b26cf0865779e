//! Macro alarms: what went wrong, where, and the FANUC alarm number.
//!
//! The numbers are those of the FANUC Series 30i/31i/32i PS alarm list
//! (PS0xxx). They were checked against a public transcription of that list
//! (the `RuntimeAlarm` classes of a FANUC Macro B interpreter written in
//! TypeScript, "generated 2025-01-14", found with the code search tool):
//! 0003 TOO MANY DIGIT, 0111 OVERFLOW :FLOATING, 0112 ZERO DIVIDE,
//! 0114 ILLEGAL EXPRESSION FORMAT, 0115 VARIABLE NO. OUT OF RANGE,
//! 0116 WRITE PROTECTED VARIABLE, 0118 TOO MANY BRACKET NESTING (five levels
//! including function brackets), 0119 ARGUMENT VALUE OUT OF RANGE,
//! 0122 TOO MANY MACRO NESTING, 0124 MISSING END STATEMENT,
//! 0125 MACRO STATEMENT FORMAT ERROR, 0126 ILLEGAL LOOP NUMBER (1 to 3),
//! 0127 DUPLICATE NC,MACRO STATEMENT, 0128 ILLEGAL MACRO SEQUENCE NUMBER,
//! 0129 USE 'G' AS ARGUMENT (on the 16i the same number is named ILLEGAL
//! ARGUMENT ADDRESS; that 16i name is from memory, unconfirmed).
//! The bracket depth of five and alarm 118 also appear in the Series
//! 16/18 Model C operator's manual (custom macro chapter, "bracket nesting").

use fiveaxis_gcode::Span;

/// What kind of macro alarm occurred. One variant per FANUC condition;
/// [`MacroErrorKind::fanuc_number`] gives its number.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MacroErrorKind {
    /// A number with more digits than the control reads (PS0003).
    TooManyDigits,
    /// An expression, word or line that cannot be read (PS0114).
    FormatError,
    /// A macro statement (`IF`, `WHILE`, `GOTO`, …) of the wrong shape (PS0125).
    StatementFormat,
    /// A variable number that does not exist (PS0115).
    UndefinedVariable,
    /// A write to a variable that can only be read, `#0` included (PS0116).
    WriteProtected,
    /// Division (or `MOD`) by zero (PS0112).
    DivisionByZero,
    /// A function argument outside its domain: `SQRT` or `LN` of a negative
    /// number, `ASIN`/`ACOS` outside \[-1, 1\], `BCD` of a negative number …
    /// (PS0119).
    ArgumentOutOfRange,
    /// A result too large for the control (not finite) (PS0111).
    Overflow,
    /// Brackets nested deeper than five levels (PS0118).
    BracketNesting,
    /// Macro calls nested deeper than the control allows (PS0122).
    CallNesting,
    /// A `DO`/`END` number other than 1, 2 or 3 (PS0126).
    IllegalLoopNumber,
    /// A `DO` without its `END` (PS0124). Raised by the runner.
    MissingEnd,
    /// An NC statement and a macro statement in the same block (PS0127).
    NcAndMacro,
    /// A `GOTO` target that is not a sequence number 1 … 99999 (PS0128).
    IllegalSequenceNumber,
    /// An address that cannot be a macro call argument (PS0129).
    IllegalArgumentAddress,
    /// The alarm a program raised itself by writing `#3000` (16i: alarm
    /// 3000 + n); the number is the value written.
    CustomAlarm(u32),
}

impl MacroErrorKind {
    /// The FANUC alarm number: the PS number of the Series 30i (the same
    /// number on the 16i/18i P/S list), or 3000 + n for a `#3000 = n`
    /// alarm (the 16i convention; the 30i shows it as an MC alarm).
    pub fn fanuc_number(self) -> u16 {
        match self {
            Self::TooManyDigits => 3,
            Self::Overflow => 111,
            Self::DivisionByZero => 112,
            Self::FormatError => 114,
            Self::UndefinedVariable => 115,
            Self::WriteProtected => 116,
            Self::BracketNesting => 118,
            Self::ArgumentOutOfRange => 119,
            Self::CallNesting => 122,
            Self::MissingEnd => 124,
            Self::StatementFormat => 125,
            Self::IllegalLoopNumber => 126,
            Self::NcAndMacro => 127,
            Self::IllegalSequenceNumber => 128,
            Self::IllegalArgumentAddress => 129,
            Self::CustomAlarm(n) => u16::try_from(n).map_or(u16::MAX, |n| n.saturating_add(3000)),
        }
    }
}

/// A macro alarm: its kind, the columns of the offending text in its line
/// and a short message naming the thing.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct MacroError {
    /// What went wrong.
    pub kind: MacroErrorKind,
    /// Where, in the line (1-based byte columns, end exclusive).
    pub span: Span,
    /// Plain English, naming the variable, function or text at fault.
    pub message: String,
}

impl MacroError {
    /// An alarm of `kind` at `span` with `message`.
    pub fn new(kind: MacroErrorKind, span: Span, message: impl Into<String>) -> Self {
        Self {
            kind,
            span,
            message: message.into(),
        }
    }

    /// The FANUC alarm number of the kind.
    pub fn fanuc_number(&self) -> u16 {
        self.kind.fanuc_number()
    }
}
