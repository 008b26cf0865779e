//! Reading errors: what went wrong, where, and the SINUMERIK alarm.

use fiveaxis_gcode::Span;

/// What kind of reading error occurred.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ParseErrorKind {
    /// Text the language does not allow: a missing value, an unknown
    /// character, an unclosed string or bracket, a keyword out of place.
    /// The control stops with alarm 12080 (syntax error; the number is
    /// from the design brief's alarm table, marked there as unverified
    /// against a Siemens diagnostics manual).
    Syntax,
    /// Brackets, function calls, indices and unary operators nested deeper
    /// than [`crate::MAX_DEPTH`]: a bound of this reader, not of the control.
    TooDeep,
    /// More than [`crate::MAX_OPERATIONS`] binary operations in one line: a
    /// bound of this reader, not of the control.
    TooManyOperations,
}

impl ParseErrorKind {
    /// The SINUMERIK alarm the control raises for the error, when one is
    /// known: 12080 for a syntax error. The reader's own bounds have none.
    pub fn alarm(self) -> Option<u32> {
        match self {
            Self::Syntax => Some(12080),
            Self::TooDeep | Self::TooManyOperations => None,
        }
    }
}

/// A reading error: its kind, the columns of the offending text and a
/// short message naming it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, columns {}–{}: {message}", span.start, span.end)]
pub struct ParseError {
    /// What went wrong.
    pub kind: ParseErrorKind,
    /// The line number given to [`crate::parse_line`].
    pub line: u32,
    /// Where, in the line (1-based byte columns, end exclusive).
    pub span: Span,
    /// Plain English, naming the text at fault.
    pub message: String,
}

impl ParseError {
    /// The SINUMERIK alarm number of the kind, when one is known.
    pub fn alarm(&self) -> Option<u32> {
        self.kind.alarm()
    }
}
