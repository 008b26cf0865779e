//! [`AheadSource`]: a program read on a thread of its own, ahead of the
//! runner. The thread reads lines in batches through a [`ReaderSource`]
//! and, once the runner has told it its reading rules
//! ([`Source::read_blocks_as`]), reads each line's block too; the
//! runner's thread then takes lines and blocks as they come and only
//! executes. On two cores, reading the text (a quarter of the work of a
//! plain block) goes alongside executing it.
//!
//! A jump within the batch at hand (a short loop, a subprogram nearby)
//! stays in it. A jump anywhere else hands the reader back to the
//! runner's side, which from then on reads as a [`ReaderSource`] does
//! itself: a program that jumps about gains nothing but loses nothing
//! either. So does a read error (the reader is handed back in the state
//! the error left it, and the error returned).
//!
//! Invariant: lines, positions, errors and blocks are those a
//! [`ReaderSource`] on the same reader and [`parse_line_as`] give
//! (tested on random programs with random jumps).

use std::io::{self, Read, Seek};
use std::ops::Range;
use std::sync::mpsc::{self, Receiver, Sender, SyncSender};
use std::thread::JoinHandle;

use fiveaxis_gcode::{Block, Syntax, parse_line_as};

use super::{ReaderSource, Source};

/// Lines in one batch.
const BATCH_LINES: usize = 512;
/// Batches on their way to the runner at most.
const BATCHES_AHEAD: usize = 4;

/// One line read ahead.
#[derive(Clone, Debug)]
struct AheadLine {
    /// Position of the line's start and of the next line's.
    offset: u64,
    next: u64,
    text: Range<usize>,
    /// Its block (in the batch's `blocks`, same index) reads without
    /// error and is still there: [`Source::take_block`] hands it over
    /// whole, once.
    block: bool,
}

/// What follows a batch's last line.
#[derive(Debug, Default)]
enum End {
    /// More lines, in the next batch.
    #[default]
    More,
    /// The end of the program: `read_line` gives `Ok(false)` there.
    Eof,
    /// A read error at the position after the last line.
    Error(io::Error),
}

/// Lines read ahead, and their blocks.
#[derive(Debug, Default)]
struct Batch {
    text: Vec<u8>,
    lines: Vec<AheadLine>,
    /// The lines' blocks by index, kept with their buffers from batch to
    /// batch.
    blocks: Vec<Block>,
    end: End,
}

impl Batch {
    fn clear(&mut self) {
        self.text.clear();
        self.lines.clear();
        self.end = End::More;
    }
}

/// What the runner's side asks of the reading thread.
enum Command {
    /// Read blocks with these rules from the next batch on.
    Syntax(Syntax),
    /// Stop and hand the reader back.
    HandBack,
}

/// The reading thread's loop: batches of lines (and blocks) until the
/// runner asks for the reader back or goes away. Returns the reader,
/// `batches` closed (dropped here), for the thread to send back.
fn read_ahead<R: Read + Seek + Send>(
    mut source: ReaderSource<R>,
    commands: &Receiver<Command>,
    batches: SyncSender<Batch>,
    spent: &Receiver<Batch>,
) -> ReaderSource<R> {
    let mut syntax = None;
    let mut line = Vec::new();
    let mut wait = false;
    loop {
        if !obey(commands, &mut syntax, wait) {
            return source;
        }
        let mut batch = spent.try_recv().unwrap_or_default();
        batch.clear();
        for _ in 0..BATCH_LINES {
            let offset = source.position();
            match source.read_line(&mut line) {
                Ok(true) => {}
                Ok(false) => {
                    batch.end = End::Eof;
                    break;
                }
                Err(e) => {
                    batch.end = End::Error(e);
                    break;
                }
            }
            let start = batch.text.len();
            batch.text.extend_from_slice(&line);
            let k = batch.lines.len();
            if batch.blocks.len() <= k {
                batch.blocks.push(Block::default());
            }
            let read = syntax.is_some_and(|syntax| {
                parse_line_as(syntax, &line, 0, &mut batch.blocks[k]).is_ok()
            });
            batch.lines.push(AheadLine {
                offset,
                next: source.position(),
                text: start..batch.text.len(),
                block: read,
            });
        }
        // At the end of the text, wait for the runner's word.
        wait = !matches!(batch.end, End::More);
        if batches.send(batch).is_err() {
            return source;
        }
    }
}

