//! The interpreter: runs the language of a Klartext program and yields
//! each block that reaches the control as an [`Executed`] block.
//!
//! # Design
//!
//! **Streaming.** Programs are read line by line through
//! [`ProgramText`]; a block of several lines (`~` at the end of a line)
//! is joined and read with [`parse_block`] into a [`Block`] that is
//! reused, as are the line buffers and the caller's [`Executed`]: a plain
//! `L` block allocates nothing once the buffers have grown.
//!
//! **Labels.** Per program level the interpreter keeps the positions of
//! the `LBL` lines read so far and the furthest position read. A label
//! not yet seen is searched by reading on from there to the end of the
//! text (remembering every label on the way), then the reader seeks back.
//! Labels are unique per program (TNC), so the whole program is searched.
//!
//! **Calls.** `CALL LBL n` (no `REP`) is a subprogram call: the position
//! after the call is kept, the program goes on at `LBL n`, and the next
//! `LBL 0` returns. `LBL 0` outside a call is ignored, as is `LBL n` in
//! the normal flow. `CALL LBL n REP k` is a program-section repeat: the
//! program goes back to `LBL n` k more times (the section runs k + 1
//! times); the count is kept per call site and reset when done.
//! `CALL PGM name` opens the program through [`ProgramStore`] and runs it
//! to its `END PGM` (or the end of its text); `Q`, `QR` and `QS`
//! parameters are shared, `QL` parameters belong to each call.
//!
//! # Decisions where the manuals were silent or not found
//!
//! * Nesting (subprogram calls and program calls together) is limited
//!   to [`MAX_NESTING`] levels (UNVERIFIED for current controls; the
//!   TNC 370 manual p6-9 gives 8 for subprograms and 4 for program
//!   calls). Section repeats do not nest: they are jumps back.
//! * Parameter ranges: `Q0`–`Q1999` (TNC 620 manual 340 56x-02 p225),
//!   `QL0`–`QL499` local to each program level, `QR0`–`QR499` (TNC 128
//!   manual 77184x-01 p181), `QS0`–`QS1999`. `QR` values live as long as
//!   the interpreter (no power-off memory here).
//! * String functions (TNC7 basic online documentation, "String
//!   functions"): `||`, `TOCHAR`, `SUBSTR`, `TONUMB`, `STRLEN` and
//!   `DECLARE STRING`; an optional `STRF` after `QSn =` (the brief's
//!   spelling of a string formula) is accepted. `INSTR`, `STRCOMP`,
//!   `SYSSTR` and `CFGREAD` are not supported (a syntax error).
//! * `FN 15: PRINT` (iTNC 530) and `FN 16: F-PRINT` only add a note with
//!   their text; nothing is written to a file.
//! * Spans of a block joined from several lines are columns of the
//!   joined text (the first line's columns are exact).
//! * `M2` / `M30` end the whole program after their block was yielded,
//!   also in a called program.
//! * `FN 9` – `FN 12` compare values exactly.
//! * `FN 13` gives `atan2(second, first)` in degrees, 0 ≤ angle < 360
//!   (TNC 640 manual 10/2017 p384 names the function, not the order of
//!   the sides: UNVERIFIED).
//! * `SGN` gives 1 for values ≥ 0 and −1 below (TNC 620 ISO manual
//!   340 56x-03 p242).
//! * Division by zero, roots and logarithms outside their domain, and
//!   any result that is not a finite number are arithmetic errors.
//! * `TOOL CALL 5.2` (a tool with an index) gives tool 5.
//! * `TOCHAR` without `DECIMALS` writes the shortest form of the number;
//!   `SUBSTR` counts characters from 0.
//! * A `/` block is skipped (unparsed) when [`Options::block_skip`] is
//!   set; labels on skipped lines are still found.
//! * Comment-only lines and `*` headings count as blocks for the budget
//!   ([`Options::max_blocks`]) but are not yielded; the lines read by a
//!   label search do not count.
//! * A program ends at `END PGM` or at the end of its text.

use std::collections::HashMap;

use fiveaxis_gcode::Span;

use crate::parse::{
    Block, Body, Compare, FnOp, Func, Item, Label, Node, Op, Operand, Q_MAX, QKind, QL_MAX, QRef,
    QS_MAX, ToolRef, parse_block, split_comment,
};
use crate::{
    Executed, Key, LangError, LangErrorKind, PatternItem, ProgramStore, ProgramText, Step, System,
    Tool, Value, Word,
};

/// Nesting of subprogram and program calls (UNVERIFIED, see the module
/// documentation).
pub const MAX_NESTING: usize = 19;
/// The most notes kept ([`Interpreter::notes`]).
pub const MAX_NOTES: usize = 100;

/// How the interpreter runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    /// `/` blocks are skipped when true.
    pub block_skip: bool,
    /// Blocks run before the program counts as a runaway (every block
    /// counts, language-only ones too); 0 = no limit.
    pub max_blocks: u64,
}

