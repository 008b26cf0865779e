//! HEIDENHAIN TNC conversational programming (Klartext): the language
//! the TNC 640 / TNC 620 / iTNC 530 / TNC7 read, without machines.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod exec;

pub use exec::{
    Executed, Key, Kind, LangError, LangErrorKind, PatternItem, ProgramStore, ProgramText, Step,
    System, Tool, Value, Word,
};
pub use fiveaxis_gcode::Span;
