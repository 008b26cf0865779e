//! The interpreter: runs the language of a SINUMERIK part program and
//! yields each block that reaches the control as an [`Executed`] block.
//!
//! # Design
//!
//! **Streaming.** Programs are read line by line through
//! [`ProgramText`]; nothing loads a whole program. Each line is parsed
//! when read ([`crate::parse_line`], after `DEFINE` macro substitution)
//! and run at once. Every line read — run, skipped by a skip level,
//! passed over by a false `IF` or read by a jump's search — counts
//! against [`Options::max_blocks`], so a runaway loop ends in an error
//! (`alarm: None`) instead of running for ever.
//!
//! **Positions.** A program's lines are only ever read in order; a
//! backward move is a [`ProgramText::seek`] to a line start remembered
//! before (the opening line of a loop, a label), never a rescan (the
//! backward search of a block number aside, below). Per
//! opening of a program (each call opens its text afresh, and seeks only
//! to positions that opening has reported) the interpreter keeps the
//! furthest position read and the positions of the labels in the text up
//! to there: memory grows with labels, not with lines. Block numbers are
//! not indexed (CAM output numbers every line).
//!
//! **Jumps** (AV11 p107) are directional text searches from the jump's
//! line: `GOTOF` forward to the end of the program, `GOTOB` backward to
//! its start, `GOTO` and `GOTOC` forward then backward, `GOTOS` to the
//! start. The nearest match in the direction of search wins. A label is
//! found forward in the index, or by reading on from the furthest line
//! read; backward in the index alone (every line before the jump has been
//! read). A block number is found forward by reading on from the line
//! after the jump, backward by reading from the program start up to the
//! jump's line, remembering the last match. The jump's own line belongs
//! to the backward search (its label stands before the jump). A target
//! that is not found raises alarm 14080 when the jump runs, never before;
//! `GOTOC` then goes on after its line.
//!
//! **Structures** are matched by nesting at run time. Each program level
//! keeps a stack of the open structures (`IF`, `WHILE`, `FOR`, `REPEAT`,
//! `LOOP`) with the position of their opening line or first body line. A
//! false condition reads forward to the matching `ELSE` / `ENDIF` /
//! `ENDWHILE` / `ENDFOR`, counting nested structures of the same kind; a
//! loop's end seeks back to its opening line (`WHILE`, which is tested
//! again) or to its first body line (`FOR`, `REPEAT`, `LOOP`). A closing
//! keyword looks for its kind from the top of the stack down and drops
//! what lies above (structures left by a jump); a backward jump drops the
//! structures opened at or after its target. A closing keyword with no
//! opener is alarm 12080 (the syntax alarm of the brief; the control
//! likely has an alarm of its own for bad nesting, not found in a
//! retrieved manual).
//!
//! **Call frames.** Each program level (the main program, then each
//! subprogram called) has its own text, position, structure stack, local
//! variables (LUD) and a queue of work left for after its current block
//! (a call, a jump, a return, the end). A call is carried out after the
//! block that holds it has been yielded (the control wants a subprogram
//! call in a block of its own, so nothing is reordered in practice);
//! items written after a call in the same block are evaluated before the
//! call runs. `PROC` parameters are bound when the called program's first
//! statement is read: value parameters by value, `VAR` parameters as
//! references to the caller's variable (or element, R parameter, system
//! variable). Program levels nest at most [`MAX_LEVELS`] deep (the main
//! program and 15 subprogram levels, UNVERIFIED against a manual).
//!
//! # Decisions where the manuals were silent or not found
//!
//! * Literal numbers are INT when whole and within the INT range, REAL
//!   otherwise; `/` always gives REAL, `DIV` an INT, `MOD` an INT for two
//!   INTs. INT arithmetic that overflows goes on in REAL.
//! * REAL comparisons treat values within a relative 1e-12 as equal
//!   ([`REAL_TOLERANCE`]; ONE p444 gives no figure).
//! * Division by zero and functions outside their domain raise alarm
//!   14051 (our choice in the interpreter range).
//! * An array index out of range raises 17020 (first index) or 17030
//!   (second); so does an R parameter beyond [`Options::r_parameters`]
//!   (secondary source: a Siemens support note).
//! * `DEF` may come anywhere in a program (the control wants it at the
//!   top of the program, before the first executed block); a `DEF NCK` /
//!   `DEF CHAN` in a program defines a global if not yet defined. A `DEF`
//!   run again (a jump back over it) defines the variable afresh.
//! * `DEFINE` macros are substituted once, as whole identifiers outside
//!   strings and comments (not inside a run such as `G1X10`); the text
//!   substituted is not searched again. Spans of a substituted line are
//!   columns of the substituted text.
//! * Skip levels: a line `/n` is skipped, unparsed, when bit n of
//!   [`Options::skip_levels`] is set. Jump searches still find labels on
//!   skipped lines; structure searches ignore them.
//! * Lines that do not parse inside a skipped structure or a search are
//!   passed over without an error.
//! * `FOR` counts by 1 while the counter is at most the end value (the
//!   end value evaluated once); after the loop the counter is one past
//!   the end.
//! * A `MCALL` of a program of the store is in force for the blocks of
//!   the program level that programmed it and ends with that level; the
//!   called program's own blocks do not trigger it. A modal call of a
//!   cycle the store does not hold goes to the front end as
//!   [`Action::ModalCall`].
//! * `CALL BLOCK A TO B` finds `A` as `GOTO` does, runs up to and with
//!   the line of `B` and returns after the `CALL` line; without `TO` it
//!   runs the line of `A` alone. The end of the text also ends a section.
//!   A section of another program (`CALL "P" BLOCK …`) is not supported
//!   (an error without alarm).
//! * `M17` and `RET` in the main program end it, as `M2` / `M30` do.
//!   `M2` / `M30` in a subprogram end the whole program. A subprogram
//!   called with arguments must begin with `PROC`; more arguments than
//!   parameters is alarm 12080.
//! * `P n` passes run at most [`MAX_PASSES`] times; `P0` or more passes
//!   than that is alarm 12080. Each new pass counts as a line read
//!   against the budget. A `P` word right after a call of a program of
//!   the store is its passes also when written `P=expression`.
//! * A `DEFINE` in a program holds from its line on, for every program
//!   level (macros are global, as those of the definition files).
//! * INT values are checked against ±(2^31 − 1) when stored in an INT
//!   variable (alarm 14051 past it); expressions compute in 64 bits.
//! * Synchronized actions are not simulated: they add a note (at most
//!   [`MAX_NOTES`] are kept) and yield nothing.
//! * A word whose address is the name of a user variable (`DEF INT I`
//!   then `I=5`; the reader takes `I=` for an address) assigns the
//!   variable.
//! * Text of values (`<<`, a number stored in a STRING): REALs rounded to
//!   10 decimals without trailing zeros ([`format_real`]: `1.5`, `3`),
//!   BOOL as `1` / `0`, CHAR as its character, an axis by its name. A
//!   string longer than its `STRING[n]` is cut to n bytes (UNVERIFIED:
//!   the control may raise an alarm). A one-character string converts
//!   to CHAR; a string never converts to a number (alarm 14096).
//! * String positions (`INDEX`, `RINDEX`, `SUBSTR`, `S[i]`) count from
//!   0, `-1` when not found; array indices count from 0. `ROUNDUP` rounds
//!   towards +∞ (UNVERIFIED for negative values); `TRUNC`, `ROUND`,
//!   `ROUNDUP`, `POT` give REAL, `ABS`, `MINVAL`, `MAXVAL` keep INT. A
//!   function the interpreter does not know is alarm 12550.
//! * Frames (`CTRANS`, `CROT`, `CSCALE`, `CMIRROR`, `CFINE` and `:`): a
//!   frame maps `p = T + R·S·M·p'` (RPY rotation about X, Y, Z as
//!   `FrameValue` has it); `A : B` composes translations through `A`'s
//!   rotation, scale and mirror and rotations as 3×3 matrices, then back
//!   to RPY angles. Scale and mirror of `A` taken through `B`'s rotation
//!   are exact only for a uniform scale without mirror. Rotations are for
//!   X, Y, Z only.
//! * Indices of system variables and axis arguments of frame functions
//!   and instructions: a bare name that is no variable of the program
//!   passes as [`Value::Axis`] (`$AA_IW[X]`, `$P_UIFR[1,X,TR]`,
//!   `FGROUP(X,Y,Z)`); the [`System`] decides whether it exists.
//! * [`Executed::program`] numbers programs by name in the order they
//!   are first opened (every call of `SUB1` is the same number). A
//!   `PROC` line in the main program binds nothing. `EXTCALL` and `CALL`
//!   take the last part of a path as the name, upper-cased.
//! * The default block budget is 50 million lines
//!   ([`Options::default`]).
//! * `POS[X]=…`, `FA[X]=…` and the like (an address with an axis index,
//!   written as an assignment) are yielded as words with the address
//!   `POS[X]`.

