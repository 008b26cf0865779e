//! `fiveaxis check`: runs programs with the soft limits lifted and reports
//! what `fiveaxis-check` finds, as text for people or JSON Lines for
//! tools (`check-contract.md`). Programs are checked in parallel (rayon)
//! and reported in the order given; a progress bar (indicatif) shows on a
//! terminal once a check has taken more than a second.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Seek, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use anstyle::{AnsiColor, Style};
use fiveaxis_check::{Finding, Kind, Message, Report, Severity, Word, check_run_with};
use fiveaxis_control::{AheadSource, DEFAULT_MAX_BLOCKS, RunError, RunOptions, Runner};
use fiveaxis_machine::{DEFAULT_MACHINE, Machine, Offsets};
use rayon::prelude::*;

use crate::progress::DelayedBar;
use crate::{
    EXIT_INPUT, EXIT_OK, InputError, MAX_LINE_BYTES, diagnostic, load_machine, load_variables,
    open_program, write_error,
};

/// Exit status: a finding at or above `--fail-on`.
const EXIT_FINDINGS: u8 = 1;

/// Findings of one kind listed in the text report; the rest are counted.
const SHOWN_PER_KIND: usize = 8;

/// Width of an axis bar, characters.
const BAR: usize = 32;

/// Output format of `check`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CheckFormat {
    /// A report for people.
    Text,
    /// One JSON object per program, one per line.
    Json,
}

/// Which findings make the exit status 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FailOn {
    /// Errors (over-travel, alarms).
    Error,
    /// Warnings and errors.
    Warning,
    /// None: the status is 0 unless an input cannot be used.
    Never,
}

#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Program files (`-` for standard input, once).
    #[arg(required = true)]
    programs: Vec<String>,
    /// Built-in machine name or machine file (TOML).
    #[arg(long, default_value = DEFAULT_MACHINE)]
    machine: String,
    /// Offsets file (TOML), or a LinuxCNC tool table (`.tbl`); default:
    /// the machine file's `tool_table`, else all offsets zero.
    #[arg(long)]
    offsets: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = CheckFormat::Text)]
    format: CheckFormat,
    /// Exit with status 1 when a finding of this severity or above is found.
    #[arg(long, value_enum, default_value_t = FailOn::Error)]
    fail_on: FailOn,
    /// Block delete switch on: skip blocks that start with `/`.
    #[arg(long)]
    block_delete: bool,
    /// Optional stop switch on (M01 stops like M00; the check goes on).
    #[arg(long)]
    optional_stop: bool,
    /// Stop a program that has not ended after this many lines (alarm
    /// FX0102, reported as a finding).
    #[arg(long, default_value_t = DEFAULT_MAX_BLOCKS, value_parser = clap::value_parser!(u64).range(1..))]
    max_blocks: u64,
    /// Go on after an alarm that leaves the control's state defined (a
    /// block the control refuses as a whole: an unknown G or M code, a
    /// missing feed, a word it cannot read): it is reported as an `alarm`
    /// finding and the check goes on from the next line. An alarm of the
    /// program's flow (macro statements, calls, O-words) or of the block
    /// budget still ends the check.
    #[arg(long)]
    keep_going: bool,
    /// Custom macro variables file (TOML, `500 = 1.25`) read at the start
    /// of each program.
    #[arg(long)]
    variables: Option<PathBuf>,
    /// The control's program memory: a folder of programs that M98 / G65
    /// call by number (`--programs`, as for `run` and `view`).
    #[arg(long = "programs", id = "program_memory", value_name = "DIR")]
    programs_dir: Option<PathBuf>,
    /// The work: fixtures, stock, part, collisions.
    #[command(flatten)]
    work: crate::work::WorkArgs,
}

/// One program's outcome: its report and its findings as the format keeps
/// them.
type Outcome = Result<(Report, Kept), InputError>;

/// Findings held in memory for one program before the rest go to an
/// anonymous temporary file, bytes of JSON.
const SPILL_MEMORY: usize = 1 << 20;

/// The findings of one program, kept as its report needs them: a program
/// of millions of blocks may have millions of findings, and `check` holds
/// none of them whole.
enum Kept {
    /// Every finding as its JSON object, in report order, spilled to a
    /// temporary file past [`SPILL_MEMORY`].
    Json(JsonFindings),
    /// The first [`SHOWN_PER_KIND`] findings of each kind (the report has
    /// the counts) with the source lines they name.
    Text(TextFindings),
}

