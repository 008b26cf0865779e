//! FANUC Custom Macro B: the layer between the G-code front end
//! (`fiveaxis-gcode`) and the controller.
//!
//! The runner (owned by the controller) reads lines, jumps, loops and calls
//! programs; this crate gives it everything else:
//!
//! * [`parse_statement`]: one line into a [`Line`] holding a
//!   [`Statement`]: an assignment, `GOTO`, `IF … GOTO`, `IF … THEN`,
//!   `WHILE … DO`, `DO`, `END`, or an NC block whose values may be
//!   variables and expressions ([`NcBlock`]);
//! * [`Variables`]: the variable store (local variables per call level,
//!   common variables, the kept `#500` … `#999`) with expression
//!   evaluation ([`Variables::eval`]) and assignment; system variables
//!   (`#1000` and up) go to the controller through [`SystemVariables`];
//! * [`evaluate_block`]: an [`NcBlock`] into a `fiveaxis_gcode::Block`;
//! * [`arguments`]: the local variables of a `G65`/`G66` call;
//! * [`is_macro_line`], [`loop_start`], [`loop_end`]: cheap byte scans so
//!   the runner keeps its fast path for plain lines and can skip loops;
//! * [`MacroError`]: every macro alarm, with its FANUC number
//!   ([`MacroErrorKind::fanuc_number`]), the columns of the offending text
//!   and a short message.
//!
//! ```
//! use fiveaxis_gcode::Block;
//! use fiveaxis_macro::{
//!     MacroSettings, NoSystemVariables, Statement, Variables, evaluate_block, parse_statement,
//! };
//!
//! let settings = MacroSettings::default();
//! let mut sys = NoSystemVariables;
//! let mut vars = Variables::new(4);
//! let line = parse_statement(b"#24 = 10 * COS[60]", 1)?;
//! if let Statement::Assign { target, value } = &line.statement {
//!     vars.assign(target, value, line.comment.as_deref(), &mut sys, &settings)?;
//! }
//! let line = parse_statement(b"G01 X#24 Y#25 F100.", 2)?;
//! let mut block = Block::default();
//! if let Statement::Nc(nc) = &line.statement {
//!     evaluate_block(nc, &vars, &sys, &settings, &mut block)?;
//! }
//! // Y#25 is vacant: the word is left out.
//! assert_eq!(block.words.len(), 3);
//! assert!((block.words[1].value - 5.0).abs() < 1e-12);
//! # Ok::<(), fiveaxis_macro::MacroError>(())
//! ```
//!
//! The code is pure: no I/O, no panics whatever the bytes, no unbounded
//! recursion (brackets nest at most [`MAX_BRACKET_DEPTH`] levels, deeper is
//! an alarm raised before going deeper; a line holds at most
//! [`MAX_OPERATIONS`] binary operations), no allocation while evaluating
//! unless an alarm is raised.
//!
//! # Sources
//!
//! The FANUC Series 30i/16i operator's manuals ("Custom macro" chapter)
//! as far as the search tool found them: the 16/18 Model C manual for the
//! five bracket levels (alarm 118), the 16i/18i-PB manual (B-63684EN) for
//! argument specification and call nesting, a public transcription of the
//! 30i PS alarm list for the alarm numbers (see `error.rs`), and the
//! vacant-variable tables (16i/30i; the same tables are in the Mitsubishi
//! M700V manual). Facts only; no text is copied.
//!
//! # Decisions where the manual is silent (or was not found)
//!
//! * **Blanks and comments** are dropped everywhere before reading
//!   (`G O T O 1 0` is `GOTO10`); keywords and functions are
//!   case-insensitive. The first comment's text is kept in
//!   [`Line::comment`] (the `#3000` message).
//! * **Line size**: more than [`MAX_OPERATIONS`] binary operations in one
//!   line is PS0114 (it bounds the depth of the tree).
//! * **Bracket depth**: the brackets of `IF […]`, `WHILE […]` and `#[…]`
//!   count towards the five levels, as function brackets do.
//! * **Signs**: at most one unary sign per operand (`--1` is PS0114); the
//!   negation of a vacant value stays vacant (so `X-#1` with `#1` vacant is
//!   left out, like `X#1`).
//! * **Conditions**: `IF` and `WHILE` take a bracketed comparison (or
//!   `AND`/`OR`/`XOR` of comparisons); a plain number there, or a
//!   comparison assigned to a variable, is PS0114, found while parsing.
//!   `EQ`/`NE` compare exactly.
//! * **Vacant operands** count as 0 for every operator and function; a
//!   vacant divisor is division by zero (PS0112).
//! * **`MOD`** works on the operands rounded to integers (half away from
//!   zero), the remainder has the sign of the dividend (`-10 MOD 3` = -1);
//!   `MOD 0` is PS0112.
//! * **`AND OR XOR` on numbers** work on the rounded operands as 32-bit
//!   two's complement integers; outside that range, PS0119.
//! * **Trigonometry** is in degrees and exact at multiples of 90°;
//!   `TAN` of 90° + k·180° is PS0119; `ATAN[0,0]` is PS0119; the
//!   one-argument `ATAN[a]` follows the `ASIN` range rule of NAT.
//! * **`LN` of 0** is PS0119 like `LN` of a negative number; `POW` of a
//!   negative number to a fractional power is PS0119, of 0 to a negative
//!   power PS0112; `EXP` overflow PS0111.
//! * **`BCD`** takes 0 … 99999999 (8 digits, 32 bits), **`BIN`** a value
//!   whose 8 nibbles are all 0 … 9; both round their operand first; other
//!   values PS0119.
//! * **`ADP`** multiplies by 10^[`MacroSettings::adp_digits`] (default 3,
//!   IS-B mm): it undoes the least-input-increment scaling of an argument
//!   written without decimal point. [`arguments`] itself takes values as
//!   written; scaling them is the caller's choice.
//! * **Variable numbers** computed by `#[…]` are rounded half away from
//!   zero; a vacant one is `#0`. Writing `#0` is PS0116.
//! * **NC words** given a computed value get `decimal_point: true` (see
//!   [`evaluate_block`]); the value is not rounded, its `code` is taken
//!   after rounding to one decimal place.
//! * **`GOTO`** targets are rounded and must be 1 … 99999 (PS0128).
//! * **`#3000` alarms**: the controller answers the write with
//!   [`SystemVarError::Alarm`]`(n)`; the alarm is
//!   [`MacroErrorKind::CustomAlarm`]`(n)` with the line's comment as its
//!   message, numbered 3000 + n (the 16i convention).
//! * **Reset** clears the local variables and `#100` … `#499`, keeps
//!   `#500` … `#999`.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod args;
mod block;
mod error;
mod eval;
mod expr;
mod ngc;
mod parse;
mod scan;
mod settings;
mod variables;

pub use args::arguments;
pub use block::evaluate_block;
pub use error::{MacroError, MacroErrorKind};
pub use expr::{
    BinOp, Binary, Call, Expr, Func, Line, NcBlock, NcWord, Statement, Value, Var, VarNumber,
    WordValue,
};
pub use ngc::{
    Comment, MAX_NGC_DEPTH, MAX_NGC_INDIRECTION, MAX_NGC_OPERATIONS, MAX_NGC_SIGNS, NgcLine, OKind,
    OLabel, OWord, label_key, oword_of, parse_ngc_line,
};
pub use parse::{MAX_BRACKET_DEPTH, MAX_OPERATIONS, parse_statement};
pub use scan::{is_macro_line, loop_end, loop_start};
pub use settings::MacroSettings;
pub use variables::{
    LOCAL_COUNT, NGC_CALL_ARGS, NGC_MAX_PARAMETER, NoSystemVariables, SystemVarError,
    SystemVariables, Variables,
};
