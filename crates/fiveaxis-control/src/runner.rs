//! The runner: streams a program through the front end and the controller,
//! one line at a time, and follows subprogram calls within the same file.
//!
//! Memory stays constant in the program's length: the runner keeps one
//! line, one block and the segments of one block, plus the positions of
//! the program numbers (`O…`) it has passed, which it needs to find
//! subprograms.

use std::io::{self, BufRead, Seek, SeekFrom};

use fiveaxis_gcode::{Block, SyntaxError, SyntaxErrorKind, parse_line};
use fiveaxis_machine::{Machine, Offsets};

use crate::alarm::{Alarm, Condition};
use crate::controller::{Controller, Flow};
use crate::dialect::Dialect;
use crate::segment::Segment;

/// Lines of a program, read in order, with the ability to jump back to a
/// line start (subprogram calls).
pub trait Source {
    /// Reads the next line, without its line end, into `buf` (cleared
    /// first). `Ok(false)` at the end of the program.
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool>;
    /// Byte offset of the next line.
    fn position(&self) -> u64;
    /// Goes on reading at byte `offset`, a line start seen before.
    fn seek(&mut self, offset: u64) -> io::Result<()>;
}

/// A program held in memory.
#[derive(Clone, Debug)]
pub struct SliceSource<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> SliceSource<'a> {
    /// Reads `data` from its start.
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }
}

impl Source for SliceSource<'_> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        buf.clear();
        let Some(rest) = self.data.get(self.pos..).filter(|r| !r.is_empty()) else {
            return Ok(false);
        };
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        buf.extend_from_slice(&rest[..len]);
        self.pos += (len + 1).min(rest.len());
        trim_line_end(buf);
        Ok(true)
    }

    fn position(&self) -> u64 {
        self.pos as u64
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        self.pos = usize::try_from(offset)
            .unwrap_or(usize::MAX)
            .min(self.data.len());
        Ok(())
    }
}

/// A program read from a seekable reader (a file), buffered.
#[derive(Debug)]
pub struct ReaderSource<R> {
    inner: R,
    pos: u64,
}

impl<R: BufRead + Seek> ReaderSource<R> {
    /// Reads `inner` from its current position, taken as offset 0.
    pub fn new(inner: R) -> Self {
        Self { inner, pos: 0 }
    }
}

impl<R: BufRead + Seek> Source for ReaderSource<R> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        buf.clear();
        let n = self.inner.read_until(b'\n', buf)?;
        self.pos += n as u64;
        trim_line_end(buf);
        Ok(n > 0)
    }

    fn position(&self) -> u64 {
        self.pos
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        self.inner.seek(SeekFrom::Start(offset))?;
        self.pos = offset;
        Ok(())
    }
}

fn trim_line_end(buf: &mut Vec<u8>) {
    while matches!(buf.last(), Some(b'\n' | b'\r')) {
        buf.pop();
    }
}

/// Options of a run that are the operator's, not the machine's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunOptions {
    /// Block delete switch: skip blocks that start with `/`.
    pub block_delete: bool,
}

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The control stopped with an alarm.
    #[error("{alarm}")]
    Alarm {
        /// The alarm.
        alarm: Alarm,
        /// The text of the failing line, for display.
        text: String,
    },
    /// The program could not be read.
    #[error("cannot read the program: {0}")]
    Io(#[from] io::Error),
}

/// A line start: byte offset and 1-based line number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Mark {
    offset: u64,
    line: u32,
}

/// An active subprogram call.
#[derive(Clone, Copy, Debug)]
struct Frame {
    /// Where the caller goes on.
    return_to: Mark,
    /// The subprogram's `O` line.
    start: Mark,
    /// Runs still to do after the current one.
    repeats_left: u32,
}