/// `fiveaxis check`.
pub fn check(args: &CheckArgs) -> Result<u8, InputError> {
    let machine = load_machine(&args.machine)?;
    let offsets = crate::load_offsets_for(&args.machine, &machine, args.offsets.as_deref())?;
    let variables = match &args.variables {
        Some(path) => Some(load_variables(&path.display().to_string(), path)?),
        None => None,
    };
    if args.programs.iter().filter(|p| *p == "-").count() > 1 {
        return Err(InputError(
            "error: standard input (`-`) can be checked once only".into(),
        ));
    }
    let work = crate::work::Work::read(&args.work, args.programs.len(), &offsets)?;
    let progress = Progress::new(args.programs.len());
    let mut outcomes: Vec<Outcome> = args
        .programs
        .par_iter()
        .map(|program| {
            let outcome = check_one(
                args,
                program,
                &machine,
                &offsets,
                variables.as_deref(),
                &work,
                &progress,
            );
            progress.program_done();
            outcome
        })
        .collect();
    progress.finish();

    let mut out = anstream::stdout().lock();
    let mut status = EXIT_OK;
    let mut text = String::new();
    for (program, outcome) in args.programs.iter().zip(outcomes.iter_mut()) {
        text.clear();
        let written = match outcome {
            Ok((report, kept)) => {
                let fails = match args.fail_on {
                    FailOn::Error => report.fails(Severity::Error),
                    FailOn::Warning => report.fails(Severity::Warning),
                    FailOn::Never => false,
                };
                if fails && status == EXIT_OK {
                    status = EXIT_FINDINGS;
                }
                match kept {
                    // JSON has no colours: it goes to standard output as it
                    // is, past the stripping of escape sequences a pipe gets
                    // for text.
                    Kept::Json(findings) => out.flush().and_then(|()| {
                        let mut raw = io::BufWriter::new(io::stdout().lock());
                        write_json(&mut raw, program, report, findings).and_then(|()| raw.flush())
                    }),
                    Kept::Text(findings) => {
                        text_report(&mut text, program, report, findings);
                        out.write_all(text.as_bytes())
                    }
                }
            }
            Err(InputError(message)) => {
                crate::report(message);
                status = EXIT_INPUT;
                Ok(())
            }
        };
        if let Err(e) = written {
            return broken_pipe_or(e, status);
        }
    }
    if args.format == CheckFormat::Text && outcomes.len() > 1 {
        text.clear();
        summary(&mut text, &args.programs, &outcomes);
        if let Err(e) = out.write_all(text.as_bytes()) {
            return broken_pipe_or(e, status);
        }
    }
    match out.flush() {
        Ok(()) => Ok(status),
        Err(e) => broken_pipe_or(e, status),
    }
}

/// A reader that went away (`| head`) is not an error.
fn broken_pipe_or(e: io::Error, status: u8) -> Result<u8, InputError> {
    if e.kind() == io::ErrorKind::BrokenPipe {
        Ok(status)
    } else {
        Err(write_error("standard output", &e))
    }
}

