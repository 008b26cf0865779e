//! HEIDENHAIN TNC conversational programming (Klartext): the language
//! the TNC 640 / TNC 620 / iTNC 530 / TNC7 read, without machines.
//!
//! [`parse_block`] reads one block; [`Interpreter`] runs a program
//! (Q parameters, formulas, `FN` functions, labels, calls) and yields
//! each block that reaches the control as an [`Executed`] block.
//!
//! What the language covers here:
//!
//! * the program frame (`BEGIN PGM … MM|INCH`, `END PGM`), block
//!   numbers, `;` comments, `~` continuation lines, `*` headings, `/`
//!   block skip (before or after the block number);
//! * the blocks of [`Kind`]: paths (`L`, `LN`, `CC`, `C`, `CR`, `CT`,
//!   `LP`, `CP`, `CTP`, `RND`, `CHF`, `APPR`, `DEP`), `TOOL CALL` /
//!   `TOOL DEF`, `BLK FORM`, `CYCL DEF` with its `Q` parameters,
//!   `CYCL CALL`, `PATTERN DEF`, `PLANE`, `FUNCTION TCPM` /
//!   `FUNCTION RESET TCPM`, `STOP` and blocks of M functions;
//! * `Q` / `QL` / `QR` formulas (`+ - * / % ^`, `SIN COS TAN ASIN ACOS
//!   ATAN SQ SQRT PI LN LOG EXP NEG INT ABS FRAC SGN`), `QS` string
//!   formulas (`||`, `TOCHAR`, `SUBSTR`, `TONUMB`, `STRLEN`,
//!   `DECLARE STRING`);
//! * `FN 0` – `FN 16` and `FN 18` (`FN 17` and `FN 19` onwards are not
//!   supported);
//! * `LBL`, `CALL LBL n` (subprogram), `CALL LBL n REP k` (section
//!   repeat), `CALL PGM`, `M2` / `M30`.
//!
//! Not covered: FK free contours, `SEL PGM` / `CALL SELECTED PGM`,
//! `FUNCTION` forms other than `TCPM`, `INSTR` / `STRCOMP` / `SYSSTR` /
//! `CFGREAD`, Q parameters as labels (`LBL QS1`).
//!
//! ```
//! use fiveaxis_heidenhain::{
//!     Executed, Interpreter, Kind, NoPrograms, NoSystem, Options, Step, TextProgram,
//! };
//!
//! let text = "0 BEGIN PGM P MM\n1 Q1 = 5 * 2\n2 L X+Q1 R0 FMAX\n3 END PGM P MM\n";
//! let mut i = Interpreter::new(
//!     Box::new(TextProgram::new(text)),
//!     Box::new(NoPrograms),
//!     Options::default(),
//! )?;
//! let mut b = Executed::default();
//! assert_eq!(i.next_block(&mut NoSystem, &mut b)?, Step::Block);
//! assert_eq!(b.kind, Kind::Line);
//! assert_eq!(b.word("X").map(|w| w.value), Some(10.0));
//! assert_eq!(i.next_block(&mut NoSystem, &mut b)?, Step::End);
//! # Ok::<(), fiveaxis_heidenhain::LangError>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod exec;
mod interp;
mod parse;

pub use exec::{
    Executed, Key, Kind, LangError, LangErrorKind, PatternItem, ProgramStore, ProgramText, Step,
    System, Tool, Value, Word,
};
pub use fiveaxis_gcode::Span;
pub use interp::{
    Interpreter, MAX_NESTING, MAX_NOTES, MemoryStore, NoPrograms, NoSystem, Options, TextProgram,
    format_number,
};
pub use parse::{
    Block, Body, Compare, FnOp, Func, Item, Label, Name, Node, Op, Operand, Param, ParseError,
    PatternDefItem, Q_MAX, QKind, QL_MAX, QRef, QS_MAX, ToolRef, parse, parse_block, split_comment,
};
