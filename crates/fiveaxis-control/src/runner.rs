//! The runner: streams a program through the front end and the controller,
//! one line at a time, and follows subprogram calls within the same file.
//!
//! Memory stays constant in the program's length: the runner keeps one
//! line, one block and the segments of one block, plus the positions of
//! the program numbers (`O…`) it has passed, which it needs to find
//! subprograms.

use std::io::{self, BufRead, BufReader, Read, Seek, SeekFrom};

use fiveaxis_gcode::{Block, Syntax, SyntaxError, SyntaxErrorKind, parse_line_as};
use fiveaxis_machine::{Control, Machine, Offsets};

use crate::alarm::{Alarm, Condition, Num};
use crate::controller::{Controller, Flow};
use crate::dialect::Dialect;
use crate::segment::{MAX_STEPS, Segment};

mod ahead;
mod heidenhain;
mod library;
mod macros;
mod oword;
mod sinumerik;

pub use ahead::AheadSource;
pub use library::ProgramLibrary;
use library::Sources;

use macros::{MacroFlow, MacroState};

/// Lines of a program, read in order, with the ability to jump back to a
/// line start (subprogram calls).
pub trait Source: Send {
    /// Reads the next line, without its line end, into `buf` (cleared
    /// first). `Ok(false)` at the end of the program.
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool>;
    /// Byte offset of the next line.
    fn position(&self) -> u64;
    /// Goes on reading at byte `offset`, a line start seen before.
    fn seek(&mut self, offset: u64) -> io::Result<()>;
    /// The reading rules of the program's blocks, for a source that reads
    /// blocks ahead of the runner ([`AheadSource`]); others ignore them.
    fn read_blocks_as(&mut self, _syntax: Syntax) {}
    /// The block of the line [`Source::read_line`] gave last, read ahead
    /// with the rules of [`Source::read_blocks_as`], put into `block` with
    /// line number `line`: true when there is one. A line that does not
    /// read as a block without error has none (the runner reads it).
    fn take_block(&mut self, _line: u32, _block: &mut Block) -> bool {
        false
    }
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

impl<S: Source + ?Sized> Source for Box<S> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        (**self).read_line(buf)
    }

    fn position(&self) -> u64 {
        (**self).position()
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        (**self).seek(offset)
    }

    fn read_blocks_as(&mut self, syntax: Syntax) {
        (**self).read_blocks_as(syntax);
    }

    fn take_block(&mut self, line: u32, block: &mut Block) -> bool {
        (**self).take_block(line, block)
    }
}

impl Source for SliceSource<'_> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        buf.clear();
        let Some(rest) = self.data.get(self.pos..).filter(|r| !r.is_empty()) else {
            return Ok(false);
        };
        // A line ends at LF, CR LF or a lone CR.
        let len = memchr::memchr2(b'\n', b'\r', rest).unwrap_or(rest.len());
        if len > MAX_LINE_BYTES + 1 {
            return Err(line_too_long());
        }
        buf.extend_from_slice(&rest[..len]);
        let ending = match rest.get(len..) {
            Some([b'\r', b'\n', ..]) => 2,
            Some([_, ..]) => 1,
            _ => 0,
        };
        self.pos += len + ending;
        trim_line_end(buf);
        if buf.len() > MAX_LINE_BYTES {
            return Err(line_too_long());
        }
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
    inner: BufReader<R>,
    pos: u64,
}

/// Read buffer of a [`ReaderSource`], bytes.
const READ_BUFFER: usize = 64 * 1024;

impl<R: Read + Seek> ReaderSource<R> {
    /// Reads `inner` from its current position, taken as offset 0.
    pub fn new(inner: R) -> Self {
        Self {
            inner: BufReader::with_capacity(READ_BUFFER, inner),
            pos: 0,
        }
    }
}