/// Checks one program: its report and its findings as the format keeps
/// them.
fn check_one(
    args: &CheckArgs,
    program: &str,
    machine: &Machine,
    offsets: &Offsets,
    variables: Option<&[(u32, f64)]>,
    work: &crate::work::Work,
    progress: &Progress,
) -> Outcome {
    let mut file = open_program(program)?;
    let sinumerik = crate::machine_for_program(machine, program, &mut file);
    let machine = sinumerik.as_ref().unwrap_or(machine);
    // The text report quotes the lines of its findings: read again from
    // the start once the run is over (standard input is a spooled file).
    let source = match args.format {
        CheckFormat::Text => Some(file.try_clone().map_err(|e| InputError::io(program, &e))?),
        CheckFormat::Json => None,
    };
    let options = RunOptions {
        block_delete: args.block_delete,
        interpolation: None,
        max_blocks: args.max_blocks,
        optional_stop: args.optional_stop,
        lift_soft_limits: true,
    };
    let mut runner = crate::with_memory(
        Runner::new(machine, offsets.clone(), AheadSource::new(file), options),
        args.programs_dir.as_deref(),
        variables.map(|v| ("variables", v)),
        crate::library::ngc_folders(&args.machine, &machine.params.subroutine_path, program),
    )?;
    let mut last = 0;
    let mut json = JsonFindings::default();
    let mut text = TextFindings::default();
    let mut spill_error = None;
    let (checks, kept_stock) = work.checks(&args.work, machine, offsets)?;
    let (report, whole_program) = check_run_with(
        &mut runner,
        args.keep_going,
        checks,
        |blocks| {
            progress.blocks(blocks - last);
            last = blocks;
        },
        |finding| match args.format {
            CheckFormat::Json => {
                if spill_error.is_none()
                    && let Err(e) = json.push(&finding)
                {
                    spill_error = Some(e);
                }
            }
            CheckFormat::Text => text.push(finding),
        },
    )
    .map_err(|e| match e {
        RunError::LineTooLong { line } => InputError(format!(
            "error: {program}: line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a program text"
        )),
        RunError::Io(e) => InputError::io(program, &e),
        RunError::Alarm { alarm, .. } => InputError(format!("error: {program}: {alarm}")),
    })?;
    if let Some(e) = spill_error {
        return Err(InputError::io("temporary file", &e));
    }
    if report.stock.is_none() && (args.work.part.is_some() || args.work.stock_out.is_some()) {
        return Err(InputError(format!(
            "error: {program}: --part and --stock-out need a stock: give --stock (the program declares none)"
        )));
    }
    if let Some(path) = &args.work.stock_out {
        let left = kept_stock.lock().ok().and_then(|mut s| s.take());
        if let Some(left) = left {
            crate::work::write_stl(path, &left.dexels)?;
        }
    }
    let kept = match source {
        None => {
            json.whole_program = whole_program.map(Box::new);
            Kept::Json(json)
        }
        Some(file) => {
            if let Some(f) = whole_program {
                text.push(f);
            }
            text.read_lines(file)
                .map_err(|e| InputError::io(program, &e))?;
            Kept::Text(text)
        }
    };
    Ok((report, kept))
}

/// The progress bar on standard error: hidden for the first second, and
/// altogether when standard error is not a terminal (indicatif's rule).
struct Progress {
    bar: DelayedBar,
    blocks: AtomicU64,
}

impl Progress {
    fn new(programs: usize) -> Self {
        Self {
            bar: DelayedBar::new(
                programs as u64,
                "{spinner} checking [{bar:30}] {pos}/{len} programs, {msg} {elapsed}",
            ),
            blocks: AtomicU64::new(0),
        }
    }

    fn blocks(&self, more: u64) {
        let total = self.blocks.fetch_add(more, Ordering::Relaxed) + more;
        if let Some(bar) = self.bar.visible() {
            bar.set_message(format!("{total} blocks"));
        }
    }

    fn program_done(&self) {
        self.bar.bar().inc(1);
    }

    fn finish(&self) {
        self.bar.finish();
    }
}

// ----- JSON ------------------------------------------------------------------

/// Writes `x` as JSON: a number, or `null` when it is not finite.
fn number(w: &mut Vec<u8>, x: f64) {
    if x.is_finite() {
        // serde_json's shortest round-trip form, as the rows use.
        let _ = serde_json::to_writer(&mut *w, &x);
    } else {
        w.extend_from_slice(b"null");
    }
}

/// Writes `text` as a JSON string (quoted and escaped).
fn string(w: &mut Vec<u8>, text: &str) {
    w.reserve(text.len() + 2);
    w.push(b'"');
    escaped(w, text);
    w.push(b'"');
}

/// Writes the inside of a JSON string: `text` with quotes, backslashes and
/// control characters escaped. Most texts need no escape:
/// [`needs_escape`] finds it eight bytes at a time, and they are copied as
/// they are (JSON takes UTF-8 unescaped); the others go through
/// `serde_json`, whose quotes are taken off.
fn escaped(w: &mut Vec<u8>, text: &str) {
    if !needs_escape(text.as_bytes()) {
        w.extend_from_slice(text.as_bytes());
        return;
    }
    let start = w.len();
    if serde_json::to_writer(&mut *w, text).is_ok() {
        w.remove(start);
        w.pop();
    }
}