/// Carries out the commands waiting (and with `wait`, waits for one
/// first); false when the thread is to stop: the reader asked back, or
/// the runner's side gone.
fn obey(commands: &Receiver<Command>, syntax: &mut Option<Syntax>, wait: bool) -> bool {
    let mut wait = wait;
    loop {
        let command = if wait {
            wait = false;
            commands.recv().ok()
        } else {
            match commands.try_recv() {
                Ok(c) => Some(c),
                Err(mpsc::TryRecvError::Empty) => return true,
                Err(mpsc::TryRecvError::Disconnected) => None,
            }
        };
        match command {
            Some(Command::Syntax(rules)) => *syntax = Some(rules),
            Some(Command::HandBack) | None => return false,
        }
    }
}

/// The runner's side of the thread.
struct Thread<R> {
    commands: Sender<Command>,
    batches: Receiver<Batch>,
    spent: Sender<Batch>,
    back: Receiver<ReaderSource<R>>,
    handle: JoinHandle<()>,
}

/// Where the reader is.
enum State<R> {
    /// On a thread that reads ahead.
    Ahead(Thread<R>),
    /// Back on the runner's side.
    Direct(ReaderSource<R>),
    /// Lost with a thread that stopped unexpectedly.
    Lost,
}

/// A program read ahead of the runner, on a thread of its own, in
/// batches of lines and their blocks; see the module documentation.
pub struct AheadSource<R> {
    state: State<R>,
    /// The batch at hand, the index of its next line, and the index of
    /// the line read last (whose block [`Source::take_block`] gives).
    batch: Batch,
    next: usize,
    last: Option<usize>,
    /// Position of the next line.
    pos: u64,
}

impl<R> std::fmt::Debug for AheadSource<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AheadSource")
            .field("ahead", &matches!(self.state, State::Ahead(_)))
            .field("pos", &self.pos)
            .finish()
    }
}

impl<R: Read + Seek + Send + 'static> AheadSource<R> {
    /// Reads `inner` from its current position, taken as offset 0, on a
    /// thread of its own (or directly, when no thread can start).
    pub fn new(inner: R) -> Self {
        let source = ReaderSource::new(inner);
        let (command_tx, command_rx) = mpsc::channel();
        let (batch_tx, batch_rx) = mpsc::sync_channel(BATCHES_AHEAD);
        let (spent_tx, spent_rx) = mpsc::channel();
        let (back_tx, back_rx) = mpsc::channel();
        // The reader crosses over once the thread runs, so that it stays
        // here if the thread cannot start.
        let (start_tx, start_rx) = mpsc::channel::<ReaderSource<R>>();
        let spawned = std::thread::Builder::new()
            .name("fiveaxis-read".into())
            .spawn(move || {
                if let Ok(source) = start_rx.recv() {
                    let source = read_ahead(source, &command_rx, batch_tx, &spent_rx);
                    let _ = back_tx.send(source);
                }
            });
        let state = match spawned {
            Ok(handle) => match start_tx.send(source) {
                Ok(()) => State::Ahead(Thread {
                    commands: command_tx,
                    batches: batch_rx,
                    spent: spent_tx,
                    back: back_rx,
                    handle,
                }),
                Err(mpsc::SendError(source)) => State::Direct(source),
            },
            Err(_) => State::Direct(source),
        };
        Self {
            state,
            batch: Batch::default(),
            next: 0,
            last: None,
            pos: 0,
        }
    }
}