impl<R: Read + Seek + Send> Source for ReaderSource<R> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        buf.clear();
        let mut any = false;
        loop {
            let available = match self.inner.fill_buf() {
                Ok(bytes) => bytes,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if available.is_empty() {
                break;
            }
            any = true;
            // A line ends at LF, CR LF or a lone CR (old Macintosh files).
            let (take, end) = match memchr::memchr2(b'\n', b'\r', available) {
                Some(i) => (i + 1, Some(available[i])),
                None => (available.len(), None),
            };
            if buf.len() + take > MAX_LINE_BYTES + 2 {
                return Err(line_too_long());
            }
            buf.extend_from_slice(&available[..take]);
            self.inner.consume(take);
            self.pos += take as u64;
            if end == Some(b'\r') {
                // CR LF: the LF belongs to this line end.
                loop {
                    match self.inner.fill_buf() {
                        Ok([b'\n', ..]) => {
                            self.inner.consume(1);
                            self.pos += 1;
                        }
                        Ok(_) => {}
                        Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                        Err(e) => return Err(e),
                    }
                    break;
                }
            }
            if end.is_some() {
                break;
            }
        }
        trim_line_end(buf);
        if buf.len() > MAX_LINE_BYTES {
            return Err(line_too_long());
        }
        Ok(any)
    }

    fn position(&self) -> u64 {
        self.pos
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        // Relative, so that a jump within the buffered text (a loop, a
        // subprogram nearby) keeps the buffer instead of reading again.
        let delta =
            i64::try_from(offset).unwrap_or(i64::MAX) - i64::try_from(self.pos).unwrap_or(i64::MAX);
        match self.inner.seek_relative(delta) {
            Ok(()) => {}
            Err(_) => {
                self.inner.seek(SeekFrom::Start(offset))?;
            }
        }
        self.pos = offset;
        Ok(())
    }
}

fn trim_line_end(buf: &mut Vec<u8>) {
    while matches!(buf.last(), Some(b'\n' | b'\r')) {
        buf.pop();
    }
}

/// The bound of `--step`: rows inside each block with tool tips at most
/// `step` mm and rotary axes at most `step_angle` degrees apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interpolation {
    /// Most tip travel between rows, mm.
    pub step: f64,
    /// Most turn of any rotary axis between rows, degrees.
    pub step_angle: f64,
}

/// Options of a run that are the operator's, not the machine's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunOptions {
    /// Block delete switch: skip blocks that start with `/`.
    pub block_delete: bool,
    /// Rows inside the blocks (`--step`); `None`: end rows only.
    pub interpolation: Option<Interpolation>,
    /// Most program lines the run reads before it stops a program that
    /// does not end (an endless `M99` or macro loop).
    pub max_blocks: u64,
    /// The optional-stop switch: M01 stops like M00 (noted; the run goes
    /// on).
    pub optional_stop: bool,
    /// Soft limits lifted: no over-travel alarm, moves beyond the limits
    /// go on (for verification, which measures the excursions itself).
    pub lift_soft_limits: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            block_delete: false,
            interpolation: None,
            max_blocks: DEFAULT_MAX_BLOCKS,
            optional_stop: false,
            lift_soft_limits: false,
        }
    }
}

/// The default block budget: beyond real programs (a large mould
/// finishing program has some millions of blocks; `--max-blocks` raises
/// it), reached by an endless loop in seconds.
pub const DEFAULT_MAX_BLOCKS: u64 = 50_000_000;

/// Lines in one window of the loop report: when the budget runs out, the
/// message names the lines run in the last full window.
const LOOP_WINDOW: u64 = 4096;

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The control stopped with an alarm.
    #[error("{alarm}")]
    Alarm {
        /// The alarm.
        alarm: Alarm,
        /// The bytes of the failing line as the program holds them, for
        /// display (not necessarily UTF-8).
        text: Vec<u8>,
        /// The file of a library program the line is in (`--programs`);
        /// `None` for the main program.
        program: Option<String>,
    },
    /// The program could not be read.
    #[error("cannot read the program: {0}")]
    Io(#[from] io::Error),
    /// A line of the program is longer than any control reads
    /// ([`MAX_LINE_BYTES`]): not a program (a binary file, `/dev/zero`).
    #[error("line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a program text")]
    LineTooLong {
        /// 1-based number of the line.
        line: u32,
    },
}

/// The longest program line the runner reads, bytes. Real blocks are tens
/// of bytes, CAM comments a few hundred; anything longer is not a program.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// The error a [`Source`] gives for a line longer than [`MAX_LINE_BYTES`].
pub fn line_too_long() -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, LineTooLong)
}

/// Marker inside the I/O error of a line that is too long.
#[derive(Debug)]
struct LineTooLong;

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "a line is longer than {MAX_LINE_BYTES} bytes")
    }
}

impl std::error::Error for LineTooLong {}

fn is_line_too_long(error: &io::Error) -> bool {
    error
        .get_ref()
        .is_some_and(|inner| inner.downcast_ref::<LineTooLong>().is_some())
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
    /// The number of the program running in it (`#4115`): the called
    /// program's, or the caller's for a call within it (M97).
    program: Option<u32>,
    /// A `G65` / `G66` macro call: it has a level of local variables of
    /// its own.
    macro_call: bool,
    /// The call a `G66` modal call made after a move.
    modal_call: bool,
}