/// Whether `bytes` hold a quote, a backslash or a control character,
/// tested a word of eight bytes at a time: a word has a byte below `n`
/// (`n` at most 128) exactly when `(w − n·0x01…01) & !w & 0x80…80` is not
/// zero, and a byte equal to `c` when `w ^ c·0x01…01` has a zero byte.
fn needs_escape(bytes: &[u8]) -> bool {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGHS: u64 = 0x8080_8080_8080_8080;
    let below = |w: u64, n: u8| w.wrapping_sub(ONES * u64::from(n)) & !w & HIGHS != 0;
    let mut words = bytes.chunks_exact(8);
    for word in &mut words {
        let mut eight = [0; 8];
        eight.copy_from_slice(word);
        let w = u64::from_le_bytes(eight);
        if below(w, 0x20)
            || below(w ^ (ONES * u64::from(b'"')), 1)
            || below(w ^ (ONES * u64::from(b'\\')), 1)
        {
            return true;
        }
    }
    words
        .remainder()
        .iter()
        .any(|&b| b < 0x20 || b == b'"' || b == b'\\')
}

/// A name of the contract (a kind, a severity: letters and underscores)
/// as a JSON string.
fn contract_name(w: &mut Vec<u8>, name: &str) {
    w.push(b'"');
    w.extend_from_slice(name.as_bytes());
    w.push(b'"');
}

/// A finding's message as a JSON string: its numbers written by the
/// rows' number writer (the text Rust's `{}` gives, as the message's own
/// `Display`), through `scratch`; its words escaped.
fn message_json(w: &mut Vec<u8>, scratch: &mut crate::text::Text, message: &Message) {
    w.push(b'"');
    for word in message.words() {
        match word {
            Word::Text(text) => escaped(w, text),
            Word::Letter(c @ ('A'..='Z' | 'a'..='z' | '0'..='9' | '+' | '-')) => {
                w.push(c as u8);
            }
            Word::Letter(c) => escaped(w, c.encode_utf8(&mut [0; 4])),
            Word::Number(x) => {
                scratch.clear();
                crate::number::write_f64(scratch, x);
                w.extend_from_slice(scratch.as_bytes());
            }
        }
    }
    w.push(b'"');
}

/// One finding as the contract's object.
fn finding_json(w: &mut Vec<u8>, scratch: &mut crate::text::Text, f: &Finding) {
    w.push(b'{');
    if let Some(axis) = f.axis {
        w.extend_from_slice(b"\"axis\":");
        if axis.is_ascii_alphabetic() {
            w.extend_from_slice(&[b'"', axis as u8, b'"']);
        } else {
            string(w, axis.encode_utf8(&mut [0; 4]));
        }
        w.push(b',');
    }
    if let Some(bodies) = &f.bodies {
        w.extend_from_slice(b"\"bodies\":[");
        string(w, &bodies[0]);
        w.push(b',');
        string(w, &bodies[1]);
        w.extend_from_slice(b"],");
    }
    w.extend_from_slice(b"\"kind\":");
    contract_name(w, f.kind.name());
    w.extend_from_slice(b",\"line\":");
    w.extend_from_slice(itoa::Buffer::new().format(f.line).as_bytes());
    w.extend_from_slice(b",\"message\":");
    message_json(w, scratch, &f.message);
    w.extend_from_slice(b",\"severity\":");
    contract_name(w, f.severity().name());
    if let Some(v) = f.value {
        w.extend_from_slice(b",\"value\":");
        number(w, v);
    }
    w.push(b'}');
}

/// Every finding of one program as JSON objects, in report order, each
/// after its line (4 bytes) and length (4 bytes): in memory up to
/// [`SPILL_MEMORY`], then in an anonymous temporary file. The finding
/// about the whole program comes at the end of the run and is placed as it
/// is copied out.
#[derive(Default)]
pub struct JsonFindings {
    memory: Vec<u8>,
    file: Option<io::BufWriter<File>>,
    record: Vec<u8>,
    /// Where a message's numbers are written before they are copied.
    scratch: crate::text::Text,
    whole_program: Option<Box<Finding>>,
}

impl JsonFindings {
    /// Adds the next finding.
    ///
    /// # Errors
    ///
    /// The temporary file cannot be made or written.
    pub fn push(&mut self, f: &Finding) -> io::Result<()> {
        self.record.clear();
        finding_json(&mut self.record, &mut self.scratch, f);
        let len = u32::try_from(self.record.len()).unwrap_or(u32::MAX);
        let mut head = [0; 8];
        head[..4].copy_from_slice(&f.line.to_le_bytes());
        head[4..].copy_from_slice(&len.to_le_bytes());
        if self.file.is_none() && self.memory.len() + self.record.len() > SPILL_MEMORY {
            let mut file = io::BufWriter::new(tempfile::tempfile()?);
            file.write_all(&self.memory)?;
            self.memory = Vec::new();
            self.file = Some(file);
        }
        match &mut self.file {
            Some(file) => {
                file.write_all(&head)?;
                file.write_all(&self.record)
            }
            None => {
                self.memory.extend_from_slice(&head);
                self.memory.extend_from_slice(&self.record);
                Ok(())
            }
        }
    }

