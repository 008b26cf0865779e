//! What the language hands on to the control: the interface between the
//! Klartext interpreter (Q parameters, formulas, FN functions, labels,
//! program calls) and the front end that turns executed blocks into the
//! kernel's commands.
//!
//! The interpreter reads a program block by block (a block may span
//! several lines joined by `~`), carries out what belongs to the language
//! itself (Q / QL / QR / QS assignments, `FN 0`–`FN 12`, `FN 14`,
//! `FN 15` / `FN 16` prints, `FN 18` reads, `LBL`, `CALL LBL … [REP n]`,
//! `CALL PGM`, `END PGM`, `/` skip) and yields every other block as an
//! [`Executed`] block: its kind, its words with every value evaluated
//! (a `Q` parameter in an address is replaced by its value), its keywords
//! and its M functions. It reads programs through [`ProgramText`] /
//! [`ProgramStore`] and the control's data through [`System`]: nothing
//! here knows machines or does I/O of its own.

use fiveaxis_gcode::Span;

/// What kind of block reached the control. The block's contents are in
/// [`Executed::words`], [`Executed::keys`] and [`Executed::m`].
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Kind {
    /// A block of M functions (and nothing else), or an empty block that
    /// still counts (`STOP` is [`Kind::Stop`]).
    #[default]
    Empty,
    /// `L`: a straight line (`L X+10 IY-5 Z+Q1 R0 FMAX M3`).
    Line,
    /// `LN`: a straight line with the surface normal `NX NY NZ` and the
    /// tool vector `TX TY TZ` (words of those names).
    LineNormal,
    /// `CC`: the circle centre / pole (`CC X+25 Y+25`, `CC IX+5`). A `CC`
    /// without coordinates takes the last programmed position.
    Centre,
    /// `C`: a circle about the pole to the end point (`C X Y DR+`).
    Circle,
    /// `CR`: a circle of radius `R` (`CR X Y R+20 DR-`).
    CircleRadius,
    /// `CT`: a circle tangential to the path before (`CT X Y`).
    CircleTangent,
    /// `LP`: a straight line in polar coordinates (`LP PR+30 PA+60`).
    LinePolar,
    /// `CP`: a circle about the pole in polar coordinates (`CP PA+90 IZ-2
    /// DR+`, with `IPA` for a helix).
    CirclePolar,
    /// `CTP`: a tangential circle in polar coordinates.
    CircleTangentPolar,
    /// `RND R5`: a rounding between the paths before and after.
    Rounding,
    /// `CHF 2`: a chamfer between the paths before and after.
    Chamfer,
    /// `APPR …` / `DEP …` with the form in [`Executed::name`] (`LT`, `LN`,
    /// `CT`, `LCT`, `PLT`, `PLN`, `PCT`, `PLCT`).
    Approach,
    /// `DEP …`, as [`Kind::Approach`].
    Depart,
    /// `TOOL CALL`: [`Executed::tool`] is the tool, [`Executed::name`]
    /// the spindle axis (`Z`) if written, the words `S`, `F`, `DL`, `DR`,
    /// `DR2`.
    ToolCall,
    /// `TOOL DEF n` / `TOOL DEF "name"`: the tool to make ready.
    ToolDef,
    /// `BLK FORM 0.1 Z X Y Z` (the stock's minimum point, with the spindle
    /// axis in [`Executed::name`]) or `BLK FORM 0.2 X Y Z` (maximum):
    /// [`Executed::number`] is 0.1 or 0.2.
    BlockForm,
    /// `CYCL DEF n.m …`: [`Executed::number`] is `n.m` (7.0, 7.1, 200);
    /// [`Executed::name`] the cycle's name when written (`DATUM SHIFT`,
    /// `DRILLING`); words as written after the number (`7.1 X+10`,
    /// `10.1 ROT+30`, `11.1 SCL 0.5`, `32.1 T0.05`); the cycle's
    /// parameters `Q200=2` in [`Executed::params`].
    CycleDef,
    /// `CYCL CALL` (keys `PAT`, `POS` as written; `M` functions in
    /// [`Executed::m`]).
    CycleCall,
    /// `PATTERN DEF`: the points and patterns in [`Executed::pattern`].
    PatternDef,
    /// `PLANE …`: the form (`SPATIAL`, `PROJECTED`, `EULER`, `VECTOR`,
    /// `POINTS`, `RELATIV`, `AXIAL`, `RESET`) in [`Executed::name`]; the
    /// angles and vectors as words (`SPA`, `SPB`, `SPC`, `PROPR`,
    /// `PROMIN`, `ROT`, `EULPR`, `EULNU`, `EULROT`, `BX`…`BZ`, `NX`…`NZ`,
    /// `P1X`…`P3Z`, `A`, `B`, `C`, `MB`, `DIST`, `F`, `FMAX` as a key);
    /// the keys `MOVE`, `TURN`, `STAY`, `SEQ+`, `SEQ-`, `COORD ROT`,
    /// `TABLE ROT`, `FMAX`.
    Plane,
    /// `FUNCTION TCPM …`: keys `F TCP`, `F CONT`, `AXIS POS`, `AXIS SPAT`,
    /// `PATHCTRL AXIS`, `PATHCTRL VECTOR`, `REFPNT TIP-TIP`,
    /// `REFPNT TIP-CENTER`, `REFPNT CENTER-CENTER`.
    Tcpm,
    /// `FUNCTION RESET TCPM`.
    TcpmReset,
    /// `STOP` (with its M functions, if any).
    Stop,
}

