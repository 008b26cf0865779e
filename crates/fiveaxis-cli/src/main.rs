//! `fiveaxis`: runs 5-axis G-code programs on a machine model and prints
//! the machine-axis motion the control would command.

mod diagnostic;
mod number;
mod output;
mod text;

use std::fs::File;
use std::io::{self, BufReader, Seek, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::mpsc;

use clap::{Parser, Subcommand};
use fiveaxis_control::{Alarm, ReaderSource, Row, RunError, RunOptions, Runner, Segment, Source};
use fiveaxis_machine::{DEFAULT_MACHINE, FileError, Machine, Offsets, builtin, builtin_names};

use output::{Format, RowWriter};
use text::Text;

/// Exit status: the program ran to its end.
const EXIT_OK: u8 = 0;
/// Exit status: an alarm stopped the program.
const EXIT_ALARM: u8 = 1;
/// Exit status: the inputs could not be used.
const EXIT_INPUT: u8 = 2;

#[derive(Debug, Parser)]
#[command(
    name = "fiveaxis",
    version,
    about = "A 5-axis CNC kernel: G-code in, machine-axis motion out"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a program on a machine and print every machine position.
    Run(RunArgs),
    /// List the built-in machines, or print one as a machine file.
    Machines {
        #[command(subcommand)]
        action: Option<MachinesAction>,
    },
}

#[derive(Debug, Subcommand)]
enum MachinesAction {
    /// Print a built-in machine as a machine file to copy and edit.
    Show {
        /// Name of the built-in machine.
        name: String,
    },
}

#[derive(Debug, clap::Args)]
struct RunArgs {
    /// Program file, or `-` for standard input.
    program: String,
    /// Built-in machine name or machine file (TOML).
    #[arg(long, default_value = DEFAULT_MACHINE)]
    machine: String,
    /// Offsets file (TOML); default: all offsets zero.
    #[arg(long)]
    offsets: Option<PathBuf>,
    /// Also emit rows inside blocks, tool tips at most this far apart (mm).
    #[arg(long, value_parser = positive)]
    step: Option<f64>,
    /// With --step: most rotary motion between rows (degrees).
    #[arg(long, default_value_t = 1.0, value_parser = positive)]
    step_angle: f64,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    format: Format,
    /// Write to this file (whole or not at all) instead of standard output.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Block delete switch on: skip blocks that start with `/`.
    #[arg(long)]
    block_delete: bool,
}

fn positive(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("`{text}` is not a positive number")),
    }
}

/// An input that cannot be used: exit status 2.
#[derive(Debug)]
struct InputError(String);

impl InputError {
    fn io(path: &str, error: &io::Error) -> Self {
        Self(format!("error: {path}: {error}"))
    }

    fn file(path: &str, text: &str, error: &FileError) -> Self {
        let line_text = text
            .lines()
            .nth(error.line.saturating_sub(1) as usize)
            .unwrap_or("");
        let column = error.column.max(1);
        let title = match &error.key {
            Some(key) => format!(
                "{path}:{}:{}: {} (key `{key}`)",
                error.line, error.column, error.message
            ),
            None => format!("{path}:{}:{}: {}", error.line, error.column, error.message),
        };
        let snippet = diagnostic::render(
            path,
            error.line,
            line_text,
            Some((column, column + 1)),
            &title,
            "here",
        );
        Self(format!("error: {title}\n{snippet}"))
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let status = match cli.command {
        Command::Run(args) => run(&args),
        Command::Machines { action: None } => list_machines(),
        Command::Machines {
            action: Some(MachinesAction::Show { name }),
        } => show_machine(&name),
    };
    match status {
        Ok(code) => ExitCode::from(code),
        Err(InputError(message)) => {
            eprintln!("{message}");
            ExitCode::from(EXIT_INPUT)
        }
    }
}

fn list_machines() -> Result<u8, InputError> {
    let mut out = io::stdout().lock();
    for &name in builtin_names() {
        let description = builtin(name).map(|m| m.name).unwrap_or_default();
        let marker = if name == DEFAULT_MACHINE {
            " (default)"
        } else {
            ""
        };
        writeln!(out, "{name:<16} {description}{marker}")
            .map_err(|e| InputError::io("stdout", &e))?;
    }
    Ok(EXIT_OK)
}

fn show_machine(name: &str) -> Result<u8, InputError> {
    let machine = builtin(name).ok_or_else(|| unknown_machine(name))?;
    print!("{}", machine.to_toml());
    Ok(EXIT_OK)
}

fn unknown_machine(name: &str) -> InputError {
    InputError(format!(
        "error: `{name}` is neither a built-in machine nor a machine file; built-in machines: {}",
        builtin_names().join(", ")
    ))
}

fn load_machine(spec: &str) -> Result<Machine, InputError> {
    if let Some(machine) = builtin(spec) {
        return Ok(machine);
    }
    if !Path::new(spec).exists() {
        return Err(unknown_machine(spec));
    }
    let text = std::fs::read_to_string(spec).map_err(|e| InputError::io(spec, &e))?;
    Machine::from_toml(&text).map_err(|e| InputError::file(spec, &text, &e))
}

fn load_offsets(path: Option<&Path>) -> Result<Offsets, InputError> {
    let Some(path) = path else {
        return Ok(Offsets::default());
    };
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError::io(&name, &e))?;
    Offsets::from_toml(&text).map_err(|e| InputError::file(&name, &text, &e))
}

