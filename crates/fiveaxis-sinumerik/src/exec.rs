//! What the language hands on to the control: the interface between the
//! interpreter (variables, expressions, program flow, calls) and the
//! front end that turns executed blocks into the kernel's commands.
//!
//! The interpreter runs the language (DEF, R parameters, IF / WHILE /
//! FOR / REPEAT / LOOP / CASE, jumps, subprograms and their parameters,
//! modal calls of subprograms, DEFINE macros) and yields each block that
//! reaches the control as an [`Executed`] block: its words and named
//! instructions in the order written, every value evaluated. It reads
//! programs through [`ProgramText`] / [`ProgramStore`] and the control's
//! data through [`System`]: nothing here knows machines or does I/O of its
//! own.

use fiveaxis_gcode::Span;

use crate::PositionMode;

/// A value of the language.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// `INT`
    Int(i64),
    /// `REAL`
    Real(f64),
    /// `BOOL`
    Bool(bool),
    /// `CHAR`
    Char(u8),
    /// `STRING`
    Str(String),
    /// `AXIS`: an axis name, upper-cased (`X`, `C`, `AX4`).
    Axis(String),
    /// `FRAME`
    Frame(Box<FrameValue>),
}

impl Value {
    /// The value as a number: INT, REAL, BOOL (0 / 1) and CHAR (its code)
    /// are numbers; a string, axis or frame is not.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Self::Int(i) => Some(*i as f64),
            Self::Real(x) => Some(*x),
            Self::Bool(b) => Some(f64::from(u8::from(*b))),
            Self::Char(c) => Some(f64::from(*c)),
            Self::Str(_) | Self::Axis(_) | Self::Frame(_) => None,
        }
    }
}

/// A frame as a value (`DEF FRAME F`, `CTRANS(X,10):CROT(Z,30)`,
/// `$P_UIFR[1]`): per axis its translation (`TR`), fine translation
/// (`FI`), rotation (`RT`, degrees, geometry axes only), scale (`SC`) and
/// mirror (`MI`), as the components `$P_PFRAME[X,TR]` name them.
/// Rotations are RPY: about Z, then the new Y, then the newest X (the
/// control's default angle convention, K2).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FrameValue {
    /// The axes with a component other than neutral, by name.
    pub axes: Vec<FrameAxis>,
}

/// The components of one axis in a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameAxis {
    /// The axis name, upper-cased.
    pub axis: String,
    /// Translation, mm or degrees.
    pub tr: f64,
    /// Fine translation.
    pub fi: f64,
    /// Rotation about the axis, degrees (X, Y, Z only).
    pub rt: f64,
    /// Scale factor (1 is neutral).
    pub sc: f64,
    /// Mirrored.
    pub mi: bool,
}

/// One block as it reaches the control, every value evaluated.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Executed {
    /// The line in its program (1-based).
    pub line: u32,
    /// Which program the line is in: 0 the main program, else the
    /// number [`ProgramStore::open`]'s programs get in the order opened.
    pub program: usize,
    /// The block number `N…`, if written.
    pub number: Option<u32>,
    /// Words and instructions in the order written.
    pub actions: Vec<Action>,
    /// The line's `;` comment, if any (without the `;`).
    pub comment: Option<String>,
}

/// One thing a block tells the control.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// An address and its value: `X=AC(10)` is address `X`, value 10,
    /// mode `AC`; `G1`, `M3`, `M2=5` (address `M2`), `T="DRILL"`, `CR=5`,
    /// `A3=0`, `I1=2`, `TURN=3`, `RPL=30`.
    Word {
        /// The address, upper-cased.
        address: String,
        /// Its value.
        value: Value,
        /// `AC(…)` and the others around the value.
        mode: Option<PositionMode>,
        /// The columns of the word.
        span: Span,
    },
    /// A named instruction the language does not carry out itself:
    /// `TRAORI(1)`, `TRANS`, `AROT`, `CYCLE81(…)`, `CYCLE800(…)`,
    /// `MSG("…")`, `SETAL(61000)`, `ORIRESET(…)`, `SOFT`, `G_FUNCTIONS`
    /// written as names, and any cycle the program store does not hold.
    /// `args` is `None` without parentheses; an omitted argument is
    /// `None`.
    Instruction {
        /// The name, upper-cased.
        name: String,
        /// The arguments, evaluated.
        args: Option<Vec<Option<Value>>>,
        /// The columns of the name and its arguments.
        span: Span,
    },
    /// `MCALL name(…)` of a cycle the control carries out (the store does
    /// not hold it): from now on called after every block that moves a
    /// geometry axis; `None` ends the modal call. A modal call of a
    /// subprogram from the store is the interpreter's own.
    ModalCall {
        /// The cycle's name and arguments, or none for `MCALL` alone.
        call: Option<(String, Vec<Option<Value>>)>,
        /// The columns.
        span: Span,
    },
    /// A synchronized action, read and not carried out.
    SyncAction {
        /// The columns of the whole action.
        span: Span,
    },
}