/// A value of the language.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number (Q, QL, QR parameters; every address value).
    Number(f64),
    /// A string (QS parameters).
    Text(String),
}

/// An address and its value: `X+10` is `X`, 10; `IX-5` is `X`, −5,
/// incremental; `F+Q3` is `F` with Q3's value; `DR+` on a circle is the
/// key `DR+`, not a word.
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    /// The address, upper-cased, without the `I` of an incremental value
    /// (`X`, `A`, `PA`, `PR`, `SPA`, `NX`, `TX`, `DL`, `R`, `F`, `S`).
    pub address: String,
    /// The value, evaluated.
    pub value: f64,
    /// Written with `I` (`IX+5`, `IPA+90`).
    pub incremental: bool,
    /// The columns of the word.
    pub span: Span,
}

/// A keyword of the block that carries no value: `R0`, `RL`, `RR`,
/// `FMAX`, `FAUTO`, `DR+`, `DR-`, `STAY`, `SEQ-`, `TABLE ROT`, `PAT`.
/// Multi-word keys are joined by one space, upper-cased.
#[derive(Clone, Debug, PartialEq)]
pub struct Key {
    /// The keyword.
    pub key: String,
    /// Its columns.
    pub span: Span,
}

/// The tool of `TOOL CALL` / `TOOL DEF`.
#[derive(Clone, Debug, PartialEq)]
pub enum Tool {
    /// By number (`TOOL CALL 5`, `TOOL CALL Q10`).
    Number(u32),
    /// By name (`TOOL CALL "FRA-D12"`, `TOOL CALL QS1`).
    Name(String),
}

/// One point or shape of `PATTERN DEF` (`POS1 (X+25 Y+33.5 Z+0)`,
/// `ROW1 (…)`, `PAT1 (…)`, `CIRC1 (…)`): its kind and its words.
#[derive(Clone, Debug, PartialEq)]
pub struct PatternItem {
    /// `POS`, `ROW`, `PAT`, `FRAME`, `CIRC`, `PITCHCIRC`.
    pub kind: String,
    /// The item's words (`X`, `Y`, `Z`, `ROTX`, `NUMX`, `DIA`, `START`,
    /// `NUM` …).
    pub words: Vec<Word>,
}