impl<R> AheadSource<R> {
    /// Takes the reader back from the thread: this side reads from now on.
    fn hand_back(&mut self) {
        if let State::Ahead(thread) = std::mem::replace(&mut self.state, State::Lost) {
            let _ = thread.commands.send(Command::HandBack);
            // The thread closes its end of the batches before it sends
            // the reader back.
            while thread.batches.recv().is_ok() {}
            let source = thread.back.recv();
            let _ = thread.handle.join();
            if let Ok(source) = source {
                self.state = State::Direct(source);
            }
        }
        self.batch.clear();
        self.next = 0;
        self.last = None;
    }
}

fn thread_lost() -> io::Error {
    io::Error::other("the thread reading the program stopped unexpectedly")
}

impl<R: Read + Seek + Send> Source for AheadSource<R> {
    fn read_line(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        self.last = None;
        loop {
            match &mut self.state {
                State::Direct(source) => {
                    let read = source.read_line(buf);
                    self.pos = source.position();
                    return read;
                }
                State::Lost => return Err(thread_lost()),
                State::Ahead(_) => {}
            }
            if let Some(line) = self.batch.lines.get(self.next) {
                buf.clear();
                buf.extend_from_slice(&self.batch.text[line.text.clone()]);
                self.pos = line.next;
                self.last = Some(self.next);
                self.next += 1;
                return Ok(true);
            }
            match std::mem::take(&mut self.batch.end) {
                End::More => {
                    let received = match &self.state {
                        State::Ahead(thread) => thread.batches.recv().ok(),
                        _ => None,
                    };
                    match received {
                        Some(batch) => {
                            let spent = std::mem::replace(&mut self.batch, batch);
                            if let State::Ahead(thread) = &self.state {
                                let _ = thread.spent.send(spent);
                            }
                            self.next = 0;
                        }
                        // The thread stopped: whatever it left is taken
                        // back, and read from here.
                        None => {
                            self.hand_back();
                            if let State::Direct(source) = &mut self.state {
                                source.seek(self.pos)?;
                            }
                        }
                    }
                }
                End::Eof => {
                    self.batch.end = End::Eof;
                    buf.clear();
                    return Ok(false);
                }
                End::Error(e) => {
                    // The reader comes back as the error left it.
                    self.hand_back();
                    if let State::Direct(source) = &self.state {
                        self.pos = source.position();
                    }
                    buf.clear();
                    return Err(e);
                }
            }
        }
    }

    fn position(&self) -> u64 {
        self.pos
    }

    fn seek(&mut self, offset: u64) -> io::Result<()> {
        self.last = None;
        if let State::Ahead(_) = self.state {
            if offset == self.pos {
                return Ok(());
            }
            if let Ok(k) = self.batch.lines.binary_search_by_key(&offset, |l| l.offset) {
                self.next = k;
                self.pos = offset;
                return Ok(());
            }
            self.hand_back();
        }
        match &mut self.state {
            State::Direct(source) => {
                source.seek(offset)?;
                self.pos = offset;
                Ok(())
            }
            _ => Err(thread_lost()),
        }
    }

    fn read_blocks_as(&mut self, syntax: Syntax) {
        if let State::Ahead(thread) = &self.state {
            let _ = thread.commands.send(Command::Syntax(syntax));
        }
    }

    fn take_block(&mut self, line: u32, block: &mut Block) -> bool {
        let Some(k) = self.last else {
            return false;
        };
        let (Some(read), Some(ready)) = (self.batch.lines.get_mut(k), self.batch.blocks.get_mut(k))
        else {
            return false;
        };
        if !read.block {
            return false;
        }
        // Handed over by a swap: the runner's old block stays behind,
        // to be read into again.
        read.block = false;
        std::mem::swap(block, ready);
        block.line = line;
        true
    }
}