mod eval;
mod flow;
mod frames;
mod text;
mod vars;

use std::collections::{HashMap, VecDeque};

use fiveaxis_gcode::Span;

pub use eval::{REAL_TOLERANCE, format_real};
pub use text::TextProgram;

use eval::{ALARM_SYNTAX, Ctx, Fault, convert, truth};
use flow::Structure;
use vars::{ALARM_CONVERSION, ALARM_INDEX_1, MAX_ELEMENTS, Place, Slot, Variable, Vars};

use crate::{
    Action, Call, CallKind, Def, Executed, ExprKind, Init, Item, Jump, JumpTarget, LangError, Line,
    ParseError, Proc, ProgramStore, ProgramText, Statement, Step, System, Value, Var, parse_line,
};

/// Program levels: the main program and up to 15 subprogram levels
/// (design brief §1: "16?", UNVERIFIED).
pub const MAX_LEVELS: usize = 16;
/// The most passes of one call, `P1` … `P9999` (the value range of `P`
/// as commonly given for the 840D; UNVERIFIED against a retrieved manual).
pub const MAX_PASSES: u64 = 9999;
/// The most notes kept ([`Interpreter::notes`]).
pub const MAX_NOTES: usize = 100;
/// Alarm for a program not in the store (`14011`, as the brief asks).
const ALARM_NOT_AVAILABLE: u32 = 14011;

/// How the interpreter runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    /// Bit n set: skip level `/n` is active (`/` alone is level 0).
    pub skip_levels: u16,
    /// Lines read before the program counts as a runaway (every line
    /// read counts, searched and skipped ones too).
    pub max_blocks: u64,
    /// The number of R parameters: `R0` … `R(n-1)` (100 by default, the
    /// usual machine data value).
    pub r_parameters: usize,
}

impl Default for Options {
    /// No skip level, a budget of 50 million lines, `R0` … `R99`.
    fn default() -> Self {
        Self {
            skip_levels: 0,
            max_blocks: 50_000_000,
            r_parameters: 100,
        }
    }
}

/// A line start: its byte offset and its line number (1-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct LinePos {
    pub pos: u64,
    pub line: u32,
}

impl LinePos {
    const START: Self = Self { pos: 0, line: 1 };
}

/// A program known by number (for [`Executed::program`]).
#[derive(Debug)]
struct ProgramInfo {
    name: String,
}

/// An argument of a call, evaluated in the caller.
#[derive(Clone, Debug)]
struct Arg {
    /// The value (a failure kept for a variable passed whole, an array,
    /// which only a `VAR` parameter can take).
    value: Result<Value, Fault>,
    /// Where the argument lives when it is a variable.
    place: Option<Place>,
    span: Span,
}

/// A subprogram call waiting for its block to be yielded.
struct CallSpec {
    name: String,
    text: Box<dyn ProgramText>,
    args: Vec<Option<Arg>>,
    passes: u64,
}

/// A modal call of a subprogram of the store.
#[derive(Clone, Debug)]
struct ModalSub {
    name: String,
    args: Vec<Option<Arg>>,
    span: Span,
}

/// `CALL BLOCK`: where to return and which line ends it.
#[derive(Debug)]
struct Section {
    back: LinePos,
    end: Option<JumpTarget>,
    structures: usize,
}

/// Work left for after a block.
enum Pending {
    Call(CallSpec),
    Jump(Jump),
    Section(JumpTarget, Option<JumpTarget>, Span),
    SectionEnd,
    Return,
    End,
}