    /// Writes the findings, comma-separated, with the whole-program one in
    /// its place (before the first of a later line).
    fn copy_to(&mut self, w: &mut dyn Write) -> io::Result<()> {
        let mut whole = self.whole_program.as_ref().map(|f| {
            let mut json = Vec::new();
            finding_json(&mut json, &mut self.scratch, f);
            (f.line, json)
        });
        let mut reader: Box<dyn Read + '_> = match self.file.take() {
            Some(file) => {
                let mut file = file.into_inner().map_err(io::IntoInnerError::into_error)?;
                file.rewind()?;
                Box::new(BufReader::new(file))
            }
            None => Box::new(&self.memory[..]),
        };
        let mut first = true;
        let mut head = [0u8; 8];
        let mut record = Vec::new();
        loop {
            match reader.read_exact(&mut head) {
                Ok(()) => {}
                Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => break,
                Err(e) => return Err(e),
            }
            let line = u32::from_le_bytes([head[0], head[1], head[2], head[3]]);
            let len = u32::from_le_bytes([head[4], head[5], head[6], head[7]]) as usize;
            record.resize(len, 0);
            reader.read_exact(&mut record)?;
            if let Some((_, json)) = whole.take_if(|(at, _)| line > *at) {
                separate(w, &mut first)?;
                w.write_all(&json)?;
            }
            separate(w, &mut first)?;
            w.write_all(&record)?;
        }
        if let Some((_, json)) = whole {
            separate(w, &mut first)?;
            w.write_all(&json)?;
        }
        Ok(())
    }
}

/// A comma before every element of a list but its first.
fn separate(w: &mut dyn Write, first: &mut bool) -> io::Result<()> {
    if !std::mem::take(first) {
        w.write_all(b",")?;
    }
    Ok(())
}

/// The contract's object for one program as one line: written directly,
/// keys in alphabetical order, with no tree of values in between; the
/// findings are copied from where they were kept.
fn write_json(
    out: &mut dyn Write,
    program: &str,
    report: &Report,
    findings: &mut JsonFindings,
) -> io::Result<()> {
    let mut w = Vec::new();
    json_head(&mut w, report);
    out.write_all(&w)?;
    findings.copy_to(out)?;
    w.clear();
    json_tail(&mut w, program, report);
    w.push(b'\n');
    out.write_all(&w)
}

/// The object up to the findings' list, opened.
fn json_head(w: &mut Vec<u8>, report: &Report) {
    w.extend_from_slice(b"{\"alarm\":");
    match &report.alarm {
        Some(a) => {
            w.extend_from_slice(b"{\"code\":");
            string(w, &a.code);
            w.extend_from_slice(format!(",\"line\":{},\"message\":", a.line).as_bytes());
            string(w, &a.message);
            w.push(b'}');
        }
        None => w.extend_from_slice(b"null"),
    }
    w.extend_from_slice(b",\"axes\":{");
    let mut axes: Vec<&fiveaxis_check::AxisRange> = report.axes.iter().collect();
    axes.sort_by_key(|a| a.name);
    for (k, axis) in axes.into_iter().enumerate() {
        if k > 0 {
            w.push(b',');
        }
        string(w, &axis.name.to_string());
        w.extend_from_slice(b":{\"limit_max\":");
        let (lo, hi) = axis.limits.map_or((f64::NAN, f64::NAN), |l| l);
        number(w, hi);
        w.extend_from_slice(b",\"limit_min\":");
        number(w, lo);
        w.extend_from_slice(b",\"max\":");
        number(w, axis.max);
        w.extend_from_slice(b",\"min\":");
        number(w, axis.min);
        w.push(b'}');
    }
    w.extend_from_slice(
        format!(
            "}},\"blocks\":{},\"ended\":{},\"findings\":[",
            report.blocks, report.ended
        )
        .as_bytes(),
    );
}