impl Default for Options {
    /// Block skip off, a budget of 50 million blocks.
    fn default() -> Self {
        Self {
            block_skip: false,
            max_blocks: 50_000_000,
        }
    }
}

/// One program level: a program's text and what belongs to it.
struct Frame<'a> {
    text: Box<dyn ProgramText + 'a>,
    program: usize,
    /// The line number of the next line read.
    next_line: u32,
    /// Labels seen: the offset and line of their `LBL` line.
    labels: HashMap<Label, (u64, u32)>,
    /// The furthest position indexed for labels, and its line.
    scanned: (u64, u32),
    /// Local parameters `QL0`–`QL499`.
    ql: Vec<f64>,
    /// Where `LBL 0` returns to (subprogram calls).
    returns: Vec<(u64, u32)>,
    /// Repeats left per `CALL LBL … REP` call site (its offset).
    reps: HashMap<u64, u32>,
}

impl<'a> Frame<'a> {
    fn new(text: Box<dyn ProgramText + 'a>, program: usize) -> Self {
        let start = text.position();
        Self {
            text,
            program,
            next_line: 1,
            labels: HashMap::new(),
            scanned: (start, 1),
            ql: vec![0.0; QL_MAX as usize + 1],
            returns: Vec::new(),
            reps: HashMap::new(),
        }
    }
}

/// The Klartext interpreter over a main program and a program store.
pub struct Interpreter<'a> {
    store: Box<dyn ProgramStore + 'a>,
    options: Options,
    frames: Vec<Frame<'a>>,
    names: Vec<String>,
    q: Vec<f64>,
    qr: Vec<f64>,
    qs: Vec<String>,
    /// The first line of the block last read.
    first: Vec<u8>,
    /// A continuation line.
    more: Vec<u8>,
    /// The block's code, lines joined.
    code: Vec<u8>,
    /// The block's comment (first line).
    comment: Vec<u8>,
    block: Block,
    values: Vec<Value>,
    blocks: u64,
    notes: Vec<String>,
    inch: bool,
    ended: bool,
    end_pending: bool,
    line: u32,
    program: usize,
}

impl std::fmt::Debug for Interpreter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Interpreter")
            .field("options", &self.options)
            .field("levels", &self.frames.len())
            .field("names", &self.names)
            .field("blocks", &self.blocks)
            .field("line", &self.line)
            .finish_non_exhaustive()
    }
}

/// What a block of the language asks for after it ran.
enum Flow {
    Next,
    Yield,
    End,
}

impl<'a> Interpreter<'a> {
    /// An interpreter of `main`, calling programs of `store`.
    ///
    /// # Errors
    ///
    /// None today; the signature leaves room for a check of the start.
    pub fn new(
        main: Box<dyn ProgramText + 'a>,
        store: Box<dyn ProgramStore + 'a>,
        options: Options,
    ) -> Result<Self, LangError> {
        Ok(Self {
            store,
            options,
            frames: vec![Frame::new(main, 0)],
            names: vec![String::new()],
            q: vec![0.0; Q_MAX as usize + 1],
            qr: vec![0.0; QL_MAX as usize + 1],
            qs: vec![String::new(); QS_MAX as usize + 1],
            first: Vec::new(),
            more: Vec::new(),
            code: Vec::new(),
            comment: Vec::new(),
            block: Block::default(),
            values: Vec::new(),
            blocks: 0,
            notes: Vec::new(),
            inch: false,
            ended: false,
            end_pending: false,
            line: 0,
            program: 0,
        })
    }

    /// The value of `Q n` (0 when unset or out of range).
    pub fn q(&self, n: u32) -> f64 {
        self.q.get(n as usize).copied().unwrap_or(0.0)
    }

    /// Sets `Q n` (the control writes Q parameters: `PLANE … STAY` gives
    /// Q120–Q122). Numbers out of range are ignored.
    pub fn set_q(&mut self, n: u32, v: f64) {
        if let Some(q) = self.q.get_mut(n as usize) {
            *q = v;
        }
    }

    /// The value of `QR n` (0 when unset or out of range).
    pub fn qr(&self, n: u32) -> f64 {
        self.qr.get(n as usize).copied().unwrap_or(0.0)
    }

    /// The value of `QL n` of the running program level.
    pub fn ql(&self, n: u32) -> f64 {
        self.frames
            .last()
            .and_then(|f| f.ql.get(n as usize).copied())
            .unwrap_or(0.0)
    }

    /// The text of `QS n` (empty when unset or out of range).
    pub fn qs(&self, n: u32) -> &str {
        self.qs.get(n as usize).map_or("", String::as_str)
    }

