//! `fiveaxis check`: runs programs with the soft limits lifted and reports
//! what `fiveaxis-check` finds, as text for people or JSON Lines for
//! tools (`check-contract.md`). Programs are checked in parallel (rayon)
//! and reported in the order given; a progress bar (indicatif) shows on a
//! terminal once a check has taken more than a second.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use anstyle::{AnsiColor, Style};
use fiveaxis_check::{Kind, Report, Severity, check_run};
use fiveaxis_control::{DEFAULT_MAX_BLOCKS, ReaderSource, RunError, RunOptions, Runner};
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
    /// Custom macro variables file (TOML, `500 = 1.25`) read at the start
    /// of each program.
    #[arg(long)]
    variables: Option<PathBuf>,
    /// The control's program memory: a folder of programs that M98 / G65
    /// call by number (`--programs`, as for `run` and `view`).
    #[arg(long = "programs", id = "program_memory", value_name = "DIR")]
    programs_dir: Option<PathBuf>,
}

/// One program's outcome.
type Outcome = Result<(Report, Vec<u8>), InputError>;

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
    let progress = Progress::new(args.programs.len());
    let outcomes: Vec<Outcome> = args
        .programs
        .par_iter()
        .map(|program| {
            let outcome = check_one(
                args,
                program,
                &machine,
                &offsets,
                variables.as_deref(),
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
    let mut json = Vec::new();
    for (program, outcome) in args.programs.iter().zip(&outcomes) {
        text.clear();
        json.clear();
        match outcome {
            Ok((report, source)) => {
                match args.format {
                    CheckFormat::Json => {
                        json.clear();
                        json_line(&mut json, program, report);
                        json.push(b'\n');
                    }
                    CheckFormat::Text => text_report(&mut text, program, report, source),
                }
                let fails = match args.fail_on {
                    FailOn::Error => report.fails(Severity::Error),
                    FailOn::Warning => report.fails(Severity::Warning),
                    FailOn::Never => false,
                };
                if fails && status == EXIT_OK {
                    status = EXIT_FINDINGS;
                }
            }
            Err(InputError(message)) => {
                crate::report(message);
                status = EXIT_INPUT;
            }
        }
        // JSON has no colours: it goes to standard output as it is, past
        // the stripping of escape sequences a pipe gets for text.
        let written = if json.is_empty() {
            out.write_all(text.as_bytes())
        } else {
            out.flush().and_then(|()| {
                let mut raw = io::stdout().lock();
                raw.write_all(&json).and_then(|()| raw.flush())
            })
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

/// Checks one program: its report and, for the text report, its bytes
/// (for the source lines of findings; empty for standard input).
fn check_one(
    args: &CheckArgs,
    program: &str,
    machine: &Machine,
    offsets: &Offsets,
    variables: Option<&[(u32, f64)]>,
    progress: &Progress,
) -> Outcome {
    let file = open_program(program)?;
    let options = RunOptions {
        block_delete: args.block_delete,
        interpolation: None,
        max_blocks: args.max_blocks,
        optional_stop: args.optional_stop,
        lift_soft_limits: true,
    };
    let mut runner = crate::with_memory(
        Runner::new(machine, offsets.clone(), ReaderSource::new(file), options),
        args.programs_dir.as_deref(),
        variables.map(|v| ("variables", v)),
        crate::library::ngc_folders(&args.machine, &machine.params.subroutine_path, program),
    )?;
    let mut last = 0;
    let report = check_run(&mut runner, |blocks| {
        progress.blocks(blocks - last);
        last = blocks;
    })
    .map_err(|e| match e {
        RunError::LineTooLong { line } => InputError(format!(
            "error: {program}: line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a program text"
        )),
        RunError::Io(e) => InputError::io(program, &e),
        RunError::Alarm { alarm, .. } => InputError(format!("error: {program}: {alarm}")),
    })?;
    let source = if args.format == CheckFormat::Text && program != "-" {
        std::fs::read(program).unwrap_or_default()
    } else {
        Vec::new()
    };
    Ok((report, source))
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
    let _ = serde_json::to_writer(&mut *w, text);
}

/// The contract's object for one program, appended to `w` as one line
/// (without its newline). Written directly, keys in alphabetical order,
/// with no tree of values in between: a report may hold hundreds of
/// thousands of findings.
pub fn json_line(w: &mut Vec<u8>, program: &str, report: &Report) {
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
    for (k, f) in report.findings.iter().enumerate() {
        if k > 0 {
            w.push(b',');
        }
        w.push(b'{');
        if let Some(axis) = f.axis {
            w.extend_from_slice(b"\"axis\":");
            string(w, &axis.to_string());
            w.push(b',');
        }
        w.extend_from_slice(b"\"kind\":");
        string(w, f.kind.name());
        w.extend_from_slice(format!(",\"line\":{},\"message\":", f.line).as_bytes());
        string(w, &f.message);
        w.extend_from_slice(b",\"severity\":");
        string(w, f.severity().name());
        if let Some(v) = f.value {
            w.extend_from_slice(b",\"value\":");
            number(w, v);
        }
        w.push(b'}');
    }
    w.extend_from_slice(b"],\"machine\":");
    string(w, &report.machine);
    w.extend_from_slice(b",\"program\":");
    string(w, program);
    w.extend_from_slice(b",\"time\":{\"estimated\":");
    number(w, report.time.estimated);
    w.extend_from_slice(b",\"programmed\":");
    number(w, report.time.programmed);
    w.extend_from_slice(b"}}");
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
fn text_report(t: &mut String, program: &str, report: &Report, source: &[u8]) {
    let (word, style) = verdict(report);
    let errors = report
        .findings
        .iter()
        .filter(|f| f.severity() == Severity::Error)
        .count();
    let warnings = report
        .findings
        .iter()
        .filter(|f| f.severity() == Severity::Warning)
        .count();
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
    let _ = writeln!(t, "  axes");
    for axis in &report.axes {
        axis_line(t, axis);
    }
    if report.findings.is_empty() {
        let _ = writeln!(t, "  {GREEN}no findings{GREEN:#}");
    }
    let lines: Vec<&[u8]> = source.split(|&b| b == b'\n').collect();
    for kind in Kind::ALL {
        let of_kind: Vec<_> = report.findings.iter().filter(|f| f.kind == kind).collect();
        if of_kind.is_empty() {
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
            of_kind.len()
        );
        for f in of_kind.iter().take(SHOWN_PER_KIND) {
            let _ = writeln!(
                t,
                "    line {:<6} {}",
                f.line,
                diagnostic::escape(&f.message)
            );
            if let Some(text) = lines.get(f.line.saturating_sub(1) as usize) {
                let text = String::from_utf8_lossy(text.strip_suffix(b"\r").unwrap_or(text));
                let text: String = text.chars().take(100).collect();
                let _ = writeln!(
                    t,
                    "    {DIM}{:>6} | {}{DIM:#}",
                    f.line,
                    diagnostic::escape(text.trim_end())
                );
            }
        }
        if of_kind.len() > SHOWN_PER_KIND {
            let _ = writeln!(t, "    … and {} more", of_kind.len() - SHOWN_PER_KIND);
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
                let count =
                    |s: Severity| report.findings.iter().filter(|f| f.severity() == s).count();
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