/// The object from the end of the findings' list.
fn json_tail(w: &mut Vec<u8>, program: &str, report: &Report) {
    w.extend_from_slice(b"],\"machine\":");
    string(w, &report.machine);
    w.extend_from_slice(b",\"program\":");
    string(w, program);
    if let Some(stock) = &report.stock {
        w.extend_from_slice(b",\"stock\":{\"air_cut_seconds\":");
        number(w, stock.air_cut_seconds);
        w.extend_from_slice(b",\"end_volume\":");
        number(w, stock.end_volume);
        w.extend_from_slice(b",\"removed\":{");
        for (k, (tool, volume)) in stock.removed.iter().enumerate() {
            if k > 0 {
                w.push(b',');
            }
            string(w, &tool.to_string());
            w.push(b':');
            number(w, *volume);
        }
        w.extend_from_slice(b"},\"resolution\":");
        number(w, stock.resolution);
        w.extend_from_slice(b",\"start_volume\":");
        number(w, stock.start_volume);
        w.push(b'}');
    }
    w.extend_from_slice(b",\"time\":{\"estimated\":");
    number(w, report.time.estimated);
    w.extend_from_slice(b",\"programmed\":");
    number(w, report.time.programmed);
    w.extend_from_slice(b"}}");
}

/// What the text report shows of the findings: the first
/// [`SHOWN_PER_KIND`] of each kind, and the source lines they name.
#[derive(Default)]
pub struct TextFindings {
    shown: Vec<Finding>,
    /// The text of the lines the shown findings name, by line number.
    lines: std::collections::BTreeMap<u32, String>,
}

impl TextFindings {
    /// Adds the next finding: kept if fewer than [`SHOWN_PER_KIND`] of its
    /// kind are.
    pub fn push(&mut self, f: Finding) {
        let of_kind = self.shown.iter().filter(|s| s.kind == f.kind).count();
        if of_kind < SHOWN_PER_KIND {
            self.shown.push(f);
        }
    }

    /// Reads the lines the shown findings name from the program, from its
    /// start, as far as the last of them.
    fn read_lines(&mut self, mut file: File) -> io::Result<()> {
        for f in &self.shown {
            self.lines.entry(f.line).or_default();
        }
        let Some(&last) = self.lines.keys().next_back() else {
            return Ok(());
        };
        file.rewind()?;
        // The run read every line up to the last finding's, each within
        // the line limit; a longer one is cut, not held.
        let mut reader = BufReader::new(file).take(u64::MAX);
        let mut buf = Vec::new();
        for number in 1..=last {
            buf.clear();
            let limit = (MAX_LINE_BYTES + 2) as u64;
            reader.set_limit(limit);
            if reader.read_until(b'\n', &mut buf)? == 0 {
                break;
            }
            reader.set_limit(u64::MAX);
            if !buf.ends_with(b"\n") && buf.len() as u64 == limit {
                break;
            }
            if let Some(text) = self.lines.get_mut(&number) {
                let line = buf.strip_suffix(b"\n").unwrap_or(&buf);
                let line = line.strip_suffix(b"\r").unwrap_or(line);
                *text = String::from_utf8_lossy(line).chars().take(100).collect();
            }
        }
        Ok(())
    }
}

// ----- text ------------------------------------------------------------------

const RED: Style = AnsiColor::Red.on_default().bold();
const YELLOW: Style = AnsiColor::Yellow.on_default().bold();
const GREEN: Style = AnsiColor::Green.on_default().bold();
const DIM: Style = Style::new().dimmed();
const BOLD: Style = Style::new().bold();

/// Verdict word and its style.
fn verdict(report: &Report) -> (&'static str, Style) {
    if report.fails(Severity::Error) {
        ("FAIL", RED)
    } else if report.fails(Severity::Warning) {
        ("WARN", YELLOW)
    } else {
        ("PASS", GREEN)
    }
}

/// Seconds as `1 h 02 min`, `12 min 05 s` or `4.2 s`.
/// A volume for people: mm³ below a cm³, else cm³.
fn volume(mm3: f64) -> String {
    if mm3.abs() < 1000.0 {
        format!("{mm3:.1} mm³")
    } else {
        format!("{:.2} cm³", mm3 / 1000.0)
    }
}

fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "-".into();
    }
    let whole = seconds.round() as u64;
    if whole >= 3600 {
        format!("{} h {:02} min", whole / 3600, (whole % 3600) / 60)
    } else if whole >= 60 {
        format!("{} min {:02} s", whole / 60, whole % 60)
    } else {
        format!("{seconds:.1} s")
    }
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("1 {word}")
    } else {
        format!("{n} {word}s")
    }
}