    /// The name of program `program`: 0 the main program (its `BEGIN PGM`
    /// name, empty before that line), else the file name `CALL PGM`
    /// gave, upper-cased, without path and `.H` (every call of one
    /// program has one number).
    pub fn program_name(&self, program: usize) -> &str {
        self.names.get(program).map_or("", String::as_str)
    }

    /// Whether the main program is in inches (`BEGIN PGM … INCH`); the
    /// language does not convert values.
    pub fn inch(&self) -> bool {
        self.inch
    }

    /// The text of the block last read (its first line).
    pub fn line_text(&self) -> &[u8] {
        &self.first
    }

    /// Blocks run so far.
    pub fn blocks(&self) -> u64 {
        self.blocks
    }

    /// `FN 15` / `FN 16` prints and other notes (at most [`MAX_NOTES`]).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    fn note(&mut self, s: String) {
        if self.notes.len() < MAX_NOTES {
            self.notes.push(s);
        }
    }

    /// The columns of the first line's code.
    fn line_span(&self) -> Span {
        let (code, _) = split_comment(&self.first);
        let start = code
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .unwrap_or(0);
        let end = code
            .iter()
            .rposition(|b| !b.is_ascii_whitespace() && *b != b'~')
            .map_or(start + 1, |e| e + 1);
        Span::new(
            u32::try_from(start + 1).unwrap_or(u32::MAX),
            u32::try_from(end.max(start + 1) + 1).unwrap_or(u32::MAX),
        )
    }

    fn error(&self, kind: LangErrorKind, message: impl Into<String>) -> LangError {
        LangError {
            kind,
            program: self.program,
            line: self.line,
            span: self.line_span(),
            message: message.into(),
        }
    }

    fn io_error(&self, e: &std::io::Error) -> LangError {
        self.error(
            LangErrorKind::Syntax,
            format!("the program cannot be read: {e}"),
        )
    }

    /// Reads one line of the running program into `buf`, indexing a
    /// label on it. `Ok(None)` at the end of the text.
    fn read_line(frame: &mut Frame<'a>, buf: &mut Vec<u8>) -> std::io::Result<Option<u32>> {
        let pos = frame.text.position();
        if !frame.text.read_line(buf)? {
            return Ok(None);
        }
        let line = frame.next_line;
        frame.next_line = frame.next_line.saturating_add(1);
        if pos >= frame.scanned.0 {
            if let Some(l) = label_on(buf) {
                frame.labels.entry(l).or_insert((pos, line));
            }
            frame.scanned = (frame.text.position(), frame.next_line);
        }
        Ok(Some(line))
    }

    /// Reads the next block (its lines joined) into `code`. The offset of
    /// its first line, or `None` at the end of the text.
    fn read_block(&mut self) -> Result<Option<u64>, LangError> {
        let Some(frame) = self.frames.last_mut() else {
            return Ok(None);
        };
        let pos = frame.text.position();
        let line = match Self::read_line(frame, &mut self.first) {
            Ok(Some(l)) => l,
            Ok(None) => return Ok(None),
            Err(e) => return Err(self.io_error(&e)),
        };
        self.line = line;
        self.program = frame.program;
        self.blocks += 1;
        let (code, comment) = split_comment(&self.first);
        self.code.clear();
        self.code.extend_from_slice(code);
        self.comment.clear();
        if let Some(c) = comment {
            self.comment.extend_from_slice(c);
        }
        let mut cont = ends_in_tilde(&self.first);
        while cont {
            match Self::read_line(frame, &mut self.more) {
                Ok(Some(_)) => {}
                Ok(None) => break,
                Err(e) => {
                    let e = self.io_error(&e);
                    return Err(e);
                }
            }
            let (code, _) = split_comment(&self.more);
            self.code.push(b' ');
            self.code.extend_from_slice(code);
            cont = ends_in_tilde(&self.more);
        }
        for b in &mut self.code {
            if *b == b'~' {
                *b = b' ';
            }
        }
        if self.options.max_blocks > 0 && self.blocks > self.options.max_blocks {
            return Err(self.error(
                LangErrorKind::Budget,
                format!(
                    "the block budget of {} blocks ran out (a runaway program?)",
                    self.options.max_blocks
                ),
            ));
        }
        Ok(Some(pos))
    }

    /// Runs the language up to the next block for the control and writes
    /// it to `out` (cleared first, its buffers reused).
    ///
    /// # Errors
    ///
    /// A block that cannot be read, a language error (missing label or
    /// program, arithmetic, `FN 14`, nesting, budget) with its line.
    pub fn next_block(
        &mut self,
        sys: &mut dyn System,
        out: &mut Executed,
    ) -> Result<Step, LangError> {
        if self.ended {
            return Ok(Step::End);
        }
        if self.end_pending {
            self.ended = true;
            return Ok(Step::End);
        }
        loop {
            let Some(pos) = self.read_block()? else {
                if self.frames.len() <= 1 {
                    self.ended = true;
                    return Ok(Step::End);
                }
                self.frames.pop();
                continue;
            };
            let mut block = std::mem::take(&mut self.block);
            let r = match parse_block(&self.code, &mut block) {
                Ok(()) => self.run(&mut block, pos, sys, out),
                Err(e) => Err(LangError {
                    kind: e.kind,
                    program: self.program,
                    line: self.line,
                    span: e.span,
                    message: e.message,
                }),
            };
            self.block = block;
            match r? {
                Flow::Next => {}
                Flow::Yield => return Ok(Step::Block),
                Flow::End => {
                    self.ended = true;
                    return Ok(Step::End);
                }
            }
        }
    }

    fn run(
        &mut self,
        block: &mut Block,
        pos: u64,
        sys: &mut dyn System,
        out: &mut Executed,
    ) -> Result<Flow, LangError> {
        if block.skip && self.options.block_skip {
            return Ok(Flow::Next);
        }
        match &block.body {
            Body::Nothing | Body::Heading => Ok(Flow::Next),
            Body::Begin { name, inch } => {
                if self.frames.len() == 1 && self.names[0].is_empty() {
                    self.names[0].clone_from(name);
                    self.inch = *inch;
                }
                Ok(Flow::Next)
            }
            Body::End => {
                if self.frames.len() <= 1 {
                    return Ok(Flow::End);
                }
                self.frames.pop();
                Ok(Flow::Next)
            }
            Body::Control { .. } => {
                self.fill(block, out)?;
                if out.m.iter().any(|(m, _)| *m == 2 || *m == 30) {
                    self.end_pending = true;
                }
                Ok(Flow::Yield)
            }
            Body::Assign(q, root) => {
                let (q, root) = (*q, *root);
                let v = self.formula(block, root)?;
                let v = self.number(v)?;
                self.store_q(q, v);
                Ok(Flow::Next)
            }
            Body::AssignText(n, root) => {
                let (n, root) = (*n, *root);
                match self.formula(block, root)? {
                    Value::Text(s) => {
                        if let Some(slot) = self.qs.get_mut(n as usize) {
                            *slot = s;
                        }
                        Ok(Flow::Next)
                    }
                    Value::Number(_) => Err(self.error(
                        LangErrorKind::Syntax,
                        "a string parameter needs a text, not a number",
                    )),
                }
            }
            Body::Arith { op, target, a, b } => {
                let x = self.operand(*a);
                let y = b.map(|b| self.operand(b));
                let v = self.arith(*op, x, y)?;
                self.store_q(*target, v);
                Ok(Flow::Next)
            }
            Body::If { cmp, a, b, label } => {
                let (x, y) = (self.operand(*a), self.operand(*b));
                let go = match cmp {
                    Compare::Equal => x == y,
                    Compare::NotEqual => x != y,
                    Compare::Greater => x > y,
                    Compare::Less => x < y,
                };
                if go {
                    let label = label.clone();
                    self.jump(&label)?;
                }
                Ok(Flow::Next)
            }
            Body::Error(v) => {
                let v = self.operand(*v);
                let n = if v >= 0.0 && v <= f64::from(u32::MAX) {
                    v as u32
                } else {
                    0
                };
                Err(self.error(
                    LangErrorKind::ProgramError(n),
                    format!("FN 14: the program raised error {n}"),
                ))
            }
            Body::Print { values, text } => {
                let mut s = format!("FN 15: PRINT {text}");
                if !values.is_empty() {
                    s.push_str(" =");
                    for v in values {
                        s.push(' ');
                        s.push_str(&format_number(self.operand(*v), None));
                    }
                }
                self.note(s);
                Ok(Flow::Next)
            }
            Body::FPrint(text) => {
                let s = format!("FN 16: F-PRINT {text}");
                self.note(s);
                Ok(Flow::Next)
            }
            Body::SysRead {
                target,
                group,
                number,
                index,
            } => match sys.sysread(*group, *number, *index) {
                Ok(v) => {
                    self.store_q(*target, v);
                    Ok(Flow::Next)
                }
                Err(m) => Err(self.error(LangErrorKind::Parameter, m)),
            },
            Body::Label(l) => {
                if *l == Label::Number(0) {
                    let popped = self
                        .frames
                        .last_mut()
                        .and_then(|f| f.returns.pop().map(|r| (f, r)));
                    if let Some((f, (at, line))) = popped {
                        f.next_line = line;
                        if let Err(e) = f.text.seek(at) {
                            return Err(self.io_error(&e));
                        }
                    }
                }
                Ok(Flow::Next)
            }
            Body::CallLabel { label, rep } => {
                let label = label.clone();
                if label == Label::Number(0) {
                    return Err(self.error(LangErrorKind::Syntax, "LBL 0 cannot be called"));
                }
                match rep {
                    None => {
                        if self.nesting() >= MAX_NESTING {
                            return Err(self.error(
                                LangErrorKind::Nesting,
                                format!("calls nested deeper than {MAX_NESTING} levels"),
                            ));
                        }
                        let Some(f) = self.frames.last() else {
                            return Ok(Flow::Next);
                        };
                        let back = (f.text.position(), f.next_line);
                        self.jump(&label)?;
                        if let Some(f) = self.frames.last_mut() {
                            f.returns.push(back);
                        }
                    }
                    Some(n) => {
                        let left = self
                            .frames
                            .last_mut()
                            .map_or(0, |f| *f.reps.entry(pos).or_insert(*n));
                        if left > 0 {
                            self.jump(&label)?;
                            if let Some(f) = self.frames.last_mut() {
                                f.reps.insert(pos, left - 1);
                            }
                        } else if let Some(f) = self.frames.last_mut() {
                            f.reps.remove(&pos);
                        }
                    }
                }
                Ok(Flow::Next)
            }
            Body::CallProgram(name) => {
                if self.nesting() >= MAX_NESTING {
                    return Err(self.error(
                        LangErrorKind::Nesting,
                        format!("calls nested deeper than {MAX_NESTING} levels"),
                    ));
                }
                let text = match self.store.open(name) {
                    Ok(Some(t)) => t,
                    Ok(None) => {
                        return Err(self.error(
                            LangErrorKind::ProgramMissing,
                            format!("program {name} does not exist"),
                        ));
                    }
                    Err(e) => {
                        return Err(self.error(
                            LangErrorKind::ProgramMissing,
                            format!("program {name} cannot be read: {e}"),
                        ));
                    }
                };
                let key = store_key(name);
                let program = match self.names.iter().skip(1).position(|n| *n == key) {
                    Some(i) => i + 1,
                    None => {
                        self.names.push(key);
                        self.names.len() - 1
                    }
                };
                self.frames.push(Frame::new(text, program));
                Ok(Flow::Next)
            }
        }
    }

    fn nesting(&self) -> usize {
        self.frames.len() - 1 + self.frames.iter().map(|f| f.returns.len()).sum::<usize>()
    }

    /// Goes on at `label` in the running program.
    fn jump(&mut self, label: &Label) -> Result<(), LangError> {
        let found = match self.find_label(label) {
            Ok(f) => f,
            Err(e) => return Err(self.io_error(&e)),
        };
        let Some((at, line)) = found else {
            let shown = match label {
                Label::Number(n) => n.to_string(),
                Label::Name(s) => format!("\"{s}\""),
            };
            return Err(self.error(
                LangErrorKind::LabelMissing,
                format!("label {shown} does not exist in the program"),
            ));
        };
        if let Some(f) = self.frames.last_mut() {
            f.next_line = line;
            if let Err(e) = f.text.seek(at) {
                return Err(self.io_error(&e));
            }
        }
        Ok(())
    }

    /// The offset and line of `label`'s `LBL` line, reading on from the
    /// furthest line read when it has not been seen yet.
    fn find_label(&mut self, label: &Label) -> std::io::Result<Option<(u64, u32)>> {
        let Some(f) = self.frames.last_mut() else {
            return Ok(None);
        };
        if let Some(&at) = f.labels.get(label) {
            return Ok(Some(at));
        }
        let back = (f.text.position(), f.next_line);
        f.text.seek(f.scanned.0)?;
        f.next_line = f.scanned.1;
        let mut found = None;
        while Self::read_line(f, &mut self.more)?.is_some() {
            if let Some(&at) = f.labels.get(label) {
                found = Some(at);
                break;
            }
        }
        f.text.seek(back.0)?;
        f.next_line = back.1;
        Ok(found)
    }

    fn store_q(&mut self, q: QRef, v: f64) {
        let slot = match q.kind {
            QKind::Q => self.q.get_mut(q.n as usize),
            QKind::Qr => self.qr.get_mut(q.n as usize),
            QKind::Ql => self
                .frames
                .last_mut()
                .and_then(|f| f.ql.get_mut(q.n as usize)),
        };
        if let Some(s) = slot {
            *s = v;
        }
    }

    fn read_q(&self, q: QRef) -> f64 {
        match q.kind {
            QKind::Q => self.q(q.n),
            QKind::Qr => self.qr(q.n),
            QKind::Ql => self.ql(q.n),
        }
    }

    fn operand(&self, o: Operand) -> f64 {
        match o {
            Operand::Num(v) => v,
            Operand::Param { q, neg } => {
                let v = self.read_q(q);
                if neg { -v } else { v }
            }
        }
    }

    fn number(&self, v: Value) -> Result<f64, LangError> {
        match v {
            Value::Number(n) => Ok(n),
            Value::Text(_) => {
                Err(self.error(LangErrorKind::Syntax, "a number was expected, not a text"))
            }
        }
    }

    fn arith(&self, op: FnOp, x: f64, y: Option<f64>) -> Result<f64, LangError> {
        let y = y.unwrap_or(0.0);
        let v = match op {
            FnOp::Assign => x,
            FnOp::Add => x + y,
            FnOp::Sub => x - y,
            FnOp::Mul => x * y,
            FnOp::Div => {
                if y == 0.0 {
                    return Err(self.error(LangErrorKind::Arithmetic, "division by zero"));
                }
                x / y
            }
            FnOp::Sqrt => {
                if x < 0.0 {
                    return Err(self.error(
                        LangErrorKind::Arithmetic,
                        "square root of a negative number",
                    ));
                }
                x.sqrt()
            }
            FnOp::Sin => x.to_radians().sin(),
            FnOp::Cos => x.to_radians().cos(),
            FnOp::Len => x.hypot(y),
            FnOp::Angle => {
                if x == 0.0 && y == 0.0 {
                    return Err(self.error(LangErrorKind::Arithmetic, "angle of a zero vector"));
                }
                y.atan2(x).to_degrees().rem_euclid(360.0)
            }
        };
        self.finite(v)
    }

    fn finite(&self, v: f64) -> Result<f64, LangError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.error(
                LangErrorKind::Arithmetic,
                "the result is not a finite number",
            ))
        }
    }

    /// Evaluates the formula whose root is `root` (nodes are stored
    /// children first, so one pass in order does it).
    fn formula(&mut self, block: &Block, root: usize) -> Result<Value, LangError> {
        let mut values = std::mem::take(&mut self.values);
        values.clear();
        let r = self.eval_nodes(block, root, &mut values);
        let out = r.map(|()| {
            values.get_mut(root).map_or(Value::Number(0.0), |v| {
                std::mem::replace(v, Value::Number(0.0))
            })
        });
        values.clear();
        self.values = values;
        out
    }

    fn eval_nodes(
        &self,
        block: &Block,
        root: usize,
        values: &mut Vec<Value>,
    ) -> Result<(), LangError> {
        let num = |values: &Vec<Value>, i: usize| -> Result<f64, LangError> {
            match values.get(i) {
                Some(Value::Number(n)) => Ok(*n),
                _ => Err(self.error(LangErrorKind::Syntax, "a number was expected, not a text")),
            }
        };
        let text = |values: &Vec<Value>, i: usize| -> Result<String, LangError> {
            match values.get(i) {
                Some(Value::Text(s)) => Ok(s.clone()),
                Some(Value::Number(n)) => Ok(format_number(*n, None)),
                None => Ok(String::new()),
            }
        };
        let arith = |msg: &str| self.error(LangErrorKind::Arithmetic, msg);
        for node in block.nodes.iter().take(root + 1) {
            let v = match node {
                Node::Num(n) => Value::Number(*n),
                Node::Param(q) => Value::Number(self.read_q(*q)),
                Node::Pi => Value::Number(std::f64::consts::PI),
                Node::Minus(a) => Value::Number(-num(values, *a)?),
                Node::Func(f, a) => {
                    let x = num(values, *a)?;
                    let v = match f {
                        Func::Sin => x.to_radians().sin(),
                        Func::Cos => x.to_radians().cos(),
                        Func::Tan => {
                            let c = x.to_radians().cos();
                            if c.abs() < 1e-15 {
                                return Err(arith("tangent of 90°"));
                            }
                            x.to_radians().tan()
                        }
                        Func::Asin | Func::Acos => {
                            if !(-1.0..=1.0).contains(&x) {
                                return Err(arith("arc sine / cosine of a value beyond ±1"));
                            }
                            if *f == Func::Asin {
                                x.asin().to_degrees()
                            } else {
                                x.acos().to_degrees()
                            }
                        }
                        Func::Atan => x.atan().to_degrees(),
                        Func::Sq => x * x,
                        Func::Sqrt => {
                            if x < 0.0 {
                                return Err(arith("square root of a negative number"));
                            }
                            x.sqrt()
                        }
                        Func::Ln | Func::Log => {
                            if x <= 0.0 {
                                return Err(arith("logarithm of a number not above 0"));
                            }
                            if *f == Func::Ln { x.ln() } else { x.log10() }
                        }
                        Func::Exp => x.exp(),
                        Func::Neg => -x,
                        Func::Int => x.trunc(),
                        Func::Abs => x.abs(),
                        Func::Frac => x.fract(),
                        Func::Sgn => {
                            if x >= 0.0 {
                                1.0
                            } else {
                                -1.0
                            }
                        }
                    };
                    Value::Number(self.finite(v)?)
                }
                Node::Bin(op, a, b) => {
                    let (x, y) = (num(values, *a)?, num(values, *b)?);
                    let v = match op {
                        Op::Add => x + y,
                        Op::Sub => x - y,
                        Op::Mul => x * y,
                        Op::Div | Op::Mod => {
                            if y == 0.0 {
                                return Err(arith("division by zero"));
                            }
                            if *op == Op::Div { x / y } else { x % y }
                        }
                        Op::Pow => x.powf(y),
                    };
                    Value::Number(self.finite(v)?)
                }
                Node::ToNumber(a) => {
                    let s = text(values, *a)?;
                    match s.trim().parse::<f64>() {
                        Ok(v) if v.is_finite() => Value::Number(v),
                        _ => {
                            return Err(self.error(
                                LangErrorKind::Parameter,
                                format!("TONUMB: \"{s}\" is not a number"),
                            ));
                        }
                    }
                }
                Node::StrLen(a) => Value::Number(text(values, *a)?.chars().count() as f64),
                Node::Text(s) => Value::Text(s.clone()),
                Node::TextParam(n) => Value::Text(self.qs(*n).to_string()),
                Node::Concat(a, b) => {
                    let mut s = text(values, *a)?;
                    s.push_str(&text(values, *b)?);
                    Value::Text(s)
                }
                Node::ToChar(a, d) => {
                    let x = num(values, *a)?;
                    let d = match d {
                        Some(d) => {
                            let d = num(values, *d)?;
                            if !(0.0..=16.0).contains(&d) {
                                return Err(self.error(
                                    LangErrorKind::Parameter,
                                    "TOCHAR: DECIMALS out of range",
                                ));
                            }
                            Some(d as usize)
                        }
                        None => None,
                    };
                    Value::Text(format_number(x, d))
                }
                Node::SubStr(s, b, l) => {
                    let s = text(values, *s)?;
                    let (b, l) = (num(values, *b)?, num(values, *l)?);
                    let count = s.chars().count() as f64;
                    if b < 0.0 || l < 0.0 || b + l > count {
                        return Err(self.error(
                            LangErrorKind::Parameter,
                            "SUBSTR: the part lies outside the text",
                        ));
                    }
                    Value::Text(s.chars().skip(b as usize).take(l as usize).collect())
                }
            };
            values.push(v);
        }
        Ok(())
    }

    /// Writes the control block `block` to `out`, every value evaluated.
    fn fill(&mut self, block: &Block, out: &mut Executed) -> Result<(), LangError> {
        let Body::Control {
            kind,
            name,
            number,
            tool,
        } = &block.body
        else {
            return Ok(());
        };
        out.line = self.line;
        out.program = self.program;
        out.block_number = block.number;
        out.kind = kind.clone();
        out.name.clone_from(name);
        out.number = *number;
        out.tool = match tool {
            None => None,
            Some(ToolRef::Name(s)) => Some(Tool::Name(s.clone())),
            Some(ToolRef::Text(n)) => Some(Tool::Name(self.qs(*n).to_string())),
            Some(ToolRef::Number(o)) => {
                let v = self.operand(*o);
                if !(0.0..=f64::from(u32::MAX)).contains(&v) {
                    return Err(self.error(
                        LangErrorKind::Parameter,
                        format!("tool number {v} is out of range"),
                    ));
                }
                Some(Tool::Number(v as u32))
            }
        };
        out.params.clear();
        for p in &block.params {
            out.params.push((p.n, self.operand(p.value)));
        }
        out.pattern.clear();
        for p in &block.pattern {
            let mut words = Vec::new();
            let mut keys = Vec::new();
            let mut m = Vec::new();
            self.items(&p.items, &mut words, &mut keys, &mut m);
            out.pattern.push(PatternItem {
                kind: p.kind.clone(),
                words,
            });
        }
        out.m.clear();
        let (mut words, mut keys, mut m) = (
            std::mem::take(&mut out.words),
            std::mem::take(&mut out.keys),
            std::mem::take(&mut out.m),
        );
        self.items(&block.items, &mut words, &mut keys, &mut m);
        out.words = words;
        out.keys = keys;
        out.m = m;
        let c = trim(&self.comment);
        let c = c.strip_suffix(b"~").map_or(c, trim);
        if c.is_empty() && self.comment.is_empty() {
            out.comment = None;
        } else {
            let s = out.comment.get_or_insert_with(String::new);
            s.clear();
            s.push_str(&String::from_utf8_lossy(c));
        }
        Ok(())
    }

    /// Words, keys and M functions of `items`, reusing the strings of the
    /// vectors given.
    fn items(
        &self,
        items: &[Item],
        words: &mut Vec<Word>,
        keys: &mut Vec<Key>,
        m: &mut Vec<(u32, Span)>,
    ) {
        let (mut nw, mut nk) = (0, 0);
        m.clear();
        for item in items {
            match item {
                Item::Word {
                    address,
                    value,
                    incremental,
                    span,
                } => {
                    let v = self.operand(*value);
                    if let Some(w) = words.get_mut(nw) {
                        w.address.clear();
                        address.write_to(&self.code, &mut w.address);
                        w.value = v;
                        w.incremental = *incremental;
                        w.span = *span;
                    } else {
                        let mut a = String::new();
                        address.write_to(&self.code, &mut a);
                        words.push(Word {
                            address: a,
                            value: v,
                            incremental: *incremental,
                            span: *span,
                        });
                    }
                    nw += 1;
                }
                Item::Key { key, span } => {
                    if let Some(k) = keys.get_mut(nk) {
                        k.key.clear();
                        key.write_to(&self.code, &mut k.key);
                        k.span = *span;
                    } else {
                        let mut s = String::new();
                        key.write_to(&self.code, &mut s);
                        keys.push(Key {
                            key: s,
                            span: *span,
                        });
                    }
                    nk += 1;
                }
                Item::M { n, span } => m.push((*n, *span)),
            }
        }
        words.truncate(nw);
        keys.truncate(nk);
    }
}