/// An error of the language: the alarm number the control shows, where,
/// and a plain-English message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct LangError {
    /// The SINUMERIK alarm number (12080 syntax error, 12550 name not
    /// defined, 14080 jump destination not found, 14011 program not
    /// available, …), or `None` for the kernel's own bounds.
    pub alarm: Option<u32>,
    /// The program the line is in (as [`Executed::program`]).
    pub program: usize,
    /// The line.
    pub line: u32,
    /// The columns at fault.
    pub span: Span,
    /// What is wrong.
    pub message: String,
}

pub use fiveaxis_gcode::ProgramText;

/// The control's program memory beside the running program:
/// subprograms, user cycles and definition files.
pub trait ProgramStore: Send {
    /// The program called `name` (as called: `RLIMIT`, `L100`, `4444411`,
    /// upper-cased), found case-insensitively as `NAME.SPF`, `NAME.MPF`,
    /// `_N_NAME_SPF`, `_N_NAME_MPF`; `None` when the store has no such
    /// program.
    ///
    /// # Errors
    ///
    /// The program exists but cannot be read.
    fn open(&mut self, name: &str) -> std::io::Result<Option<Box<dyn ProgramText>>>;
    /// The definition files (`*.DEF`: `DEF NCK|CHAN …` global data,
    /// `DEFINE … AS` macros), read once at the start, each with its name.
    ///
    /// # Errors
    ///
    /// A file cannot be read.
    fn definitions(&mut self) -> std::io::Result<Vec<(String, Box<dyn ProgramText>)>> {
        Ok(Vec::new())
    }
}

/// The control's data that a program reads and writes: system variables
/// (`$AA_IW[X]`, `$P_TOOLNO`, `$TC_DP3[1,1]`, `$P_UIFR[1]`), and the
/// names the control knows beyond the language.
pub trait System {
    /// The value of system variable `name` (upper-cased, with its `$`) at
    /// `indices` (an axis index arrives as [`Value::Axis`]). `Err` with a
    /// message when the control has no such variable or index (alarm
    /// 12550 at the variable).
    ///
    /// # Errors
    ///
    /// The variable or index does not exist.
    fn read(&mut self, name: &str, indices: &[Value]) -> Result<Value, String>;
    /// Writes system variable `name`.
    ///
    /// # Errors
    ///
    /// The variable does not exist or cannot be written.
    fn write(&mut self, name: &str, indices: &[Value], value: Value) -> Result<(), String>;
    /// Whether `name` (upper-cased) is an axis of the channel: `X`, `C`
    /// … An axis name is a value of type AXIS in expressions (`$AA_IW[X]`,
    /// `DEF AXIS A1=(X)`), and a block that moves a geometry axis
    /// triggers a modal call.
    fn is_axis(&self, name: &str) -> bool;
    /// Whether `name` is a cycle or instruction the control carries out
    /// itself (`CYCLE81`, `CYCLE800`, `HOLES1`, `TRAORI`, `MSG` …): the
    /// interpreter passes it on as an [`Action::Instruction`] when the
    /// store does not hold a program of that name.
    fn is_builtin(&self, name: &str) -> bool;
}

/// What [`crate::Interpreter::next_block`] gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// A block was written to the caller's [`Executed`].
    Block,
    /// The main program ended (`M2`, `M30` and `M17` / `RET` at the main
    /// level end it after their block; so does the end of its text).
    End,
}