/// A report for people: verdict, time, axis ranges as bars against their
/// limits, findings grouped by kind with their lines and source text.
fn text_report(t: &mut String, program: &str, report: &Report, findings: &TextFindings) {
    let (word, style) = verdict(report);
    let errors = report.count_severity(Severity::Error);
    let warnings = report.count_severity(Severity::Warning);
    let _ = writeln!(
        t,
        "{style}{word}{style:#}  {BOLD}{}{BOLD:#} on {}: {}, {}",
        diagnostic::escape(program),
        diagnostic::escape(&report.machine),
        plural(errors, "error"),
        plural(warnings, "warning"),
    );
    let end = match &report.alarm {
        Some(a) => format!("stopped by alarm {} at line {}", a.code, a.line),
        None if report.ended => "ran to its end".into(),
        None => "did not end".into(),
    };
    let _ = writeln!(
        t,
        "  time    {} programmed, {} estimated; {} blocks, {end}",
        duration(report.time.programmed),
        duration(report.time.estimated),
        report.blocks,
    );
    if report.feed_limited_seconds > 0.0 {
        let _ = writeln!(
            t,
            "          feed limits add about {} to it",
            duration(report.feed_limited_seconds)
        );
    }
    if let Some(stock) = &report.stock {
        let tools: Vec<String> = stock
            .removed
            .iter()
            .filter(|(_, v)| **v > 0.0)
            .map(|(t, v)| format!("T{t} {}", volume(*v)))
            .collect();
        let _ = writeln!(
            t,
            "  stock   {} removed of {} ({}), {} left; cutting air {}",
            volume(stock.start_volume - stock.end_volume),
            volume(stock.start_volume),
            if tools.is_empty() {
                "no tool cut".to_string()
            } else {
                tools.join(", ")
            },
            volume(stock.end_volume),
            duration(stock.air_cut_seconds)
        );
    }
    let _ = writeln!(t, "  axes");
    for axis in &report.axes {
        axis_line(t, axis);
    }
    if report.total() == 0 {
        let _ = writeln!(t, "  {GREEN}no findings{GREEN:#}");
    }
    let mut kinds = Kind::ALL;
    // Errors first, then warnings, then information.
    kinds.sort_by_key(|k| std::cmp::Reverse(k.severity()));
    for kind in kinds {
        let count = report.count(kind);
        if count == 0 {
            continue;
        }
        let style = match kind.severity() {
            Severity::Error => RED,
            Severity::Warning => YELLOW,
            Severity::Info => BOLD,
        };
        let _ = writeln!(
            t,
            "  {style}{}{style:#} ({}, {})",
            kind.name(),
            kind.severity().name(),
            count
        );
        let shown = findings.shown.iter().filter(|f| f.kind == kind);
        for f in shown.clone() {
            let _ = writeln!(
                t,
                "    line {:<6} {}",
                f.line,
                diagnostic::escape(&f.message.to_string())
            );
            if let Some(text) = findings.lines.get(&f.line) {
                let _ = writeln!(
                    t,
                    "    {DIM}{:>6} | {}{DIM:#}",
                    f.line,
                    diagnostic::escape(text.trim_end())
                );
            }
        }
        let more = count - shown.count();
        if more > 0 {
            let _ = writeln!(t, "    … and {more} more (the JSON report lists every one)");
        }
    }
    t.push('\n');
}

/// One axis: its range, and a bar of the travel between its limits with
/// the part used filled in (red where it goes past a limit).
fn axis_line(t: &mut String, axis: &fiveaxis_check::AxisRange) {
    let range = format!("{:>10.3} .. {:<10.3}", axis.min, axis.max);
    let Some((lo, hi)) = axis.limits else {
        let _ = writeln!(t, "    {}  {range}  {DIM}(no limits){DIM:#}", axis.name);
        return;
    };
    let cell = |x: f64| {
        (((x - lo) / (hi - lo)) * BAR as f64)
            .floor()
            .clamp(0.0, BAR as f64 - 1.0) as usize
    };
    let (a, b) = (cell(axis.min), cell(axis.max));
    let mut bar = String::new();
    for k in 0..BAR {
        bar.push(if (a..=b).contains(&k) { '#' } else { '-' });
    }
    let over_lo = axis.min < lo - fiveaxis_check::LIMIT_TOLERANCE;
    let over_hi = axis.max > hi + fiveaxis_check::LIMIT_TOLERANCE;
    let mark = |over: bool| {
        if over {
            format!("{RED}!{RED:#}")
        } else {
            "|".into()
        }
    };
    let style = if over_lo || over_hi {
        RED
    } else {
        Style::new()
    };
    let _ = writeln!(
        t,
        "    {}  {range}  {:>9} {}{style}{bar}{style:#}{} {hi}",
        axis.name,
        format!("{lo}"),
        mark(over_lo),
        mark(over_hi),
    );
}