/// Streams a program through the controller.
#[derive(Debug)]
pub struct Runner<'m, S> {
    controller: Controller<'m>,
    source: S,
    options: RunOptions,
    max_nesting: usize,
    text: Vec<u8>,
    /// Line and block buffers for searches (program and sequence
    /// numbers), so that the executing line stays intact for messages.
    scan_text: Vec<u8>,
    scan_block: Block,
    block: Block,
    queue: Vec<Segment>,
    queue_pos: usize,
    /// Line number of the next line to read.
    next_line: u32,
    stack: Vec<Frame>,
    /// Program numbers seen, with their lines.
    labels: Vec<(u32, Mark)>,
    /// Everything before this mark has been seen (and its labels recorded).
    scanned: Mark,
    /// No block has run since the start or the last jump to a program.
    at_program_start: bool,
    done: bool,
    /// The controller has emitted what it held at the end.
    flushed: bool,
    /// The last lines read, for messages about blocks the controller held
    /// back (cutter compensation's look-ahead); buffers are reused.
    recent: [(u32, Vec<u8>); RECENT_LINES],
    recent_next: usize,
}

/// How many recent lines the runner keeps for messages.
const RECENT_LINES: usize = 16;

impl<'m, S: Source> Runner<'m, S> {
    /// A run of the program in `source` on `machine` with `offsets`.
    pub fn new(machine: &'m Machine, offsets: Offsets, source: S, options: RunOptions) -> Self {
        Self {
            controller: Controller::new(machine, offsets),
            source,
            options,
            max_nesting: Dialect::of(machine.control).max_nesting,
            text: Vec::new(),
            scan_text: Vec::new(),
            scan_block: Block::default(),
            block: Block::default(),
            queue: Vec::new(),
            queue_pos: 0,
            next_line: 1,
            stack: Vec::new(),
            labels: Vec::new(),
            scanned: Mark { offset: 0, line: 1 },
            at_program_start: true,
            done: false,
            flushed: false,
            recent: std::array::from_fn(|_| (0, Vec::new())),
            recent_next: 0,
        }
    }