/// Streams a program through the controller.
#[derive(Debug)]
pub struct Runner<'m, S> {
    controller: Controller<'m>,
    /// The main program and the library programs it called.
    source: Sources<S>,
    options: RunOptions,
    max_nesting: usize,
    /// How the control reads a line (its front-end dialect).
    syntax: Syntax,
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
    /// The main program's number (its `O` line), if it has one.
    main_program: Option<u32>,
    done: bool,
    /// The last alarm left the control's state defined: the run may go
    /// on from the next line ([`Runner::resume`]).
    resumable: bool,
    /// The controller has emitted what it held at the end.
    flushed: bool,
    /// The last lines read, for messages about blocks the controller held
    /// back (cutter compensation's look-ahead); buffers are reused.
    recent: [(u32, Vec<u8>); RECENT_LINES],
    recent_next: usize,
    /// Custom macro B: variables and open loops.
    macros: MacroState,
    /// The program is RS274/NGC (LinuxCNC).
    rs274ngc: bool,
    /// Haas: `ONONAME` starts a program without a number, and a
    /// subprogram must end with M99 (alarm 312).
    haas: bool,
    /// RS274/NGC flow: subroutines, calls, open o-word blocks.
    ngc: oword::NgcState,
    /// The leader before the first `%` has been looked for.
    started: bool,
    /// What the runner skipped and why, for `--verbose`.
    notes: Vec<String>,
    /// Notes past [`MAX_NOTES`], counted only.
    notes_dropped: u64,
    /// Lines read so far (the block budget counts them).
    blocks: u64,
    /// Lines read past without running them (skips and searches that
    /// read on; the block budget counts them too).
    skipped: u64,
    /// A SINUMERIK program's interpreter and front end, made at the first
    /// step (when the program memory is known).
    sinumerik: Option<Box<sinumerik::SinumerikRun<'m>>>,
    /// A HEIDENHAIN program's interpreter and front end, as `sinumerik`.
    heidenhain: Option<Box<heidenhain::HeidenhainRun<'m>>>,
    /// The stock a program describes (HEIDENHAIN `BLK FORM`).
    stock: Option<crate::heidenhain::Stock>,
    /// The program source lives as long as the machine's borrow (a
    /// SINUMERIK run hands it to its interpreter).
    _source_outlives: std::marker::PhantomData<fn() -> &'m S>,
    /// Lowest and highest line of the current and of the last full window
    /// of [`LOOP_WINDOW`] lines, for the message of an endless loop.
    window: [(u32, u32); 2],
}

/// Most notes kept for `--verbose`.
const MAX_NOTES: usize = 100;

/// How many recent lines the runner keeps for messages.
const RECENT_LINES: usize = 16;

impl<'m, S: Source> Runner<'m, S> {
    /// A run of the program in `source` on `machine` with `offsets`.
    pub fn new(machine: &'m Machine, offsets: Offsets, source: S, options: RunOptions) -> Self {
        let mut controller = Controller::new(machine, offsets);
        controller.set_optional_stop(options.optional_stop);
        controller.lift_soft_limits(options.lift_soft_limits);
        let dialect = Dialect::of(machine.control);
        let mut source = Sources::new(source);
        // The FANUC family's lines read as blocks by `parse_line_as`; the
        // other languages have readers of their own.
        let reads_blocks = !dialect.rs274ngc
            && !matches!(machine.control, Control::Sinumerik | Control::Heidenhain);
        if reads_blocks {
            source.read_blocks_as(dialect.syntax);
        }
        Self {
            controller,
            source,
            options,
            max_nesting: dialect.max_nesting,
            syntax: dialect.syntax,
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
            main_program: None,
            done: false,
            resumable: false,
            flushed: false,
            recent: std::array::from_fn(|_| (0, Vec::new())),
            recent_next: 0,
            macros: if dialect.rs274ngc {
                MacroState::linuxcnc(oword::NGC_MAX_CALLS)
            } else {
                MacroState::new(
                    dialect.max_macro_nesting,
                    machine.params.additional_common_variables,
                    dialect.structured_if,
                )
            },
            rs274ngc: dialect.rs274ngc,
            haas: dialect.haas_codes,
            ngc: oword::NgcState::default(),
            started: false,
            notes: Vec::new(),
            notes_dropped: 0,
            blocks: 0,
            skipped: 0,
            window: [(u32::MAX, 0); 2],
            sinumerik: None,
            heidenhain: None,
            stock: None,
            _source_outlives: std::marker::PhantomData,
        }
    }

    /// The stock the program describes (HEIDENHAIN `BLK FORM 0.1 / 0.2`),
    /// once read.
    pub fn stock(&self) -> Option<crate::heidenhain::Stock> {
        self.stock
    }

    /// Lines read so far: every block executed, each time it is executed
    /// (in a loop, in a called program), as the block budget counts them.
    pub fn blocks(&self) -> u64 {
        self.blocks
    }