/// The table after several programs.
fn summary(t: &mut String, programs: &[String], outcomes: &[Outcome]) {
    let width = programs
        .iter()
        .map(|p| p.chars().count())
        .max()
        .unwrap_or(7)
        .clamp(7, 48);
    let _ = writeln!(
        t,
        "{BOLD}{:<width$}  verdict  errors  warnings  time          blocks{BOLD:#}",
        "program"
    );
    for (program, outcome) in programs.iter().zip(outcomes) {
        let name: String = diagnostic::escape(program).chars().take(width).collect();
        match outcome {
            Ok((report, _)) => {
                let (word, style) = verdict(report);
                let count = |s: Severity| report.count_severity(s);
                let _ = writeln!(
                    t,
                    "{name:<width$}  {style}{word:<7}{style:#}  {:>6}  {:>8}  {:<12}  {:>6}",
                    count(Severity::Error),
                    count(Severity::Warning),
                    duration(report.time.programmed),
                    report.blocks
                );
            }
            Err(_) => {
                let _ = writeln!(
                    t,
                    "{name:<width$}  {RED}{:<7}{RED:#}  (could not be read)",
                    "INPUT"
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{message_json, needs_escape, string};
    use fiveaxis_check::{Message, Word};
    use proptest::prelude::*;

    /// The plain copy and the escaping writer agree with serde_json on
    /// texts with and without characters JSON escapes.
    #[test]
    fn json_strings_are_serde_json_strings() {
        let texts = [
            "",
            "C turns 93.637° in one block (more than 90°)",
            "a \"quoted\" word",
            "back\\slash",
            "tab\tand\nnewline",
            "bell \u{7}",
            "DEL \u{7f} and ünïcödé",
        ];
        for text in texts {
            let mut ours = Vec::new();
            string(&mut ours, text);
            let theirs = serde_json::to_vec(text).expect("serialises");
            assert_eq!(ours, theirs, "{text:?}");
        }
        let controls: String = (0u8..0x20).map(char::from).collect();
        let mut ours = Vec::new();
        string(&mut ours, &controls);
        assert_eq!(ours, serde_json::to_vec(&controls).expect("serialises"));
    }

    /// Each byte JSON escapes is found at every place of a text, in the
    /// words of eight bytes and in the rest; no other ASCII byte is.
    #[test]
    fn escapes_are_found_wherever_they_are() {
        let plain: Vec<u8> = (0x20u8..0x7f)
            .filter(|&b| b != b'"' && b != b'\\')
            .collect();
        assert!(!needs_escape(&plain));
        for len in 1..20 {
            for at in 0..len {
                for special in (0u8..0x20).chain([b'"', b'\\']) {
                    let mut text = plain[..len].to_vec();
                    text[at] = special;
                    assert!(needs_escape(&text), "{len} {at} {special}");
                }
            }
        }
    }

    proptest! {
        /// Any text is written as serde_json writes it.
        #[test]
        fn any_text_is_a_serde_json_string(text in any::<String>()) {
            let mut ours = Vec::new();
            string(&mut ours, &text);
            prop_assert_eq!(ours, serde_json::to_vec(&text).expect("serialises"));
        }

        /// A message kept as words is written as the JSON string of its
        /// text: numbers as Rust's `{}` writes them, at every magnitude.
        #[test]
        fn messages_are_the_json_strings_of_their_text(
            x in any::<f64>(),
            y in prop_oneof![-1e6..1e6f64, (-1e6..1e6f64).prop_map(|v| (v * 1e3).round() / 1e3)],
            name in proptest::char::range('A', 'Z'),
        ) {
            let message = Message::of(&[
                Word::Letter(name),
                Word::Text(" \"turns\" "),
                Word::Number(x),
                Word::Text("° in\tone block ("),
                Word::Number(y),
                Word::Text(")"),
            ]);
            let mut ours = Vec::new();
            message_json(&mut ours, &mut crate::text::Text::default(), &message);
            let theirs = serde_json::to_vec(&message.to_string()).expect("serialises");
            prop_assert_eq!(ours, theirs);
        }
    }
}