/// One program level.
struct CallFrame<'a> {
    program: usize,
    text: Box<dyn ProgramText + 'a>,
    /// Label positions in the text read so far, in order.
    labels: HashMap<String, Vec<LinePos>>,
    /// The first line not read yet.
    high_water: LinePos,
    /// The line being run.
    cur: LinePos,
    /// The columns of its text (first non-blank to the end).
    cur_span: Span,
    /// The next line to read.
    next: LinePos,
    structures: Vec<Structure>,
    sections: Vec<Section>,
    pending: VecDeque<Pending>,
    passes_left: u64,
    args: Vec<Option<Arg>>,
    started: bool,
    modal: Option<ModalSub>,
}

/// A line read and parsed.
struct ReadLine {
    at: LinePos,
    skipped: bool,
    parsed: Result<Line, ParseError>,
}

/// The SINUMERIK language interpreter: design and decisions in the
/// [module documentation](self).
pub struct Interpreter<'a> {
    options: Options,
    store: Box<dyn ProgramStore + 'a>,
    frames: Vec<CallFrame<'a>>,
    programs: Vec<ProgramInfo>,
    by_name: HashMap<String, usize>,
    vars: Vars,
    macros: HashMap<String, String>,
    blocks: u64,
    notes: Vec<String>,
    ended: bool,
    failed: Option<LangError>,
    buf: Vec<u8>,
    /// The text of the line being carried out (for messages).
    line_text: Vec<u8>,
}

impl std::fmt::Debug for Interpreter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Interpreter")
            .field("options", &self.options)
            .field("levels", &self.frames.len())
            .field("blocks", &self.blocks)
            .field("ended", &self.ended)
            .finish_non_exhaustive()
    }
}

/// A system for the definitions read before any: no axes, no variables.
struct NoSystem;

impl System for NoSystem {
    fn read(&mut self, name: &str, _: &[Value]) -> Result<Value, String> {
        Err(format!("{name} cannot be read in a definition file"))
    }
    fn write(&mut self, name: &str, _: &[Value], _: Value) -> Result<(), String> {
        Err(format!("{name} cannot be written in a definition file"))
    }
    fn is_axis(&self, _: &str) -> bool {
        false
    }
    fn is_builtin(&self, _: &str) -> bool {
        false
    }
}

/// The columns of a line's text, from its first non-blank to its end.
fn text_span(text: &[u8]) -> Span {
    let len = u32::try_from(text.len()).unwrap_or(u32::MAX - 1);
    let first = text
        .iter()
        .position(|b| !matches!(b, b' ' | b'\t'))
        .map_or(len, |i| u32::try_from(i).unwrap_or(0));
    Span::new(
        first.saturating_add(1),
        len.saturating_add(1).max(first.saturating_add(2)),
    )
}

/// Whether a line begins with a skip level that is active.
fn skipped(text: &[u8], levels: u16) -> bool {
    let mut i = 0;
    while matches!(text.get(i), Some(b' ' | b'\t')) {
        i += 1;
    }
    if text.get(i) != Some(&b'/') {
        return false;
    }
    let level = match text.get(i + 1) {
        Some(d) if d.is_ascii_digit() => u32::from(d - b'0'),
        _ => 0,
    };
    levels & (1u16 << level) != 0
}

fn io_error(program: usize, line: u32, name: &str, e: &std::io::Error) -> LangError {
    LangError {
        alarm: None,
        program,
        line,
        span: Span::new(1, 1),
        message: format!("program {name} cannot be read: {e}"),
    }
}

fn parse_error(program: usize, e: ParseError) -> LangError {
    LangError {
        alarm: e.alarm(),
        program,
        line: e.line,
        span: e.span,
        message: e.message,
    }
}

/// Addresses written with an axis index as an assignment (`POS[X]=10`),
/// yielded as words.
fn indexed_address(name: &str) -> bool {
    matches!(
        name,
        "POS"
            | "POSA"
            | "SPOS"
            | "SPOSA"
            | "FA"
            | "FL"
            | "FGREF"
            | "ACC"
            | "OVRA"
            | "JERKA"
            | "VELOLIMA"
            | "ACCLIMA"
            | "FDA"
            | "FD"
            | "IPOENDA"
            | "IPOBRKA"
            | "ADISPOSA"
            | "SCC"
            | "FPR"
            | "FPRAON"
            | "FPRAOF"
            | "S"
            | "M"
            | "T"
            | "D"
            | "H"
    )
}

impl<'t> Interpreter<'t> {
    /// An interpreter for the main program `main`, with the subprograms
    /// and definition files of `store`. Reads the definition files first
    /// (`DEF NCK|CHAN …` global data, `DEFINE … AS` macros).
    ///
    /// # Errors
    ///
    /// A definition file cannot be read or holds an error.
    pub fn new(
        main: Box<dyn ProgramText + 't>,
        mut store: Box<dyn ProgramStore + 't>,
        options: Options,
    ) -> Result<Self, LangError> {
        let definitions = store
            .definitions()
            .map_err(|e| io_error(0, 0, "definitions", &e))?;
        let mut me = Self {
            vars: Vars::new(options.r_parameters),
            options,
            store,
            frames: vec![CallFrame {
                program: 0,
                text: main,
                labels: HashMap::new(),
                high_water: LinePos::START,
                cur: LinePos::START,
                cur_span: Span::new(1, 1),
                next: LinePos::START,
                structures: Vec::new(),
                sections: Vec::new(),
                pending: VecDeque::new(),
                passes_left: 1,
                args: Vec::new(),
                started: false,
                modal: None,
            }],
            programs: vec![ProgramInfo {
                name: "main".to_string(),
            }],
            by_name: HashMap::new(),
            macros: HashMap::new(),
            blocks: 0,
            notes: Vec::new(),
            ended: false,
            failed: None,
            buf: Vec::new(),
            line_text: Vec::new(),
        };
        for (name, mut text) in definitions {
            me.read_definitions(&name, text.as_mut())?;
        }
        Ok(me)
    }