    /// The controller, for its state after the run.
    pub fn controller(&self) -> &Controller<'m> {
        &self.controller
    }

    /// Sends plain blocks through the controller's plain path (on, the
    /// default) or every block through its general path (off): for the
    /// tests that compare the two (`Controller::set_plain_path`).
    #[doc(hidden)]
    pub fn set_plain_path(&mut self, on: bool) {
        self.controller.set_plain_path(on);
    }

    /// From now on the controller counts the axis words written without a
    /// decimal point where they are read in least input increments
    /// ([`Controller::count_words_without_point`]; for verification).
    pub fn count_words_without_point(&mut self) {
        self.controller.count_words_without_point();
    }

    /// The control's program memory: programs that `M98` / `G65` call and
    /// that the running file does not hold are looked up there.
    pub fn with_library(mut self, library: Box<dyn ProgramLibrary>) -> Self {
        self.source.set_library(library);
        self
    }

    /// Keeps a note for [`Runner::notes`]; past [`MAX_NOTES`] only counts
    /// them (a loop must not grow memory).
    fn note(&mut self, text: String) {
        if self.notes.len() < MAX_NOTES {
            self.notes.push(text);
        } else {
            self.notes_dropped += 1;
            let last = format!("… and {} notes more", self.notes_dropped);
            if self.notes.len() == MAX_NOTES {
                self.notes.push(last);
            } else if let Some(slot) = self.notes.last_mut() {
                *slot = last;
            }
        }
    }

    /// What the run skipped so far and why (a leader before the first `%`,
    /// a byte-order mark, text after the closing `%`, deleted blocks), one
    /// sentence each.
    pub fn notes(&self) -> &[String] {
        &self.notes
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
            let stepped = self.step(&mut queue);
            let result = self.release(&mut queue, 0, stepped).and_then(|()| {
                let first = queue.len();
                let flushed = self.flush_at_end(&mut queue);
                self.release(&mut queue, first, flushed)
            });
            self.queue = queue;
            result?;
        }
    }

    /// After an alarm from [`Runner::fill`] or [`Runner::next_segment`]:
    /// whether the control's state is defined (the failing block was not
    /// executed at all: an alarm of the controller on one block, with no
    /// block held by cutter compensation, or a line the front end could
    /// not read), so that the run may go on from the next line, as
    /// `check --keep-going` does. An alarm of the program's flow (macro
    /// statements, subprogram calls, O-words), of the block budget, of a
    /// position that is not finite or of the end of the file leaves it
    /// undefined: `false`, and the run stays stopped.
    pub fn resume(&mut self) -> bool {
        std::mem::take(&mut self.resumable)
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
            let first = out.len();
            let stepped = self.step(out);
            self.release(out, first, stepped)?;
        }
        let first = out.len();
        let flushed = self.flush_at_end(out);
        self.release(out, first, flushed)?;
        Ok(!self.done)
    }

    /// Checks the segments a step appended (from `first` on) before they
    /// leave the runner: every number finite, and with `--step` the rows
    /// each block is sampled into. On an alarm the failing block's
    /// segments are taken back out: the caller keeps only whole blocks
    /// before it.
    fn release(
        &self,
        out: &mut Vec<Segment>,
        first: usize,
        stepped: Result<(), RunError>,
    ) -> Result<(), RunError> {
        let failed = |out: &mut Vec<Segment>, at: usize, line: u32| {
            let keep = (first..at)
                .rev()
                .take_while(|&k| out[k].line == line)
                .last()
                .unwrap_or(at);
            out.truncate(keep);
        };
        // The block that failed appended nothing of its own; earlier held
        // blocks released in the same step stay.
        stepped?;
        let machine = self.controller.machine();
        for at in first..out.len() {
            let seg = &out[at];
            if !seg.is_finite() {
                let line = seg.line;
                failed(out, at, line);
                return Err(self.alarm_here(Alarm {
                    condition: Condition::NonFinitePosition,
                    code: Condition::NonFinitePosition.code(self.controller.control()),
                    line,
                    span: None,
                    message: "the block computes a position that is not a finite number: \
                              an offset, a tool length or a machine dimension is out of range"
                        .into(),
                }));
            }
            if let Some(bound) = self.options.interpolation {
                match seg.steps(machine, bound.step, bound.step_angle) {
                    Some(n) => out[at].rows = n,
                    None => {
                        let line = seg.line;
                        failed(out, at, line);
                        return Err(self.alarm_here(Alarm {
                            condition: Condition::InterpolationTooFine,
                            code: Condition::InterpolationTooFine.code(self.controller.control()),
                            line,
                            span: None,
                            message: format!(
                                "the block cannot be interpolated in {MAX_STEPS} rows at most \
                                 {} mm and {} degrees apart: an axis moves too fast for the \
                                 step (a rotary axis swinging near the singular direction, or a \
                                 step too fine for the block's length)",
                                Num(bound.step),
                                Num(bound.step_angle)
                            ),
                        }));
                    }
                }
            }
        }
        Ok(())
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
        match self.controller.control() {
            Control::Sinumerik => return self.sinumerik_step(out),
            Control::Heidenhain => return self.heidenhain_step(out),
            _ => {}
        }
        self.resumable = false;
        if !self.started {
            self.started = true;
            self.skip_leader()?;
        }
        let here = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        let read = self.source.read_line(&mut self.text).map_err(|e| {
            if is_line_too_long(&e) {
                RunError::LineTooLong { line: here.line }
            } else {
                RunError::Io(e)
            }
        });
        if !read? {
            if self.rs274ngc && self.stack.is_empty() {
                // LinuxCNC: "File ended with no percent sign or program
                // end" (rs274): the main file must end with M2, M30 or the
                // % that closes an opening one.
                return Err(self.runner_alarm(
                    Condition::ProgramEndMissing,
                    here.line.saturating_sub(1).max(1),
                    "the file ended with no percent sign or program end (M2, M30)".into(),
                ));
            }
            return self.end_of_program();
        }
        self.count_block(here.line)?;
        self.next_line += 1;
        let byte_order_mark = here.offset == library::file_start(library::file_of(here.offset))
            && self.text.starts_with(BYTE_ORDER_MARK);
        if byte_order_mark {
            self.text.drain(..BYTE_ORDER_MARK.len());
            self.note("line 1: a UTF-8 byte-order mark, skipped".into());
        }
        let slot = &mut self.recent[self.recent_next];
        slot.0 = here.line;
        slot.1.clear();
        slot.1.extend_from_slice(&self.text);
        self.recent_next = (self.recent_next + 1) % RECENT_LINES;
        let sequential = library::file_of(here.offset) == 0 && here.offset >= self.scanned.offset;
        if sequential {
            self.scanned = Mark {
                offset: self.source.position(),
                line: self.next_line,
            };
        }
        if self.rs274ngc {
            return self.ngc_step(here, sequential, out);
        }
        if self.is_cached_macro_line(here.offset) {
            match self.macro_line(here)? {
                MacroFlow::Done => return Ok(()),
                MacroFlow::Block => return self.execute_block(here, false, out),
            }
        }
        if is_program_name(&self.text) || (self.haas && is_haas_unnamed(&self.text)) {
            // `<NAME>` or `O<NAME>`: a program start by name (30i);
            // Haas's `ONONAME`, a program without a number.
            return if self.at_program_start {
                Ok(())
            } else {
                self.end_of_program()
            };
        }
        // Plain lines take the front end's fast path; a line the front end
        // finds custom macro syntax in goes through the macro layer.
        // The block may have been read ahead (the line as read, without
        // a byte-order mark to drop).
        let read = if !byte_order_mark && self.source.take_block(here.line, &mut self.block) {
            Ok(())
        } else {
            parse_line_as(self.syntax, &self.text, here.line, &mut self.block)
        };
        match read {
            Ok(()) => {}
            Err(error) if error.kind == SyntaxErrorKind::Macro => match self.macro_line(here)? {
                MacroFlow::Done => return Ok(()),
                MacroFlow::Block => return self.execute_block(here, false, out),
            },
            Err(error) if starts_with_o(&self.text) => {
                let mut alarm = self.syntax_alarm(here.line, error);
                if let RunError::Alarm { alarm, .. } = &mut alarm {
                    alarm.message = format!(
                        "an O line gives a program number (O1234) or a name (O<NAME>): {}",
                        alarm.message
                    );
                }
                return Err(alarm);
            }
            Err(error) => {
                // Nothing of the line was executed.
                self.resumable = true;
                return Err(self.syntax_alarm(here.line, error));
            }
        }
        self.execute_block(here, sequential, out)
    }

    /// Executes the block in `self.block`, read at `here` (`sequential`:
    /// for the first time, in file order).
    fn execute_block(
        &mut self,
        here: Mark,
        sequential: bool,
        out: &mut Vec<Segment>,
    ) -> Result<(), RunError> {
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
        if let Some(number) = program
            && self.at_program_start
            && self.stack.is_empty()
        {
            self.main_program = Some(number);
        }
        if self.block.tape_mark {
            // The opening % of the main program or of a library program's
            // file; any other % ends the program that is running.
            let opening = self.at_program_start
                && (self.stack.is_empty()
                    || here.offset == library::file_start(library::file_of(here.offset)));
            return if opening {
                Ok(())
            } else {
                if self.stack.is_empty() {
                    self.note(format!(
                        "line {}: the closing %: anything after it is not read",
                        here.line
                    ));
                }
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
        if let Some(called) = self.macro_call(here.line) {
            return called;
        }
        // Haas G47 P1 engraves the serial number kept in #599.
        let engraves = self.controller.engraves(&self.block);
        if engraves {
            let serial = self.serial_number();
            self.controller.set_serial_number(serial);
        }
        let flow = match self.controller.execute(&self.block, out) {
            Ok(flow) => flow,
            Err(alarm) => {
                // The controller put its state back as before the block,
                // unless cutter compensation dropped a block it held.
                self.resumable = !self.controller.holds_blocks();
                return Err(self.alarm_here(alarm));
            }
        };
        if engraves && let Some(serial) = self.controller.serial_number() {
            self.set_serial_number(serial, here.line)?;
        }
        if let Some(stop) = self.controller.program_stop() {
            let what = match stop {
                crate::controller::ProgramStop::Stop => "program stop",
                crate::controller::ProgramStop::OptionalStop => "optional stop (switch on)",
            };
            self.note(format!(
                "line {}: {what}: the control waits for cycle start; the run goes on",
                here.line
            ));
        }
        match flow {
            Flow::Next => self.modal_call_after_move(here.line),
            Flow::End if self.haas && !self.stack.is_empty() => {
                Err(self.subprogram_end_missing(here.line))
            }
            Flow::End => {
                self.done = true;
                Ok(())
            }
            Flow::Call { program, repeats } => self.call(program, repeats, here.line),
            Flow::LocalCall { sequence, repeats } => self.local_call(sequence, repeats, here.line),
            Flow::Return { sequence } => self.return_from(sequence, here.line),
        }
    }

    /// Text before the first `%` line is leader when no program block
    /// comes before that `%` (CAM listings, banners, blank lines): the run
    /// starts at the `%`. Otherwise the program starts at its first line.
    fn skip_leader(&mut self) -> Result<(), RunError> {
        let start = Mark {
            offset: self.source.position(),
            line: self.next_line,
        };
        let mut line = start.line;
        let mut tape = None;
        let mut content = false;
        while let Some(mark) = self.scan_line(&mut line)? {
            let text = if mark.offset == 0 {
                self.scan_text
                    .strip_prefix(BYTE_ORDER_MARK)
                    .unwrap_or(&self.scan_text)
            } else {
                &self.scan_text
            };
            let first = text.iter().find(|b| !b.is_ascii_whitespace());
            if first == Some(&b'%') {
                tape = Some(mark);
                break;
            }
            if is_program_name(text) || (self.haas && is_haas_unnamed(text)) {
                break;
            }
            match parse_line_as(self.syntax, text, mark.line, &mut self.scan_block) {
                Ok(()) if self.scan_block.is_empty() => {}
                Ok(()) => break,
                Err(e) if e.kind == SyntaxErrorKind::Macro => break,
                Err(_) => content = true,
            }
        }
        match tape {
            Some(mark) if mark.line > start.line => {
                self.source.seek(mark.offset)?;
                self.next_line = mark.line;
                self.scanned = mark;
                let what = if content {
                    "leader text"
                } else {
                    "blank lines"
                };
                self.note(format!(
                    "lines {} to {}: {what} before the first %, skipped",
                    start.line,
                    mark.line - 1
                ));
            }
            _ => self.source.seek(start.offset)?,
        }
        Ok(())
    }

    /// Counts a line against the block budget (`--max-blocks`); past it,
    /// the program is taken for one that does not end.
    fn count_block(&mut self, line: u32) -> Result<(), RunError> {
        self.blocks += 1;
        let current = &mut self.window[0];
        *current = (current.0.min(line), current.1.max(line));
        if self.blocks.is_multiple_of(LOOP_WINDOW) {
            self.window = [(u32::MAX, 0), self.window[0]];
        }
        self.check_budget(line)
    }

    /// Counts a line read past without running it (a skip or a search
    /// that reads the text: `WHILE` to its `END`, `GOTO`, `M99 P`, o-word
    /// flow without its index) against the block budget, so that the
    /// budget bounds the time a run takes, not only the blocks it runs;
    /// `line` is the line being run.
    fn count_skipped(&mut self, line: u32) -> Result<(), RunError> {
        self.skipped += 1;
        self.check_budget(line)
    }

    /// The block budget alarm, when blocks run and lines skipped over
    /// have passed it.
    fn check_budget(&self, line: u32) -> Result<(), RunError> {
        if self.blocks.saturating_add(self.skipped) <= self.options.max_blocks {
            return Ok(());
        }
        let (lo, hi) = if self.window[1].1 > 0 {
            self.window[1]
        } else {
            self.window[0]
        };
        let ran = if self.skipped == 0 {
            format!("ran {} blocks", self.options.max_blocks)
        } else {
            format!(
                "read {} lines ({} blocks run, {} lines skipped over)",
                self.options.max_blocks, self.blocks, self.skipped
            )
        };
        Err(self.runner_alarm(
            Condition::BlockBudget,
            line,
            format!(
                "the program {ran} without ending (--max-blocks); \
                 it was repeating lines {lo} to {hi}"
            ),
        ))
    }

    /// The end of the text of the running program: a subprogram returns,
    /// the main program ends.
    fn end_of_program(&mut self) -> Result<(), RunError> {
        if self.haas && !self.stack.is_empty() {
            return Err(self.subprogram_end_missing(self.next_line.saturating_sub(1).max(1)));
        }
        if self.stack.is_empty() {
            self.done = true;
            Ok(())
        } else {
            self.return_from(None, self.next_line.saturating_sub(1))
        }
    }

    /// Haas: a subprogram that ends (M30, M02, its file's end) without
    /// M99 is alarm 312 (NGC mill operator's manual, Program Stop
    /// Commands: "If your subprogram does not end with M99, the control
    /// gives Alarm 312 - Program End").
    fn subprogram_end_missing(&self, line: u32) -> RunError {
        self.runner_alarm(
            Condition::SubprogramEndMissing,
            line,
            "the subprogram ends without M99 (Haas: program end in a subprogram)".into(),
        )
    }

    fn call(&mut self, program: u32, repeats: u32, line: u32) -> Result<(), RunError> {
        let Some(return_to) = self.call_room(repeats, line)? else {
            return Ok(());
        };
        let Some(start) = self.find_program(program)? else {
            return Err(self.runner_alarm(
                Condition::ProgramNotFound,
                line,
                format!("program O{program} is neither in this file nor in the program library (--programs)"),
            ));
        };
        self.enter(start, return_to, repeats)
    }

    /// Haas M97: an M98 call whose start is sequence number `sequence` of
    /// the running program.
    fn local_call(&mut self, sequence: u32, repeats: u32, line: u32) -> Result<(), RunError> {
        let Some(return_to) = self.call_room(repeats, line)? else {
            return Ok(());
        };
        let Some(start) = self.find_sequence(sequence, return_to, line)? else {
            return Err(self.runner_alarm(
                Condition::ProgramNotFound,
                line,
                format!("M97: sequence number N{sequence} is not in the program"),
            ));
        };
        self.enter(start, return_to, repeats)
    }

    /// Where a subprogram call returns to, after checking the nesting
    /// depth; `None` when it is called no times (L0).
    fn call_room(&self, repeats: u32, line: u32) -> Result<Option<Mark>, RunError> {
        if repeats == 0 {
            return Ok(None);
        }
        if self.stack.len() >= self.max_nesting {
            return Err(self.runner_alarm(
                Condition::NestingTooDeep,
                line,
                format!("subprograms nested deeper than {} levels", self.max_nesting),
            ));
        }
        Ok(Some(Mark {
            offset: self.source.position(),
            line: self.next_line,
        }))
    }

    /// Runs a subprogram from `start`, `repeats` times, then back to
    /// `return_to`.
    fn enter(&mut self, start: Mark, return_to: Mark, repeats: u32) -> Result<(), RunError> {
        let program = self
            .labels
            .iter()
            .find(|(_, mark)| mark.offset == start.offset)
            .map(|(n, _)| *n)
            .or_else(|| self.program_number());
        self.stack.push(Frame {
            return_to,
            start,
            program,
            repeats_left: repeats - 1,
            macro_call: false,
            modal_call: false,
        });
        self.jump(start)
    }

    fn return_from(&mut self, sequence: Option<u32>, line: u32) -> Result<(), RunError> {
        let Some(frame) = self.stack.last_mut() else {
            // M99 P n in the main program jumps to its sequence n (the
            // endless loops of bar feeders and pallet changers: the block
            // budget stops them). A plain M99 there would start the program
            // again; the run ends here.
            let Some(n) = sequence else {
                self.done = true;
                return Ok(());
            };
            let here = Mark {
                offset: self.source.position(),
                line: self.next_line,
            };
            return match self.find_sequence(n, here, line)? {
                Some(mark) => {
                    self.jump(mark)?;
                    self.at_program_start = false;
                    Ok(())
                }
                None => Err(self.runner_alarm(
                    Condition::ProgramNotFound,
                    line,
                    format!("sequence number N{n} is not in the program"),
                )),
            };
        };
        if frame.repeats_left > 0 {
            frame.repeats_left -= 1;
            let start = frame.start;
            return self.jump(start);
        }
        let return_to = frame.return_to;
        if frame.macro_call {
            self.macros.vars.pop_frame();
        }
        self.stack.pop();
        let level = self.stack.len();
        self.macros.loops.retain(|l| l.level <= level);
        self.jump(return_to)?;
        self.at_program_start = false;
        if let Some(n) = sequence {
            match self.find_sequence(n, return_to, line)? {
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

    /// The number of the program running (`#4115`): the called one's, or
    /// the main program's; `None` for a program without an `O` number.
    pub(super) fn program_number(&self) -> Option<u32> {
        self.stack
            .last()
            .map_or(self.main_program, |frame| frame.program)
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
        // `scanned` is in the main program: the scan below reads it on.
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
        if found.is_none()
            && let Some(offset) = self.source.library_program(number)?
        {
            let mark = Mark { offset, line: 1 };
            self.labels.push((number, mark));
            found = Some(mark);
        }
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

    /// [`Runner::scan_line`] for a line read past while line `at` runs:
    /// counted against the block budget.
    fn skip_line(&mut self, line: &mut u32, at: u32) -> Result<Option<Mark>, RunError> {
        let mark = self.scan_line(line)?;
        if mark.is_some() {
            self.count_skipped(at)?;
        }
        Ok(mark)
    }

    /// The line with sequence number `n`: searched from `from` to the end,
    /// then from the start of the file, while line `at` runs (every line
    /// read counts against the block budget).
    fn find_sequence(&mut self, n: u32, from: Mark, at: u32) -> Result<Option<Mark>, RunError> {
        let file_start = Mark {
            offset: library::file_start(library::file_of(from.offset)),
            line: 1,
        };
        for start in [from, file_start] {
            self.source.seek(start.offset)?;
            let mut line = start.line;
            while let Some(mark) = self.skip_line(&mut line, at)? {
                let sequence = match parse_line_as(
                    self.syntax,
                    &self.scan_text,
                    mark.line,
                    &mut self.scan_block,
                ) {
                    Ok(()) => self.scan_block.sequence,
                    Err(e) if e.kind == SyntaxErrorKind::Macro => {
                        fiveaxis_macro::parse_statement(&self.scan_text, mark.line)
                            .ok()
                            .and_then(|line| line.sequence)
                    }
                    Err(_) => None,
                };
                if sequence == Some(n) {
                    return Ok(Some(mark));
                }
            }
        }
        Ok(None)
    }

    fn alarm_here(&self, mut alarm: Alarm) -> RunError {
        if let std::borrow::Cow::Owned(message) = crate::alarm::readable_numbers(&alarm.message) {
            alarm.message = message;
        }
        // An alarm about an earlier block (held back by the controller)
        // shows that block's text.
        let text = match self
            .recent
            .iter()
            .find(|(line, _)| *line == alarm.line && *line != 0)
        {
            Some((_, text)) => text.clone(),
            None => self.text.clone(),
        };
        RunError::Alarm {
            alarm,
            text,
            program: self.source.current_name().map(str::to_owned),
        }
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

/// The UTF-8 byte-order mark some editors put at the start of a file.
const BYTE_ORDER_MARK: &[u8] = b"\xef\xbb\xbf";

/// Whether the line is a program name, `<NAME>` or `O<NAME>` (FANUC 30i
/// program names), alone apart from blanks and a comment.
fn is_program_name(text: &[u8]) -> bool {
    let rest = text.trim_ascii_start();
    let rest = match rest {
        [b'O' | b'o', tail @ ..] => tail.trim_ascii_start(),
        _ => rest,
    };
    rest.first() == Some(&b'<') && rest.contains(&b'>')
}

/// Whether the line is Haas's `ONONAME` (the name the Haas control gives
/// a program without a program number), alone apart from blanks and a
/// comment; letters in either case.
fn is_haas_unnamed(text: &[u8]) -> bool {
    let rest = text.trim_ascii();
    let Some(head) = rest.get(..7) else {
        return false;
    };
    if !head.eq_ignore_ascii_case(b"ONONAME") {
        return false;
    }
    let tail = rest[7..].trim_ascii_start();
    tail.is_empty() || (tail.first() == Some(&b'(') && tail.last() == Some(&b')'))
}

/// Whether the line's first word is an `O`.
fn starts_with_o(text: &[u8]) -> bool {
    matches!(text.trim_ascii_start().first(), Some(b'O' | b'o'))
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