fn trim(b: &[u8]) -> &[u8] {
    let s = b
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(b.len());
    let e = b
        .iter()
        .rposition(|c| !c.is_ascii_whitespace())
        .map_or(s, |e| e + 1);
    &b[s..e.max(s)]
}

/// Whether a line continues on the next (its last non-space byte is `~`,
/// also at the end of a comment, or at the end of the code before
/// a comment).
fn ends_in_tilde(line: &[u8]) -> bool {
    trim(line).last() == Some(&b'~') || trim(split_comment(line).0).last() == Some(&b'~')
}

/// The label of an `LBL` line, if it is one (`/`, a block number and
/// spaces may come first).
fn label_on(line: &[u8]) -> Option<Label> {
    let mut i = 0;
    let skip_ws = |i: &mut usize| {
        while line
            .get(*i)
            .is_some_and(|b| matches!(b, b' ' | b'\t' | b'/'))
        {
            *i += 1;
        }
    };
    skip_ws(&mut i);
    while line.get(i).is_some_and(u8::is_ascii_digit) {
        i += 1;
    }
    skip_ws(&mut i);
    let rest = line.get(i..)?;
    if rest.len() < 4
        || !rest[..3].eq_ignore_ascii_case(b"LBL")
        || !(matches!(rest[3], b' ' | b'\t' | b'"') || rest[3].is_ascii_digit())
    {
        return None;
    }
    let mut b = Block::default();
    parse_block(line, &mut b).ok()?;
    match b.body {
        Body::Label(l) => Some(l),
        _ => None,
    }
}