    fn read_definitions(
        &mut self,
        name: &str,
        text: &mut dyn ProgramText,
    ) -> Result<(), LangError> {
        let mut buf = Vec::new();
        let mut line = 0u32;
        let fail = |e: LangError| LangError {
            message: format!("definition file {name}, line {}: {}", e.line, e.message),
            ..e
        };
        loop {
            buf.clear();
            match text.read_line(&mut buf) {
                Ok(true) => {}
                Ok(false) => return Ok(()),
                Err(e) => return Err(io_error(0, line, name, &e)),
            }
            line = line.saturating_add(1);
            let parsed = parse_line(&buf, line).map_err(|e| fail(parse_error(0, e)))?;
            match parsed.statement {
                Statement::Def(def) => {
                    let mut sys = NoSystem;
                    self.define(&def, true, &mut sys)
                        .map_err(|f| fail(self.fault_at(f, 0, line)))?;
                }
                Statement::Define { name, text } => {
                    self.macros.insert(name.text, text);
                }
                _ => {}
            }
        }
    }

    /// The name of program `program` ("main" for 0, else as called), for
    /// messages; `"?"` for a number never given.
    pub fn program_name(&self, program: usize) -> &str {
        self.programs.get(program).map_or("?", |p| p.name.as_str())
    }

    /// The text of the line being carried out, or of the last one carried
    /// out: the block an error or an [`crate::Executed`] block is about.
    pub fn line_text(&self) -> &[u8] {
        &self.line_text
    }

    /// Lines read so far (run, skipped and searched).
    pub fn blocks(&self) -> u64 {
        self.blocks
    }