/// The program as a seekable file: the file itself, or standard input
/// spooled to an anonymous temporary file (so that subprogram calls can
/// jump back and memory stays constant).
fn open_program(spec: &str) -> Result<File, InputError> {
    if spec == "-" {
        let mut spool = tempfile::tempfile().map_err(|e| InputError::io("temporary file", &e))?;
        io::copy(&mut io::stdin().lock(), &mut spool)
            .map_err(|e| InputError::io("standard input", &e))?;
        spool
            .rewind()
            .map_err(|e| InputError::io("temporary file", &e))?;
        Ok(spool)
    } else {
        File::open(spec).map_err(|e| InputError::io(spec, &e))
    }
}

fn run(args: &RunArgs) -> Result<u8, InputError> {
    let machine = load_machine(&args.machine)?;
    let offsets = load_offsets(args.offsets.as_deref())?;
    let file = open_program(&args.program)?;
    let program_name = if args.program == "-" {
        "<stdin>"
    } else {
        args.program.as_str()
    };
    let source = ReaderSource::new(BufReader::with_capacity(1 << 16, file));
    let options = RunOptions {
        block_delete: args.block_delete,
    };
    let runner = Runner::new(&machine, offsets, source, options);
    let writer = RowWriter::new(args.format, &machine);

    match &args.output {
        None => {
            let result = stream(runner, &writer, args, io::stdout());
            finish(result, program_name, "standard output")
        }
        Some(path) => {
            let name = path.display().to_string();
            // A device or pipe (`-o /dev/null`) is written to as it is; a
            // file is written beside its place and renamed over it when
            // whole, so that it is never seen half written.
            let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file());
            if special {
                let file = File::create(path).map_err(|e| InputError::io(&name, &e))?;
                return finish(stream(runner, &writer, args, file), program_name, &name);
            }
            let dir = path
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            let temp =
                tempfile::NamedTempFile::new_in(dir).map_err(|e| InputError::io(&name, &e))?;
            let file = temp.reopen().map_err(|e| InputError::io(&name, &e))?;
            let status = finish(stream(runner, &writer, args, file), program_name, &name)?;
            temp.persist(path)
                .map_err(|e| InputError::io(&name, &e.error))?;
            Ok(status)
        }
    }
}

/// Why streaming stopped, besides reaching the end.
enum Stop {
    Alarm(Box<RunError>),
    Write(io::Error),
}

/// Segments handed from the controller thread to the writer thread at once.
const BATCH: usize = 1024;