/// A number as text: with `decimals` places, or its shortest form.
pub fn format_number(v: f64, decimals: Option<usize>) -> String {
    match decimals {
        Some(d) => format!("{v:.d$}"),
        None => {
            let s = format!("{v}");
            if s == "-0" { "0".to_string() } else { s }
        }
    }
}

pub use fiveaxis_gcode::TextProgram;

/// A store with no programs (for a main program that calls none).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoPrograms;

impl ProgramStore for NoPrograms {
    fn open(&mut self, _name: &str) -> std::io::Result<Option<Box<dyn ProgramText>>> {
        Ok(None)
    }
}

/// A store of programs in memory, found by file name as
/// [`ProgramStore::open`] asks (case-insensitive, with or without `.H`,
/// the last part of a path).
#[derive(Clone, Debug, Default)]
pub struct MemoryStore {
    programs: Vec<(String, String)>,
}

impl MemoryStore {
    /// An empty store.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds program `name` with `text`.
    #[must_use]
    pub fn with(mut self, name: &str, text: &str) -> Self {
        self.programs.push((store_key(name), text.to_string()));
        self
    }
}

/// The file name of a program as `CALL PGM` writes it: upper-cased,
/// without path and `.H`.
fn store_key(name: &str) -> String {
    let base = name.rsplit(['\\', '/', ':']).next().unwrap_or(name);
    let upper = base.to_ascii_uppercase();
    upper
        .strip_suffix(".H")
        .map_or(upper.clone(), str::to_string)
}

impl ProgramStore for MemoryStore {
    fn open(&mut self, name: &str) -> std::io::Result<Option<Box<dyn ProgramText>>> {
        let key = store_key(name);
        Ok(self
            .programs
            .iter()
            .find(|(n, _)| *n == key)
            .map(|(_, t)| Box::new(TextProgram::new(t.clone())) as Box<dyn ProgramText>))
    }
}

/// A control that knows no data: every `FN 18` read fails.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoSystem;

impl System for NoSystem {
    fn sysread(&mut self, group: u32, number: u32, index: Option<u32>) -> Result<f64, String> {
        let idx = index.map(|i| format!(" IDX{i}")).unwrap_or_default();
        Err(format!(
            "system datum ID{group} NR{number}{idx} is not known"
        ))
    }
}
