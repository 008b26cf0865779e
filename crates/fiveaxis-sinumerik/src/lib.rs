//! The SINUMERIK (840D sl / 828D) part program language: one line of
//! program text into a spanned syntax tree, and an interpreter that runs
//! the language.
//!
//! A front end of its own, not a FANUC dialect: [`parse_line`] reads a
//! line into a [`Line`] (skip level, block number, label, [`Statement`],
//! comment) or a [`ParseError`] with the columns of the offending text and
//! the alarm the control gives ([`ParseErrorKind::alarm`]). Nothing is
//! evaluated by the reader: no variables, no machine, no I/O.
//!
//! The [`Interpreter`] runs a program streamed through [`ProgramText`]
//! (variables, expressions, control structures, jumps, subprograms from
//! a [`ProgramStore`], macros) and yields the blocks that reach the
//! control as [`Executed`] blocks, every value evaluated; the control's
//! data comes through [`System`]. Its design and the decisions taken where
//! the manuals are silent are in the documentation of the [`interp`]
//! module.
//!
//! ```
//! use std::collections::HashMap;
//! use fiveaxis_sinumerik::{
//!     Action, Executed, Interpreter, Options, ProgramStore, ProgramText, Step, System,
//!     TextProgram, Value,
//! };
//!
//! struct Store;
//! impl ProgramStore for Store {
//!     fn open(&mut self, name: &str) -> std::io::Result<Option<Box<dyn ProgramText>>> {
//!         Ok((name == "LIFT").then(|| {
//!             Box::new(TextProgram::new("PROC LIFT(REAL H)\nG0 Z=H\nRET\n")) as Box<dyn ProgramText>
//!         }))
//!     }
//! }
//! struct Control(HashMap<String, Value>);
//! impl System for Control {
//!     fn read(&mut self, name: &str, _: &[Value]) -> Result<Value, String> {
//!         self.0.get(name).cloned().ok_or_else(|| "unknown".to_string())
//!     }
//!     fn write(&mut self, name: &str, _: &[Value], v: Value) -> Result<(), String> {
//!         self.0.insert(name.to_string(), v);
//!         Ok(())
//!     }
//!     fn is_axis(&self, name: &str) -> bool {
//!         matches!(name, "X" | "Y" | "Z")
//!     }
//!     fn is_builtin(&self, _: &str) -> bool {
//!         false
//!     }
//! }
//!
//! let main = "R1=2\nWHILE R1>0\nG1 X=R1*10\nR1=R1-1\nENDWHILE\nLIFT(50)\nM30\n";
//! let mut interp = Interpreter::new(
//!     Box::new(TextProgram::new(main)),
//!     Box::new(Store),
//!     Options::default(),
//! )?;
//! let mut control = Control(HashMap::new());
//! let mut block = Executed::default();
//! let mut words = Vec::new();
//! while interp.next_block(&mut control, &mut block)? == Step::Block {
//!     for action in &block.actions {
//!         if let Action::Word { address, value, .. } = action {
//!             words.push(format!("{address}{}", value.as_f64().unwrap_or(0.0)));
//!         }
//!     }
//! }
//! assert_eq!(words, ["G1", "X20", "G1", "X10", "G0", "Z50", "M30"]);
//! # Ok::<(), fiveaxis_sinumerik::LangError>(())
//! ```
//!
//! ```
//! use fiveaxis_sinumerik::{Item, Statement, parse_line};
//!
//! let line = parse_line(b"N40 G1 X=R1*2+5 CR=10 ; arc", 40)?;
//! assert_eq!(line.number.map(|n| n.value), Some(40));
//! let Statement::Block(items) = &line.statement else { unreachable!() };
//! let Item::Word(g) = &items[0] else { unreachable!() };
//! assert_eq!((g.address.as_str(), g.number()), ("G", Some(1.0)));
//! assert_eq!(line.comment.map(|c| c.text), Some(" arc".to_string()));
//! # Ok::<(), fiveaxis_sinumerik::ParseError>(())
//! ```
//!
//! The code is pure: no panics whatever the bytes, no unbounded recursion
//! (nesting is bounded by [`MAX_DEPTH`], binary operations per line by
//! [`MAX_OPERATIONS`]; past them an error, never a stack overflow).
//!
//! # What is read
//!
//! Sources are cited with the keys of the design brief
//! (`sinumerik-heidenhain-brief.md`, section 0): ONE = SINUMERIK ONE NC
//! Programming Manual 12/2019; 840Di = 840Di Programming Fundamentals
//! 11/2006; 828JP = 828D Job Planning 07/2010; AV11 = 840D sl
//! Arbeitsvorbereitung 02/2011.
//!
//! * **Block** `[/n] [N<int> | :<int>] [label:] … [; comment]` (ONE
//!   p43–45; skip levels `/0` … `/9` as the brief has them, not confirmed
//!   in a manual). A `%…` line is a [`Statement::ProgramHeader`]; a line
//!   that is only `;$PATH=…` a [`Statement::PathHeader`].
//! * **Words** (840Di p62–63): one address letter and a number need no `=`
//!   (`X10`, `X-.5`, `G642`; runs like `G53G0X0M5` are split); an address
//!   with an extension or of several letters, and any value that is not a
//!   number, take `=` (`A3=0`, `CR=10`, `X=R1*2+5`, `T="DRILL"`). A value
//!   may be wrapped in `AC IC DC ACP ACN` ([`PositionMode`]). Numbers
//!   take the exponent `EX` (`-.1EX-3`); `'H…'` and `'B…'` constants are
//!   hexadecimal and binary.
//! * **Variables**: R parameters (`R1`, `R[R2]`), user variables, system
//!   variables (`$AA_IW[X]`, `$TC_DP3[1,1]`), each with indices
//!   ([`Var`]). `name=` is an [`Item::Word`] when the name is an address
//!   (a letter with or without digits other than `R`, or a multi-letter
//!   address such as `CR`, `TURN`), an [`Item::Assign`] otherwise.
//! * **Expressions** with the precedence of ONE p444 / 828JP p72, from the
//!   tightest: `NOT B_NOT` and signs; `* / DIV MOD`; `+ -`; `B_AND`;
//!   `B_XOR`; `B_OR`; `AND`; `XOR`; `OR`; `<<`; the comparisons
//!   `== <> > < >= <=` last ([`BinOp::precedence`]); the frame chain `:`
//!   below them all, as it mixes with none. Functions and their
//!   arguments by name (`SIN(30)`, `ATAN2(1,2)`, `CTRANS(X,10)`), left to
//!   the evaluator.
//! * **Statements**: `DEF` (ONE; 840Di p62–63), `DEFINE … AS`, `PROC` with
//!   `VAR` parameters and attributes, `IF`/`ELSE`/`ENDIF`, `IF … GOTOF`,
//!   `WHILE`, `FOR … TO`, `REPEAT`/`UNTIL`, `LOOP`, `CASE … OF … DEFAULT`,
//!   the jumps `GOTOF GOTOB GOTO GOTOC GOTOS` (AV11 p107); calls by name
//!   with arguments, empty ones kept (`CYCLE81(5,,3)`, ONE p494), `L100
//!   P3`, `CALL "NAME"`, `CALL BLOCK A TO B`, `MCALL`; named instructions
//!   (`TRAORI`, `AROT`, `SUPA`, `STOPRE`, `MSG(…)` …) are [`Call`]s whose
//!   [`CallKind`] says what the name is; the words that follow them in the
//!   block (`TRANS X10`, `AROT RPL=30`) are the block's next items.
//! * **Synchronized actions** `ID=n WHENEVER … DO …` into a
//!   [`SyncAction`], read and not executed.
//!
//! # Decisions where the manuals were not found or are silent
//!
//! * Keywords win over names: `IF`, `GOTOF`, `DEF` … cannot be labels,
//!   variables or calls. A keyword that opens a statement must begin its
//!   block.
//! * A name made of a letter and digits is one name (`R1`, `X1`, `L1`)
//!   inside an expression, a declaration, a jump target, and before `=`,
//!   `(`, `[` or `:`; elsewhere it is an address and its number.
//! * `L` with digits is a subprogram call (`L100`); a `P` word right after
//!   a call is its number of passes.
//! * A name alone that is neither keyword nor address letter is a call
//!   (a user cycle such as `RLIMIT`), a name followed by `(` a call with
//!   arguments (`M202(0.0059)` too).
//! * `name[…]=` is an assignment whatever the name (`POS[X]=10` included):
//!   which names are addresses with an axis index is left to the
//!   interpreter.
//! * A sign before a number is folded into it (`-5` is the number -5).
//! * Names are kept as written, upper-cased: `R01` stays `R01` (the same
//!   parameter as `R1`, 840Di p62, for the interpreter to fold). Any name
//!   that is not a keyword, followed by `:` at the start of a block, is a
//!   label; the rule of two leading letters is the interpreter's to check.
//! * Line ends (`\r`, `\n`) at the end of `text` are dropped; a `%` line
//!   is a header whatever follows the `%`.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod error;
mod exec;
pub mod interp;
mod lex;
mod names;
mod parse;
mod tree;

pub use error::{ParseError, ParseErrorKind};
pub use exec::{
    Action, Executed, FrameAxis, FrameValue, LangError, ProgramStore, ProgramText, Step, System,
    Value,
};
pub use fiveaxis_gcode::Span;
pub use interp::{
    Interpreter, MAX_LEVELS, MAX_NOTES, MAX_PASSES, Options, REAL_TOLERANCE, TextProgram,
    format_real,
};
pub use parse::{MAX_DEPTH, MAX_OPERATIONS, parse_line};
pub use tree::{
    Assign, BinOp, BlockNumber, Call, CallKind, Comment, Declarator, Def, Expr, ExprKind,
    IndirectCall, Init, Item, Jump, JumpKind, JumpTarget, Line, Name, Param, PositionMode, Proc,
    Skip, Statement, SyncAction, SyncWhen, Type, UnOp, Var, Word,
};