    /// Notes on what was read and not simulated (synchronized actions),
    /// at most [`MAX_NOTES`] and a last one saying more were dropped.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    fn note(&mut self, text: String) {
        match self.notes.len() {
            n if n < MAX_NOTES => self.notes.push(text),
            MAX_NOTES => self.notes.push("further notes not kept".to_string()),
            _ => {}
        }
    }

    /// Runs the language until a block has something for the control,
    /// written to `out` (cleared first), or the program ends.
    ///
    /// # Errors
    ///
    /// An alarm of the language, a program that cannot be read, or the
    /// block budget exhausted. After an error every later call gives it
    /// again.
    pub fn next_block(
        &mut self,
        sys: &mut dyn System,
        out: &mut Executed,
    ) -> Result<Step, LangError> {
        // The buffer of actions is kept from block to block.
        out.line = 0;
        out.program = 0;
        out.number = None;
        out.actions.clear();
        out.comment = None;
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        if self.ended {
            return Ok(Step::End);
        }
        match self.run(sys, out) {
            Ok(step) => {
                if step == Step::End {
                    self.ended = true;
                }
                Ok(step)
            }
            Err(e) => {
                self.failed = Some(e.clone());
                Err(e)
            }
        }
    }

    fn top(&self) -> &CallFrame<'t> {
        let n = self.frames.len() - 1;
        &self.frames[n]
    }

    fn top_mut(&mut self) -> &mut CallFrame<'t> {
        let n = self.frames.len() - 1;
        &mut self.frames[n]
    }

    fn level(&self) -> usize {
        self.frames.len() - 1
    }

    fn fault_at(&self, f: Fault, program: usize, line: u32) -> LangError {
        LangError {
            alarm: f.alarm,
            program,
            line,
            span: f.span,
            message: f.message,
        }
    }

    /// A fault on the line being run.
    fn fault(&self, f: Fault) -> LangError {
        let top = self.top();
        self.fault_at(f, top.program, top.cur.line)
    }

    /// The columns of the line being run.
    fn line_span(&self) -> Span {
        self.top().cur_span
    }

    fn error(&self, alarm: Option<u32>, span: Span, message: String) -> LangError {
        self.fault(Fault::new(alarm, span, message))
    }

    fn ctx<'a>(&'a mut self, sys: &'a mut dyn System) -> Ctx<'a> {
        let level = self.frames.len() - 1;
        Ctx {
            vars: &mut self.vars,
            sys,
            level,
        }
    }

    /// Goes on reading the running program at `to`.
    fn seek(&mut self, to: LinePos) -> Result<(), LangError> {
        let top = self.frames.len() - 1;
        let program = self.frames[top].program;
        let line = self.frames[top].cur.line;
        if let Err(e) = self.frames[top].text.seek(to.pos) {
            return Err(io_error(program, line, self.program_name(program), &e));
        }
        self.frames[top].next = to;
        Ok(())
    }

    /// Counts one line against the budget, or the runaway error.
    fn charge(&mut self) -> Result<(), LangError> {
        self.budget()?;
        self.blocks += 1;
        Ok(())
    }

    /// The runaway error when the budget is used up.
    fn budget(&self) -> Result<(), LangError> {
        if self.blocks < self.options.max_blocks {
            return Ok(());
        }
        let top = self.top();
        let program = top.program;
        // At the last line read (the first line when none was).
        let (line, span) = if self.blocks == 0 {
            (top.next.line, Span::new(1, 1))
        } else {
            (top.cur.line, top.cur_span)
        };
        Err(LangError {
            alarm: None,
            program,
            line,
            span,
            message: format!(
                "block budget of {} lines exhausted at line {line} of program {}: the program does not end (a runaway loop?)",
                self.options.max_blocks,
                self.program_name(program)
            ),
        })
    }

    /// Reads the next line of the running program: counted, skip level
    /// checked, macros substituted, parsed, its label indexed when new.
    fn read_line(&mut self) -> Result<Option<ReadLine>, LangError> {
        let top = self.frames.len() - 1;
        let program = self.frames[top].program;
        self.budget()?;
        let frame = &mut self.frames[top];
        let at = LinePos {
            pos: frame.text.position(),
            line: frame.next.line,
        };
        self.buf.clear();
        let more = match frame.text.read_line(&mut self.buf) {
            Ok(more) => more,
            Err(e) => {
                let name = self.programs.get(program).map_or("?", |p| p.name.as_str());
                return Err(io_error(program, at.line, name, &e));
            }
        };
        if !more {
            return Ok(None);
        }
        if at.pos == 0 && self.buf.starts_with(b"\xEF\xBB\xBF") {
            // A UTF-8 byte-order mark before the first line: not text.
            self.buf.drain(..3);
        }
        self.blocks += 1;
        frame.cur = at;
        frame.cur_span = text_span(&self.buf);
        frame.next = LinePos {
            pos: frame.text.position(),
            line: at.line.saturating_add(1),
        };
        let next = frame.next;
        let skipped = skipped(&self.buf, self.options.skip_levels);
        let parsed = match text::substitute(&self.buf, &self.macros) {
            Some(text) => parse_line(&text, at.line),
            None => parse_line(&self.buf, at.line),
        };
        let frame = &mut self.frames[top];
        if at.pos >= frame.high_water.pos {
            if let Ok(Line {
                label: Some(label), ..
            }) = &parsed
            {
                frame.labels.entry(label.text.clone()).or_default().push(at);
            }
            frame.high_water = next;
        }
        Ok(Some(ReadLine {
            at,
            skipped,
            parsed,
        }))
    }

    fn run(&mut self, sys: &mut dyn System, out: &mut Executed) -> Result<Step, LangError> {
        loop {
            if let Some(p) = self.top_mut().pending.pop_front() {
                if self.pending(p)? {
                    return Ok(Step::End);
                }
                continue;
            }
            let Some(read) = self.read_line()? else {
                // The end of the text.
                if !self.top().sections.is_empty() {
                    self.section_end()?;
                    continue;
                }
                if self.ret()? {
                    return Ok(Step::End);
                }
                continue;
            };
            let (label, number) = match &read.parsed {
                Ok(line) => (
                    line.label.as_ref().map(|l| l.text.clone()),
                    line.number.map(|n| n.value),
                ),
                Err(_) => (None, None),
            };
            let yielded = if read.skipped {
                false
            } else {
                self.line_text.clear();
                self.line_text.extend_from_slice(&self.buf);
                let program = self.top().program;
                let line = read.parsed.map_err(|e| parse_error(program, e))?;
                self.execute(line, read.at, sys, out)?
            };
            self.check_section_end(label.as_deref(), number);
            if yielded {
                return Ok(Step::Block);
            }
        }
    }

    /// Carries out work left after a block; `true` when the program ends.
    fn pending(&mut self, p: Pending) -> Result<bool, LangError> {
        match p {
            Pending::Call(spec) => self.push_call(spec)?,
            Pending::Jump(j) => self.jump(&j)?,
            Pending::Section(start, end, span) => self.call_block(&start, end, span)?,
            Pending::SectionEnd => self.section_end()?,
            Pending::Return => return self.ret(),
            Pending::End => return Ok(true),
        }
        Ok(false)
    }

    fn check_section_end(&mut self, label: Option<&str>, number: Option<u32>) {
        let top = self.top_mut();
        let Some(section) = top.sections.last() else {
            return;
        };
        let ends = match &section.end {
            None => true,
            Some(JumpTarget::Label(name)) => label == Some(name.text.as_str()),
            Some(JumpTarget::Block(n, _)) => number == Some(*n),
        };
        let busy = top
            .pending
            .iter()
            .any(|p| matches!(p, Pending::Jump(_) | Pending::Return | Pending::End));
        if ends && !busy {
            top.pending.push_back(Pending::SectionEnd);
        }
    }

    fn section_end(&mut self) -> Result<(), LangError> {
        let top = self.top_mut();
        let Some(section) = top.sections.pop() else {
            return Ok(());
        };
        top.structures.truncate(section.structures);
        self.seek(section.back)
    }

    /// `RET`, `M17`, the end of a program's text: the next pass, back to
    /// the caller, or (the main program) the end; `true` at the end.
    fn ret(&mut self) -> Result<bool, LangError> {
        if self.frames.len() == 1 {
            return Ok(true);
        }
        let level = self.level();
        if self.top().passes_left > 1 {
            // A new pass counts as a line read: an empty program run many
            // times still uses up the budget.
            self.charge()?;
            let top = self.top_mut();
            top.passes_left -= 1;
            top.structures.clear();
            top.sections.clear();
            top.pending.clear();
            top.started = false;
            top.modal = None;
            if let Some(l) = self.vars.levels.get_mut(level) {
                l.clear();
            }
            self.seek(LinePos::START)?;
            return Ok(false);
        }
        self.frames.pop();
        self.vars.levels.truncate(self.frames.len());
        Ok(false)
    }

    fn program_number(&mut self, name: &str) -> usize {
        if let Some(&n) = self.by_name.get(name) {
            return n;
        }
        let n = self.programs.len();
        self.programs.push(ProgramInfo {
            name: name.to_string(),
        });
        self.by_name.insert(name.to_string(), n);
        n
    }

    fn push_call(&mut self, spec: CallSpec) -> Result<(), LangError> {
        if self.frames.len() >= MAX_LEVELS {
            return Err(self.error(
                None,
                self.line_span(),
                format!(
                    "calling {} would nest more than {MAX_LEVELS} program levels",
                    spec.name
                ),
            ));
        }
        let program = self.program_number(&spec.name);
        self.frames.push(CallFrame {
            program,
            text: spec.text,
            labels: HashMap::new(),
            high_water: LinePos::START,
            cur: LinePos::START,
            cur_span: Span::new(1, 1),
            next: LinePos::START,
            structures: Vec::new(),
            sections: Vec::new(),
            pending: VecDeque::new(),
            passes_left: spec.passes.max(1),
            args: spec.args,
            started: false,
            modal: None,
        });
        self.vars.levels.push(HashMap::new());
        Ok(())
    }

    /// Opens program `name` of the store: `None` when the store has none.
    fn open(&mut self, name: &str, span: Span) -> Result<Option<Box<dyn ProgramText>>, LangError> {
        self.store
            .open(name)
            .map_err(|e| self.error(None, span, format!("program {name} cannot be read: {e}")))
    }

    /// Runs one line; `true` when it wrote a block to `out`.
    fn execute(
        &mut self,
        line: Line,
        at: LinePos,
        sys: &mut dyn System,
        out: &mut Executed,
    ) -> Result<bool, LangError> {
        let first = !self.top().started
            && !matches!(
                line.statement,
                Statement::Empty | Statement::ProgramHeader(_) | Statement::PathHeader(_)
            );
        if first {
            self.top_mut().started = true;
            let has_args = self.top().args.iter().any(Option::is_some);
            if has_args && !matches!(line.statement, Statement::Proc(_)) {
                return Err(self.error(
                    Some(ALARM_SYNTAX),
                    self.line_span(),
                    format!(
                        "program {} is called with arguments but does not begin with PROC",
                        self.program_name(self.top().program)
                    ),
                ));
            }
        }
        let meta = line_meta(&line);
        match line.statement {
            Statement::Empty | Statement::ProgramHeader(_) | Statement::PathHeader(_) => Ok(false),
            Statement::Proc(proc) => {
                if !first {
                    return Err(self.error(
                        Some(ALARM_SYNTAX),
                        proc.name.span,
                        "PROC must be the first statement of a program".to_string(),
                    ));
                }
                if self.frames.len() > 1 {
                    self.bind(&proc)?;
                }
                Ok(false)
            }
            Statement::Def(def) => {
                self.define(&def, false, sys).map_err(|f| self.fault(f))?;
                Ok(false)
            }
            Statement::Define { name, text } => {
                self.macros.insert(name.text, text);
                Ok(false)
            }
            Statement::Block(items) => self.block(&meta, items, sys, out),
            Statement::SyncAction(_) => {
                let program = self.top().program;
                let place = if program == 0 {
                    format!("line {}", at.line)
                } else {
                    format!("line {} of {}", at.line, self.program_name(program))
                };
                self.note(format!("{place}: synchronized action read, not simulated"));
                Ok(false)
            }
            other => {
                self.flow(other, at, sys)?;
                Ok(false)
            }
        }
    }

    /// Binds the arguments of the call to the parameters of `PROC`.
    fn bind(&mut self, proc: &Proc) -> Result<(), LangError> {
        let level = self.level();
        let args = self.top().args.clone();
        if args.len() > proc.params.len() {
            return Err(self.error(
                Some(ALARM_SYNTAX),
                proc.name.span,
                format!(
                    "{} takes {} parameter(s), {} argument(s) given",
                    proc.name.text,
                    proc.params.len(),
                    args.len()
                ),
            ));
        }
        for (k, param) in proc.params.iter().enumerate() {
            let arg = args.get(k).cloned().flatten();
            let slot = if param.by_reference {
                match arg {
                    Some(Arg {
                        place: Some(place), ..
                    }) => Slot::Alias(place),
                    Some(arg) => {
                        return Err(self.fault_at(
                            Fault::new(
                                Some(vars::ALARM_UNDEFINED),
                                arg.span,
                                format!(
                                    "argument {} for VAR parameter {} is not a variable",
                                    k + 1,
                                    param.name.text
                                ),
                            ),
                            self.frames[level - 1].program,
                            self.frames[level - 1].cur.line,
                        ));
                    }
                    None => Slot::Own(Variable::new(param.ty, Vec::new())),
                }
            } else {
                if !param.dims.is_empty() {
                    return Err(self.error(
                        Some(ALARM_SYNTAX),
                        param.name.span,
                        format!("array parameter {} must be VAR", param.name.text),
                    ));
                }
                let mut var = Variable::new(param.ty, Vec::new());
                if let Some(arg) = arg {
                    let caller = (
                        self.frames[level - 1].program,
                        self.frames[level - 1].cur.line,
                    );
                    let value = arg
                        .value
                        .map_err(|f| self.fault_at(f, caller.0, caller.1))?;
                    let value = convert(value, param.ty, arg.span)
                        .map_err(|f| self.fault_at(f, caller.0, caller.1))?;
                    var.data[0] = value;
                }
                Slot::Own(var)
            };
            self.vars.define_local(level, &param.name.text, slot);
        }
        Ok(())
    }

    /// `DEF`: each variable defined with its initial value.
    fn define(&mut self, def: &Def, global: bool, sys: &mut dyn System) -> Result<(), Fault> {
        let global = global || def.scope.is_some();
        let level = self.level();
        for d in &def.vars {
            if d.dims.len() > 2 {
                return Err(Fault::new(
                    Some(ALARM_SYNTAX),
                    d.name.span,
                    "arrays have at most 2 dimensions".to_string(),
                ));
            }
            let mut ctx = self.ctx(sys);
            let mut dims = Vec::with_capacity(d.dims.len());
            for e in &d.dims {
                let v = ctx.eval(e)?;
                let n = v.as_f64().unwrap_or(-1.0).round();
                if !(1.0..=MAX_ELEMENTS as f64).contains(&n) {
                    return Err(Fault::new(
                        Some(ALARM_INDEX_1),
                        e.span,
                        format!("array dimension {} not allowed", eval::text_of(&v)),
                    ));
                }
                dims.push(n as usize);
            }
            if dims.iter().product::<usize>() > MAX_ELEMENTS {
                return Err(Fault::new(
                    Some(ALARM_INDEX_1),
                    d.name.span,
                    format!("array {} too large", d.name.text),
                ));
            }
            let mut var = Variable::new(def.ty, dims);
            match &d.init {
                None => {}
                Some(Init::Value(e)) | Some(Init::Rep(e)) => {
                    let v = convert(ctx.eval(e)?, def.ty, e.span)?;
                    var.data.iter_mut().for_each(|x| *x = v.clone());
                }
                Some(Init::Set(list)) => {
                    if list.len() > var.data.len() {
                        return Err(Fault::new(
                            Some(ALARM_INDEX_1),
                            d.name.span,
                            format!(
                                "SET gives {} values for {} elements",
                                list.len(),
                                var.data.len()
                            ),
                        ));
                    }
                    for (k, e) in list.iter().enumerate() {
                        var.data[k] = convert(ctx.eval(e)?, def.ty, e.span)?;
                    }
                }
            }
            if global {
                if def.scope.is_none() || !self.vars.globals.contains_key(&d.name.text) {
                    self.vars.globals.insert(d.name.text.clone(), var);
                }
            } else {
                self.vars.define_local(level, &d.name.text, Slot::Own(var));
            }
        }
        Ok(())
    }

    /// The arguments of a call as the callee will bind them.
    fn call_args(
        &mut self,
        args: Option<&Vec<Option<crate::Expr>>>,
        sys: &mut dyn System,
    ) -> Result<Vec<Option<Arg>>, LangError> {
        let Some(args) = args else {
            return Ok(Vec::new());
        };
        let mut out = Vec::with_capacity(args.len());
        for a in args {
            let Some(e) = a else {
                out.push(None);
                continue;
            };
            let mut ctx = self.ctx(sys);
            let arg = if let ExprKind::Var(v) = &e.kind
                && let Some(place) = ctx.place(v).map_err(|f| self.fault(f))?
            {
                let mut ctx = self.ctx(sys);
                Arg {
                    value: ctx.read_place(&place, e.span),
                    place: Some(place),
                    span: e.span,
                }
            } else {
                let mut ctx = self.ctx(sys);
                Arg {
                    value: Ok(ctx.eval(e).map_err(|f| self.fault(f))?),
                    place: None,
                    span: e.span,
                }
            };
            out.push(Some(arg));
        }
        Ok(out)
    }

    /// The arguments of an instruction for the front end: a bare name
    /// that is no variable passes as an axis (`FGROUP(X,Y,Z)`).
    fn instruction_args(
        &mut self,
        args: Option<&Vec<Option<crate::Expr>>>,
        sys: &mut dyn System,
    ) -> Result<Option<Vec<Option<Value>>>, LangError> {
        let Some(args) = args else {
            return Ok(None);
        };
        let mut out = Vec::with_capacity(args.len());
        for a in args {
            match a {
                None => out.push(None),
                Some(e) => {
                    let v = self.ctx(sys).loose(e).map_err(|f| self.fault(f))?;
                    out.push(Some(v));
                }
            }
        }
        Ok(Some(out))
    }

    /// The number of passes `P n`.
    fn passes(&mut self, call: &Call, sys: &mut dyn System) -> Result<u64, LangError> {
        let Some(e) = &call.passes else {
            return Ok(1);
        };
        let v = self.ctx(sys).eval(e).map_err(|f| self.fault(f))?;
        let n = v.as_f64().unwrap_or(0.0).round();
        if !(1.0..=MAX_PASSES as f64).contains(&n) {
            return Err(self.error(
                Some(ALARM_SYNTAX),
                e.span,
                format!("number of passes {} not allowed", eval::text_of(&v)),
            ));
        }
        Ok(n as u64)
    }

    /// A block of words, assignments, calls and jumps.
    fn block(
        &mut self,
        meta: &Meta,
        items: Vec<Item>,
        sys: &mut dyn System,
        out: &mut Executed,
    ) -> Result<bool, LangError> {
        let modal_before = self.top().modal.is_some();
        let mut moved_axis = false;
        let mut calls: Vec<Pending> = Vec::new();
        let mut jump: Option<Pending> = None;
        let mut ret = false;
        let mut end = false;
        let mut actions = Vec::new();
        let mut items = items.into_iter().peekable();
        while let Some(item) = items.next() {
            match item {
                Item::Word(w) => {
                    let value = self.ctx(sys).eval(&w.value).map_err(|f| self.fault(f))?;
                    if w.equals
                        && w.mode.is_none()
                        && let Some(place) = self.vars.resolve_user(self.level(), &w.address)
                    {
                        // A user variable named like an address (`DEF INT I`,
                        // `DEF FRAME F`): `I=5` assigns it.
                        self.ctx(sys)
                            .write_place(&place, value, w.span)
                            .map_err(|f| self.fault(f))?;
                        continue;
                    }
                    if w.address == "M" {
                        let code = value.as_f64().unwrap_or(-1.0);
                        if code == 17.0 {
                            ret = true;
                            continue;
                        }
                        if code == 2.0 || code == 30.0 {
                            end = true;
                        }
                    }
                    if sys.is_axis(&w.address) {
                        moved_axis = true;
                    }
                    actions.push(Action::Word {
                        address: w.address,
                        value,
                        mode: w.mode,
                        span: w.span,
                    });
                }
                Item::Assign(a) => {
                    if let Some(action) = self.assign(&a, sys)? {
                        actions.push(action);
                    }
                }
                Item::Call(c) => match c.kind {
                    CallKind::GFunction
                    | CallKind::Frame
                    | CallKind::Transformation
                    | CallKind::Suppress => {
                        let args = self.instruction_args(c.args.as_ref(), sys)?;
                        actions.push(Action::Instruction {
                            name: c.name,
                            args,
                            span: c.span,
                        });
                    }
                    CallKind::Procedure => match c.name.as_str() {
                        "STOPRE" => {}
                        "RET" => ret = true,
                        "EXTCALL" => calls.push(self.extcall(&c, sys)?),
                        _ => {
                            let args = self.instruction_args(c.args.as_ref(), sys)?;
                            actions.push(Action::Instruction {
                                name: c.name,
                                args,
                                span: c.span,
                            });
                        }
                    },
                    CallKind::Cycle | CallKind::User => {
                        if let Some(text) = self.open(&c.name, c.span)? {
                            let args = self.call_args(c.args.as_ref(), sys)?;
                            let mut c = c;
                            // `L100 P=R2`: a P word right after the call
                            // is its number of passes too.
                            if c.passes.is_none()
                                && let Some(Item::Word(w)) = items.peek()
                                && w.address == "P"
                            {
                                c.passes = Some(w.value.clone());
                                items.next();
                            }
                            let passes = self.passes(&c, sys)?;
                            calls.push(Pending::Call(CallSpec {
                                name: c.name,
                                text,
                                args,
                                passes,
                            }));
                        } else if sys.is_builtin(&c.name) {
                            let args = self.instruction_args(c.args.as_ref(), sys)?;
                            actions.push(Action::Instruction {
                                name: c.name,
                                args,
                                span: c.span,
                            });
                        } else {
                            return Err(self.not_available(&c.name, c.span));
                        }
                    }
                },
                Item::ModalCall { call, span } => {
                    if let Some(action) = self.modal_call(call, span, sys)? {
                        actions.push(action);
                    }
                }
                Item::IndirectCall(ic) => {
                    if let Some((start, end)) = ic.section {
                        if ic.program.is_some() {
                            return Err(self.error(
                                None,
                                ic.span,
                                "CALL of a section of another program is not supported".to_string(),
                            ));
                        }
                        jump = Some(Pending::Section(start, end, ic.span));
                    } else if let Some(e) = ic.program {
                        let v = self.ctx(sys).eval(&e).map_err(|f| self.fault(f))?;
                        let name = match v {
                            Value::Str(s) | Value::Axis(s) => program_name_of(&s),
                            other => {
                                return Err(self.error(
                                    Some(ALARM_CONVERSION),
                                    e.span,
                                    format!(
                                        "CALL takes a program name, not {}",
                                        eval::type_name(&other)
                                    ),
                                ));
                            }
                        };
                        if let Some(text) = self.open(&name, ic.span)? {
                            calls.push(Pending::Call(CallSpec {
                                name,
                                text,
                                args: Vec::new(),
                                passes: 1,
                            }));
                        } else if sys.is_builtin(&name) {
                            actions.push(Action::Instruction {
                                name,
                                args: None,
                                span: ic.span,
                            });
                        } else {
                            return Err(self.not_available(&name, ic.span));
                        }
                    }
                }
                Item::Jump(j) => jump = Some(Pending::Jump(j)),
            }
        }
        let modal = self.top().modal.clone();
        let top = self.frames.len() - 1;
        if modal_before
            && moved_axis
            && let Some(m) = modal
        {
            let span = m.span;
            match self.open(&m.name, span)? {
                Some(text) => self.frames[top].pending.push_back(Pending::Call(CallSpec {
                    name: m.name,
                    text,
                    args: m.args,
                    passes: 1,
                })),
                None => return Err(self.not_available(&m.name, span)),
            }
        }
        let frame = &mut self.frames[top];
        frame.pending.extend(calls);
        frame.pending.extend(jump);
        if ret {
            frame.pending.push_back(Pending::Return);
        }
        if end {
            frame.pending.push_back(Pending::End);
        }
        if actions.is_empty() {
            return Ok(false);
        }
        out.line = meta.line;
        out.program = frame.program;
        out.number = meta.number;
        out.comment = meta.comment.clone();
        out.actions = actions;
        Ok(true)
    }

    fn not_available(&self, name: &str, span: Span) -> LangError {
        self.error(
            Some(ALARM_NOT_AVAILABLE),
            span,
            format!("program {name} not available"),
        )
    }

    /// `EXTCALL("NAME")`.
    fn extcall(&mut self, c: &Call, sys: &mut dyn System) -> Result<Pending, LangError> {
        let Some(Some(e)) = c.args.as_ref().and_then(|a| a.first()) else {
            return Err(self.error(
                Some(ALARM_SYNTAX),
                c.span,
                "EXTCALL needs the program's name".to_string(),
            ));
        };
        let v = self.ctx(sys).eval(e).map_err(|f| self.fault(f))?;
        let Value::Str(s) = v else {
            return Err(self.error(
                Some(ALARM_CONVERSION),
                e.span,
                format!("EXTCALL takes a STRING, not {}", eval::type_name(&v)),
            ));
        };
        let name = program_name_of(&s);
        match self.open(&name, c.span)? {
            Some(text) => Ok(Pending::Call(CallSpec {
                name,
                text,
                args: Vec::new(),
                passes: 1,
            })),
            None => Err(self.not_available(&name, c.span)),
        }
    }

    /// `MCALL name(…)` or a bare `MCALL`.
    fn modal_call(
        &mut self,
        call: Option<Call>,
        span: Span,
        sys: &mut dyn System,
    ) -> Result<Option<Action>, LangError> {
        let Some(call) = call else {
            if self.top_mut().modal.take().is_some() {
                return Ok(None);
            }
            return Ok(Some(Action::ModalCall { call: None, span }));
        };
        if self.open(&call.name, call.span)?.is_some() {
            let args = self.call_args(call.args.as_ref(), sys)?;
            self.top_mut().modal = Some(ModalSub {
                name: call.name,
                args,
                span,
            });
            return Ok(None);
        }
        self.top_mut().modal = None;
        let args = self
            .instruction_args(call.args.as_ref(), sys)?
            .unwrap_or_default();
        Ok(Some(Action::ModalCall {
            call: Some((call.name, args)),
            span,
        }))
    }

    /// An assignment; a word when the target is an address with an axis
    /// index (`POS[X]=10`).
    fn assign(
        &mut self,
        a: &crate::Assign,
        sys: &mut dyn System,
    ) -> Result<Option<Action>, LangError> {
        let value = self.ctx(sys).eval(&a.value).map_err(|f| self.fault(f))?;
        let target = &a.target;
        let mut ctx = self.ctx(sys);
        let place = ctx.place(target).map_err(|f| self.fault(f))?;
        match place {
            Some(place) => {
                let mut ctx = self.ctx(sys);
                ctx.write_place(&place, value, target.span)
                    .map_err(|f| self.fault(f))?;
                Ok(None)
            }
            None if !target.indices.is_empty() && indexed_address(&target.name) => {
                let mut idx = Vec::new();
                for e in &target.indices {
                    let v = self.ctx(sys).loose(e).map_err(|f| self.fault(f))?;
                    idx.push(eval::text_of(&v));
                }
                Ok(Some(Action::Word {
                    address: format!("{}[{}]", target.name, idx.join(",")),
                    value,
                    mode: None,
                    span: a.span,
                }))
            }
            None => Err(self.error(
                Some(vars::ALARM_UNDEFINED),
                target.span,
                format!("name {} not defined", target.name),
            )),
        }
    }

    /// Evaluates a condition on the line being run.
    fn condition(&mut self, e: &crate::Expr, sys: &mut dyn System) -> Result<bool, LangError> {
        let v = self.ctx(sys).eval(e).map_err(|f| self.fault(f))?;
        truth(&v, e.span).map_err(|f| self.fault(f))
    }

    fn eval(&mut self, e: &crate::Expr, sys: &mut dyn System) -> Result<Value, LangError> {
        self.ctx(sys).eval(e).map_err(|f| self.fault(f))
    }

    fn read_var(&mut self, v: &Var, sys: &mut dyn System) -> Result<Value, LangError> {
        self.ctx(sys).read_var(v).map_err(|f| self.fault(f))
    }

    fn write_var(&mut self, v: &Var, value: Value, sys: &mut dyn System) -> Result<(), LangError> {
        self.ctx(sys).assign(v, value).map_err(|f| self.fault(f))
    }
}

/// What a yielded block takes from its line.
struct Meta {
    line: u32,
    number: Option<u32>,
    comment: Option<String>,
}

fn line_meta(line: &Line) -> Meta {
    Meta {
        line: line.line,
        number: line.number.map(|n| n.value),
        comment: line.comment.as_ref().map(|c| c.text.clone()),
    }
}

/// A program name from a string: upper-cased, the last part of a path.
fn program_name_of(s: &str) -> String {
    let s = s.trim();
    let last = s.rsplit(['/', '\\']).next().unwrap_or(s);
    last.to_ascii_uppercase()
}