/// Runs the program and writes every row. The controller, the sampling of
/// segments and forward kinematics run on this thread; formatting and
/// writing on a second one, fed with batches of rows whose buffers travel
/// back for reuse.
fn stream<S: Source, W: Write + Send>(
    mut runner: Runner<'_, S>,
    writer: &RowWriter<'_>,
    args: &RunArgs,
    out: W,
) -> Result<(), Stop> {
    let machine = runner.controller().machine();
    std::thread::scope(|scope| {
        let (full_tx, full_rx) = mpsc::sync_channel::<(Vec<Row>, Option<Alarm>)>(4);
        let (empty_tx, empty_rx) = mpsc::channel::<Vec<Row>>();
        let formatter = scope.spawn(move || -> io::Result<()> {
            let mut out = out;
            let mut text = Text::default();
            writer.header(&mut text);
            for (mut rows, alarm) in full_rx {
                for row in &rows {
                    writer.row(&mut text, row);
                    if text.is_full() {
                        out.write_all(text.as_bytes())?;
                        text.clear();
                    }
                }
                if let Some(alarm) = alarm {
                    writer.alarm(&mut text, &alarm);
                }
                rows.clear();
                // The producer may be gone already; then the buffer is dropped.
                let _ = empty_tx.send(rows);
            }
            out.write_all(text.as_bytes())?;
            out.flush()
        });

        let mut segments = Vec::with_capacity(BATCH);
        let mut batch = RowBatch {
            rows: Vec::with_capacity(BATCH),
            full: full_tx,
            empty: empty_rx,
        };
        let outcome = loop {
            segments.clear();
            let filled = runner.fill(&mut segments, BATCH);
            let mut sent = true;
            for segment in &segments {
                sent &= sample(segment, machine, args, &mut batch);
            }
            let (more, alarm, outcome) = match filled {
                Ok(more) => (more, None, Ok(())),
                Err(error) => {
                    let alarm = match &error {
                        RunError::Alarm { alarm, .. } => Some(alarm.clone()),
                        RunError::Io(_) => None,
                    };
                    (false, alarm, Err(Stop::Alarm(Box::new(error))))
                }
            };
            if !(sent && batch.send(alarm) && more) {
                break outcome;
            }
        };
        let RowBatch { full: full_tx, .. } = batch;
        drop(full_tx);
        let written = formatter
            .join()
            .unwrap_or_else(|_| Err(io::Error::other("the writer thread panicked")));
        written.map_err(Stop::Write)?;
        outcome
    })
}

/// Rows on their way to the writer thread.
struct RowBatch {
    rows: Vec<Row>,
    full: mpsc::SyncSender<(Vec<Row>, Option<Alarm>)>,
    empty: mpsc::Receiver<Vec<Row>>,
}

impl RowBatch {
    /// Adds a row; hands the batch over when it is full. `false` when the
    /// writer has stopped.
    fn push(&mut self, row: Row) -> bool {
        self.rows.push(row);
        self.rows.len() < BATCH || self.send(None)
    }

    /// Hands the rows (and a closing alarm) over to the writer.
    fn send(&mut self, alarm: Option<Alarm>) -> bool {
        let next = self
            .empty
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH));
        let rows = std::mem::replace(&mut self.rows, next);
        self.full.send((rows, alarm)).is_ok()
    }
}

/// The rows of one segment: with `--step`, the ones inside it, then always
/// its end. `false` when the writer has stopped.
fn sample(segment: &Segment, machine: &Machine, args: &RunArgs, batch: &mut RowBatch) -> bool {
    if let Some(step) = args.step {
        let n = segment.steps(machine, step, args.step_angle);
        for i in 1..n {
            if !batch.push(segment.row(machine, f64::from(i) / f64::from(n))) {
                return false;
            }
        }
    }
    batch.push(segment.row(machine, 1.0))
}

/// Reports how the run ended and gives its exit status.
fn finish(result: Result<(), Stop>, program: &str, output: &str) -> Result<u8, InputError> {
    match result {
        Ok(()) => Ok(EXIT_OK),
        // A reader that stopped reading (`| head`) is not an error.
        Err(Stop::Write(e)) if e.kind() == io::ErrorKind::BrokenPipe => Ok(EXIT_OK),
        Err(Stop::Write(e)) => Err(write_error(output, &e)),
        Err(Stop::Alarm(error)) => match *error {
            RunError::Alarm { alarm, text } => {
                eprintln!(
                    "ALARM {} line {}: {}",
                    alarm.code, alarm.line, alarm.message
                );
                let span = alarm.span.map(|s| (s.start, s.end));
                let title = format!("{} {}", alarm.code, alarm.message);
                eprint!(
                    "{}",
                    diagnostic::render(program, alarm.line, &text, span, &title, "here")
                );
                eprintln!();
                Ok(EXIT_ALARM)
            }
            RunError::Io(e) => Err(InputError::io(program, &e)),
        },
    }
}

fn write_error(output: &str, error: &io::Error) -> InputError {
    InputError::io(output, error)
}