    /// The controller, for its state after the run.
    pub fn controller(&self) -> &Controller<'m> {
        &self.controller
    }

    /// The next segment of the program, `None` at its end.
    pub fn next_segment(&mut self) -> Result<Option<Segment>, RunError> {
        loop {
            if let Some(seg) = self.queue.get(self.queue_pos) {
                self.queue_pos += 1;
                return Ok(Some(seg.clone()));
            }
            if self.done {
                return Ok(None);
            }
            let mut queue = std::mem::take(&mut self.queue);
            queue.clear();
            self.queue_pos = 0;
            let result = self
                .step(&mut queue)
                .and_then(|()| self.flush_at_end(&mut queue));
            self.queue = queue;
            result?;
        }
    }

    /// Appends the program's next segments to `out` until it holds at
    /// least `count` or the program ends; `Ok(false)` once it has ended.
    /// Faster than [`Runner::next_segment`] for bulk consumers: segments
    /// are written once, where they will be read.
    pub fn fill(&mut self, out: &mut Vec<Segment>, count: usize) -> Result<bool, RunError> {
        if self.queue_pos < self.queue.len() {
            out.extend_from_slice(&self.queue[self.queue_pos..]);
            self.queue_pos = self.queue.len();
        }
        while out.len() < count && !self.done {
            self.step(out)?;
        }
        self.flush_at_end(out)?;
        Ok(!self.done)
    }

    /// At the end of the program, what the controller still holds (cutter
    /// compensation's look-ahead).
    fn flush_at_end(&mut self, out: &mut Vec<Segment>) -> Result<(), RunError> {
        if self.done && !self.flushed {
            self.flushed = true;
            if let Err(alarm) = self.controller.finish(out) {
                return Err(self.alarm_here(alarm));
            }
        }
        Ok(())
    }

    /// Reads and executes one line, appending its segments to `out`.
    fn step(&mut self, out: &mut Vec<Segment>) -> Result<(), RunError> {
        let here = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        if !self.source.read_line(&mut self.text)? {
            return self.end_of_program();
        }
        self.next_line += 1;
        let slot = &mut self.recent[self.recent_next];
        slot.0 = here.line;
        slot.1.clear();
        slot.1.extend_from_slice(&self.text);
        self.recent_next = (self.recent_next + 1) % RECENT_LINES;
        let sequential = here.offset >= self.scanned.offset;
        if sequential {
            self.scanned = Mark {
                offset: self.source.position(),
                line: self.next_line,
            };
        }
        if let Err(error) = parse_line(&self.text, here.line, &mut self.block) {
            return Err(self.syntax_alarm(here.line, error));
        }
        let program = self
            .block
            .words
            .first()
            .filter(|w| w.letter == b'O')
            .map(|w| w.value as u32);
        if let Some(number) = program
            && sequential
        {
            self.labels.push((number, here));
        }
        if self.block.tape_mark {
            return if self.at_program_start && self.stack.is_empty() {
                Ok(())
            } else {
                self.end_of_program()
            };
        }
        if program.is_some() {
            if !self.at_program_start {
                // The next program in the file: the current one ended.
                return self.end_of_program();
            }
        } else if self.block.is_empty() || (self.block.block_delete && self.options.block_delete) {
            return Ok(());
        }
        self.at_program_start = false;
        let flow = match self.controller.execute(&self.block, out) {
            Ok(flow) => flow,
            Err(alarm) => return Err(self.alarm_here(alarm)),
        };
        match flow {
            Flow::Next => Ok(()),
            Flow::End => {
                self.done = true;
                Ok(())
            }
            Flow::Call { program, repeats } => self.call(program, repeats, here.line),
            Flow::Return { sequence } => self.return_from(sequence, here.line),
        }
    }

    /// The end of the text of the running program: a subprogram returns,
    /// the main program ends.
    fn end_of_program(&mut self) -> Result<(), RunError> {
        if self.stack.is_empty() {
            self.done = true;
            Ok(())
        } else {
            self.return_from(None, self.next_line.saturating_sub(1))
        }
    }

    fn call(&mut self, program: u32, repeats: u32, line: u32) -> Result<(), RunError> {
        if repeats == 0 {
            return Ok(());
        }
        if self.stack.len() >= self.max_nesting {
            return Err(self.runner_alarm(
                Condition::NestingTooDeep,
                line,
                format!("subprograms nested deeper than {} levels", self.max_nesting),
            ));
        }
        let return_to = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        let Some(start) = self.find_program(program)? else {
            return Err(self.runner_alarm(
                Condition::ProgramNotFound,
                line,
                format!("program O{program} is not in this file"),
            ));
        };
        self.stack.push(Frame {
            return_to,
            start,
            repeats_left: repeats - 1,
        });
        self.jump(start)
    }

    fn return_from(&mut self, sequence: Option<u32>, line: u32) -> Result<(), RunError> {
        let Some(frame) = self.stack.last_mut() else {
            // M99 in the main program: a control would start it again; the
            // run ends here.
            self.done = true;
            return Ok(());
        };
        if frame.repeats_left > 0 {
            frame.repeats_left -= 1;
            let start = frame.start;
            return self.jump(start);
        }
        let return_to = frame.return_to;
        self.stack.pop();
        self.jump(return_to)?;
        self.at_program_start = false;
        if let Some(n) = sequence {
            match self.find_sequence(n, return_to)? {
                Some(mark) => self.jump(mark)?,
                None => {
                    return Err(self.runner_alarm(
                        Condition::ProgramNotFound,
                        line,
                        format!("sequence number N{n} is not in the calling program"),
                    ));
                }
            }
            self.at_program_start = false;
        }
        Ok(())
    }

    fn jump(&mut self, mark: Mark) -> Result<(), RunError> {
        self.source.seek(mark.offset)?;
        self.next_line = mark.line;
        self.at_program_start = true;
        Ok(())
    }

    /// Where program `number` starts: a label seen already, or the first
    /// one found reading on past everything seen so far.
    fn find_program(&mut self, number: u32) -> Result<Option<Mark>, RunError> {
        if let Some(&(_, mark)) = self.labels.iter().find(|(n, _)| *n == number) {
            return Ok(Some(mark));
        }
        let resume = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        self.source.seek(self.scanned.offset)?;
        let mut line = self.scanned.line;
        let mut found = None;
        while let Some(mark) = self.scan_line(&mut line)? {
            if let Some(n) = program_number(&self.scan_text) {
                self.labels.push((n, mark));
                if n == number {
                    found = Some(mark);
                    break;
                }
            }
        }
        self.scanned = Mark {
            offset: self.source.position(),
            line,
        };
        self.source.seek(resume.offset)?;
        self.next_line = resume.line;
        Ok(found)
    }

    /// Reads the next line of the source into the scan buffer; its mark,
    /// numbered `line` (counted on), or `None` at the end.
    fn scan_line(&mut self, line: &mut u32) -> Result<Option<Mark>, RunError> {
        let offset = self.source.position();
        if !self.source.read_line(&mut self.scan_text)? {
            return Ok(None);
        }
        let mark = Mark {
            offset,
            line: *line,
        };
        *line += 1;
        Ok(Some(mark))
    }

    /// The line with sequence number `n`: searched from `from` to the end,
    /// then from the start of the file.
    fn find_sequence(&mut self, n: u32, from: Mark) -> Result<Option<Mark>, RunError> {
        for start in [from, Mark { offset: 0, line: 1 }] {
            self.source.seek(start.offset)?;
            let mut line = start.line;
            while let Some(mark) = self.scan_line(&mut line)? {
                if parse_line(&self.scan_text, mark.line, &mut self.scan_block).is_ok()
                    && self.scan_block.sequence == Some(n)
                {
                    return Ok(Some(mark));
                }
            }
        }
        Ok(None)
    }

    fn text(&self) -> String {
        String::from_utf8_lossy(&self.text).into_owned()
    }

    fn alarm_here(&self, alarm: Alarm) -> RunError {
        // An alarm about an earlier block (held back by the controller)
        // shows that block's text.
        let text = match self
            .recent
            .iter()
            .find(|(line, _)| *line == alarm.line && *line != 0)
        {
            Some((_, text)) => String::from_utf8_lossy(text).into_owned(),
            None => self.text(),
        };
        RunError::Alarm { alarm, text }
    }

    fn runner_alarm(&self, condition: Condition, line: u32, message: String) -> RunError {
        let control = self.controller.control();
        let alarm = Alarm {
            condition,
            code: condition.code(control),
            line,
            span: None,
            message,
        };
        self.alarm_here(alarm)
    }

    fn syntax_alarm(&self, line: u32, error: SyntaxError) -> RunError {
        let condition = match error.kind {
            SyntaxErrorKind::MissingValue(_) => Condition::NoDataAfterAddress,
            SyntaxErrorKind::BadNumber => Condition::BadNumber,
            SyntaxErrorKind::TooManyDigits => Condition::TooManyDigits,
            SyntaxErrorKind::UnclosedComment => Condition::UnclosedComment,
            SyntaxErrorKind::Macro => Condition::CustomMacro,
            _ => Condition::ImproperAddress,
        };
        let control = self.controller.control();
        let alarm = Alarm {
            condition,
            code: condition.code(control),
            line,
            span: Some(error.span),
            message: error.kind.to_string(),
        };
        self.alarm_here(alarm)
    }
}

/// The program number of a line that starts with `O` and digits.
fn program_number(text: &[u8]) -> Option<u32> {
    let mut rest = text.iter().skip_while(|b| b.is_ascii_whitespace());
    if !matches!(rest.next(), Some(b'O' | b'o')) {
        return None;
    }
    let mut number: Option<u32> = None;
    for &b in rest {
        match b {
            b' ' | b'\t' => {}
            b'0'..=b'9' => {
                number = Some(
                    number
                        .unwrap_or(0)
                        .checked_mul(10)?
                        .checked_add(u32::from(b - b'0'))?,
                )
            }
            _ => break,
        }
    }
    number
}