/// One block as it reaches the control, every value evaluated.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Executed {
    /// The first line of the block in its program (1-based, counting the
    /// file's lines, not the TNC's block numbers).
    pub line: u32,
    /// Which program the line is in: 0 the main program, else the number
    /// [`ProgramStore::open`]'s programs get in the order opened.
    pub program: usize,
    /// The TNC's block number at the start of the line, if written.
    pub block_number: Option<u32>,
    /// What the block is.
    pub kind: Kind,
    /// A name of the block, upper-cased: the form of `PLANE` / `APPR` /
    /// `DEP`, the cycle name of `CYCL DEF`, the spindle axis of `TOOL
    /// CALL` / `BLK FORM 0.1`.
    pub name: Option<String>,
    /// A number of the block: the cycle number of `CYCL DEF` (7.1, 200),
    /// 0.1 / 0.2 of `BLK FORM`.
    pub number: Option<f64>,
    /// The tool of `TOOL CALL` / `TOOL DEF`.
    pub tool: Option<Tool>,
    /// Words in the order written.
    pub words: Vec<Word>,
    /// Keywords in the order written.
    pub keys: Vec<Key>,
    /// The cycle parameters of `CYCL DEF` (`Q200=2` is (200, 2.0)), in
    /// the order written.
    pub params: Vec<(u32, f64)>,
    /// `PATTERN DEF`'s items.
    pub pattern: Vec<PatternItem>,
    /// M functions in the order written, with their columns.
    pub m: Vec<(u32, Span)>,
    /// The block's `;` comment, if any (without the `;`).
    pub comment: Option<String>,
}

impl Executed {
    /// The word with `address`, if the block has one.
    pub fn word(&self, address: &str) -> Option<&Word> {
        self.words.iter().find(|w| w.address == address)
    }

    /// Whether the block has keyword `key`.
    pub fn has_key(&self, key: &str) -> bool {
        self.keys.iter().any(|k| k.key == key)
    }

    /// The value of cycle parameter `q`, if written.
    pub fn param(&self, q: u32) -> Option<f64> {
        self.params.iter().find(|(n, _)| *n == q).map(|(_, v)| *v)
    }
}

/// An error of the language: where, and a plain-English message (the TNC
/// shows error texts, not numbers).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct LangError {
    /// What kind of error: the kernel gives each its FX code.
    pub kind: LangErrorKind,
    /// The program the line is in (as [`Executed::program`]).
    pub program: usize,
    /// The line.
    pub line: u32,
    /// The columns at fault.
    pub span: Span,
    /// What is wrong.
    pub message: String,
}

/// The kinds of language errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LangErrorKind {
    /// A block the language cannot read.
    Syntax,
    /// A label that does not exist (`CALL LBL 7`, `FN 9 … GOTO LBL 7`).
    LabelMissing,
    /// A program `CALL PGM` names that the store does not hold.
    ProgramMissing,
    /// Division by zero, root of a negative number and the like.
    Arithmetic,
    /// A parameter out of its range (`Q2000`), or read before it was set
    /// where the control refuses that.
    Parameter,
    /// `FN 14: ERROR = n`: the program raised error `n`.
    ProgramError(u32),
    /// Calls nested deeper than the control allows.
    Nesting,
    /// The kernel's block budget ran out (a runaway program).
    Budget,
}

pub use fiveaxis_gcode::ProgramText;

/// The control's program memory beside the running program (`CALL PGM`).
pub trait ProgramStore: Send {
    /// The program called `name` as written (`SUB1`, `TNC:\PARTS\SUB1.H`,
    /// `SUB1.H`); the store finds it case-insensitively, with or without
    /// `.H`, by its file name. `None` when the store has no such program.
    ///
    /// # Errors
    ///
    /// The program exists but cannot be read.
    fn open(&mut self, name: &str) -> std::io::Result<Option<Box<dyn ProgramText>>>;
}

/// The control's data that a program reads (`FN 18: SYSREAD`) and the
/// prints it makes (`FN 15`, `FN 16`).
pub trait System {
    /// `FN 18: SYSREAD Qn = ID<group> NR<number> IDX<index>`: the value
    /// the control gives, or `Err` with a message when the kernel does
    /// not know that datum.
    ///
    /// # Errors
    ///
    /// The datum is not one the kernel knows.
    fn sysread(&mut self, group: u32, number: u32, index: Option<u32>) -> Result<f64, String>;
}

/// What [`crate::Interpreter::next_block`] gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// A block was written to the caller's [`Executed`].
    Block,
    /// The main program ended (`END PGM` of the main program, or `M2` /
    /// `M30` after their block has been yielded).
    End,
}
