//! `fiveaxis`: runs 5-axis G-code programs on a machine model and prints
//! the machine-axis motion the control would command.

mod check;
mod diagnostic;
mod library;
mod number;
mod output;
mod post;
mod progress;
mod signals;
mod text;
mod view;
mod work;

use std::fs::File;
use std::io::{self, BufReader, Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::mpsc;

use clap::{Parser, Subcommand};
use fiveaxis_control::{
    AheadSource, Alarm, DEFAULT_MAX_BLOCKS, Interpolation, MAX_LINE_BYTES, RunError, RunOptions,
    Runner, Segment, Source,
};
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
    /// Check programs on a machine: over-travel, singular passages, flips,
    /// feed limits, chord error, machining time.
    Check(check::CheckArgs),
    /// Write a self-contained HTML page showing the program in 3-D on its
    /// machine (tool path, machine moving, timeline, axis plots, findings).
    View(view::ViewArgs),
    /// Turn a program that uses TCPC (G43.4 / G43.5) or the tilted working
    /// plane into a machine-axis program for the same machine and one tool
    /// length, within a tolerance, with inverse time feed (a program with
    /// neither is written unchanged).
    Post(post::PostArgs),
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
    /// Import a LinuxCNC configuration (its INI file, the HAL files it
    /// names, its kinematics module) or a SINUMERIK swivel data record (a
    /// file of `$TC_CARR…` assignments) and print it as a machine file.
    Import {
        /// The configuration's INI file, or the swivel data file.
        config: PathBuf,
        /// Swivel data only: the machine (built-in name or machine file)
        /// that gives the linear axes, parameters and M codes.
        #[arg(long)]
        machine: Option<String>,
        /// Swivel data only: the record to import, by name ($TC_CARR34) or
        /// number; the first when not given.
        #[arg(long)]
        record: Option<String>,
    },
}

#[derive(Debug, clap::Args)]
struct RunArgs {
    /// Program file, or `-` for standard input.
    program: String,
    /// Built-in machine name or machine file (TOML).
    #[arg(long, default_value = DEFAULT_MACHINE)]
    machine: String,
    /// Offsets file (TOML), or a LinuxCNC tool table (`.tbl`); default:
    /// the machine file's `tool_table`, else all offsets zero.
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
    /// Round every number to at most this many decimals (0-15), trailing
    /// zeros left out, for reading; default: the exact shortest form that
    /// reads back as the same 64-bit float.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=i64::from(number::MAX_DIGITS)))]
    digits: Option<u8>,
    /// Write to this file (whole or not at all) instead of standard output.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Block delete switch on: skip blocks that start with `/`.
    #[arg(long)]
    block_delete: bool,
    /// Stop a program that has not ended after this many lines (an
    /// endless loop) with alarm FX0102.
    #[arg(long, default_value_t = DEFAULT_MAX_BLOCKS, value_parser = clap::value_parser!(u64).range(1..))]
    max_blocks: u64,
    /// Say on standard error what was skipped and why (leader text before
    /// the first `%`, a byte-order mark, text after the closing `%`).
    #[arg(short, long)]
    verbose: bool,
    /// Custom macro variables file (TOML, `500 = 1.25`): the kept common
    /// variables #500-#999 and the interface signals #1000-#1035 at start.
    #[arg(long)]
    variables: Option<PathBuf>,
    /// Write #500-#999 back to the --variables file after the run (whole or
    /// not at all), as the control keeps them.
    #[arg(long, requires = "variables")]
    save_variables: bool,
    /// Optional stop switch on: M01 stops like M00 (noted with --verbose;
    /// the run goes on).
    #[arg(long)]
    optional_stop: bool,
    /// The control's program memory: a folder of programs that M98 / G65
    /// call by number (files named O1234, O1234.nc, or whose first O line
    /// has the number).
    #[arg(long)]
    programs: Option<PathBuf>,
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

    fn file(path: &str, text: &[u8], error: &FileError) -> Self {
        let line_text = text
            .split(|&b| b == b'\n')
            .nth(error.line.saturating_sub(1) as usize)
            .unwrap_or(b"");
        let line_text = line_text.strip_suffix(b"\r").unwrap_or(line_text);
        // File errors count columns in characters; the renderer marks bytes.
        let chars = error.column.max(1) as usize - 1;
        let column = String::from_utf8_lossy(line_text)
            .char_indices()
            .nth(chars)
            .map_or(line_text.len(), |(at, _)| at.min(line_text.len()));
        let column = u32::try_from(column + 1).unwrap_or(u32::MAX);
        let message = diagnostic::escape(&error.message);
        let title = match &error.key {
            Some(key) => format!(
                "{path}:{}:{}: {message} (key `{}`)",
                error.line,
                error.column,
                diagnostic::escape(key)
            ),
            None => format!("{path}:{}:{}: {message}", error.line, error.column),
        };
        let snippet = diagnostic::render(
            path,
            error.line,
            line_text,
            Some((column, column + 1)),
            &title,
            "here",
        );
        // The snippet's heading is the title itself: `error: path:line:col: …`.
        Self(snippet.trim_end().to_owned())
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(error) => {
            // Help and version go to standard output, usage errors to
            // standard error; a stream that cannot be written to is no
            // reason to panic.
            let _ = error.print();
            return ExitCode::from(if error.use_stderr() {
                EXIT_INPUT
            } else {
                EXIT_OK
            });
        }
    };
    let status = match cli.command {
        Command::Run(args) => run(&args),
        Command::Check(args) => check::check(&args),
        Command::View(args) => view::view(&args),
        Command::Post(args) => post::post(&args),
        Command::Machines { action: None } => list_machines(),
        Command::Machines {
            action: Some(MachinesAction::Show { name }),
        } => show_machine(&name),
        Command::Machines {
            action:
                Some(MachinesAction::Import {
                    config,
                    machine,
                    record,
                }),
        } => import_machine(&config, machine.as_deref(), record.as_deref()),
    };
    match status {
        Ok(code) => ExitCode::from(code),
        Err(InputError(message)) => {
            report(&message);
            ExitCode::from(EXIT_INPUT)
        }
    }
}

/// Writes a message for people to standard error. Standard error that
/// cannot be written to (closed, full) loses the message; the exit status
/// still tells what happened.
fn report(message: &str) {
    let mut err = io::stderr().lock();
    let _ = writeln!(err, "{message}");
}

/// Writes `text` to standard output whole; a reader that went away
/// (`| head`) is not an error.
fn print_out(text: &str) -> Result<u8, InputError> {
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(EXIT_OK),
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(EXIT_OK),
        Err(e) => Err(write_error("standard output", &e)),
    }
}

fn list_machines() -> Result<u8, InputError> {
    let mut text = String::new();
    let width = builtin_names().iter().map(|n| n.len()).max().unwrap_or(0);
    for &name in builtin_names() {
        let description = builtin(name).map(|m| m.name).unwrap_or_default();
        let marker = if name == DEFAULT_MACHINE {
            " (default)"
        } else {
            ""
        };
        text.push_str(&format!("{name:<width$} {description}{marker}\n"));
    }
    print_out(&text)
}

fn show_machine(name: &str) -> Result<u8, InputError> {
    let machine = builtin(name).ok_or_else(|| {
        InputError(format!(
            "error: `{}` is not a built-in machine name{}; built-in machines: {} (`fiveaxis machines` lists them)",
            diagnostic::escape(name),
            did_you_mean(name),
            builtin_names().join(", ")
        ))
    })?;
    print_out(&machine.to_toml())
}

/// `machines import CONFIG.ini`: the LinuxCNC configuration as a machine
/// file on standard output. The INI file's folder is made absolute first,
/// so that the file's `tool_table` and `subroutine_path` hold wherever the
/// output is saved. Every file is read with the data-file bounds (1 MiB,
/// UTF-8). A file whose text holds `$TC_CARR` is a SINUMERIK swivel data
/// file instead ([`import_swivel_data`]).
fn import_machine(
    config: &Path,
    base: Option<&str>,
    record: Option<&str>,
) -> Result<u8, InputError> {
    let name = config.display().to_string();
    if let Ok((bytes, text)) = read_data_file(&name, config)
        && text.to_ascii_uppercase().contains("$TC_CARR")
    {
        return import_swivel_data(&name, &bytes, &text, base, record);
    }
    if base.is_some() || record.is_some() {
        return Err(InputError(format!(
            "error: {}: --machine and --record are for SINUMERIK swivel data files ($TC_CARR…)",
            diagnostic::escape(&name)
        )));
    }
    let config = std::path::absolute(config)
        .map_err(|e| InputError::io(&config.display().to_string(), &e))?;
    let mut read = |path: &Path| -> io::Result<String> {
        let file = File::open(path)?;
        let mut bytes = Vec::new();
        file.take(MAX_DATA_FILE_BYTES + 1).read_to_end(&mut bytes)?;
        if bytes.len() as u64 > MAX_DATA_FILE_BYTES {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("larger than {MAX_DATA_FILE_BYTES} bytes"),
            ));
        }
        String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("not UTF-8 text (byte {at})"),
            )
        })
    };
    let imported = fiveaxis_machine::import_linuxcnc(&config, &mut read)
        .map_err(|e| InputError(format!("error: {}", diagnostic::escape(&e.to_string()))))?;
    print_out(&imported.to_toml())
}

/// `machines import FILE` of a SINUMERIK swivel data file: one record
/// as a machine file, the linear axes from `--machine` (or the built-in
/// SINUMERIK machine). Errors point at the file's line and column.
fn import_swivel_data(
    name: &str,
    bytes: &[u8],
    text: &str,
    base: Option<&str>,
    record: Option<&str>,
) -> Result<u8, InputError> {
    let base = base.map(load_machine).transpose()?;
    let imported = fiveaxis_machine::import_tc_carr(text, base.as_ref(), record).map_err(|e| {
        if e.line == 0 {
            InputError(format!(
                "error: {}: {}",
                diagnostic::escape(name),
                diagnostic::escape(&e.message)
            ))
        } else {
            let error = FileError {
                line: e.line,
                column: e.column,
                key: None,
                message: e.message,
            };
            InputError::file(name, bytes, &error)
        }
    })?;
    print_out(&imported.to_toml())
}

fn unknown_machine(name: &str) -> InputError {
    InputError(format!(
        "error: `{}` is neither a built-in machine nor a machine file{}; built-in machines: {}",
        diagnostic::escape(name),
        did_you_mean(name),
        builtin_names().join(", ")
    ))
}

/// `; did you mean `a`?` (or `` `a` or `b` ``) naming the built-in
/// machines nearest to `name`, or nothing when none is near.
fn did_you_mean(name: &str) -> String {
    let nearest = nearest_names(name, builtin_names());
    match nearest.as_slice() {
        [] => String::new(),
        names => format!(
            "; did you mean {}?",
            names
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(" or ")
        ),
    }
}

/// The names nearest to `typed` by edit distance (letters swapped count
/// one edit; case is ignored), when they are near enough to be a slip:
/// at most a third of the name's letters (at least 2) apart. Every name
/// at the smallest distance, in the given order.
fn nearest_names<'a>(typed: &str, names: &[&'a str]) -> Vec<&'a str> {
    let typed = typed.trim().to_lowercase();
    let limit = (typed.chars().count() / 3).max(2);
    let distances: Vec<(usize, &str)> = names
        .iter()
        .map(|&n| (strsim::damerau_levenshtein(&typed, &n.to_lowercase()), n))
        .collect();
    let best = distances
        .iter()
        .map(|&(d, _)| d)
        .min()
        .unwrap_or(usize::MAX);
    if best > limit {
        return Vec::new();
    }
    distances
        .into_iter()
        .filter(|&(d, _)| d == best)
        .map(|(_, n)| n)
        .collect()
}

/// The largest machine or offsets file read, bytes: a real one is a few
/// kilobytes.
const MAX_DATA_FILE_BYTES: u64 = 1 << 20;

/// The largest program read from standard input or a device, bytes (it is
/// spooled to a temporary file; files on disk are read in place, whatever
/// their size).
const MAX_SPOOL_BYTES: u64 = 4 << 30;

/// A machine or offsets file: at most [`MAX_DATA_FILE_BYTES`], UTF-8.
fn read_data_file(name: &str, path: &Path) -> Result<(Vec<u8>, String), InputError> {
    let file = File::open(path).map_err(|e| InputError::io(name, &e))?;
    let mut bytes = Vec::new();
    file.take(MAX_DATA_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| InputError::io(name, &e))?;
    if bytes.len() as u64 > MAX_DATA_FILE_BYTES {
        return Err(InputError(format!(
            "error: {name}: larger than {} bytes: not a machine or offsets file",
            MAX_DATA_FILE_BYTES
        )));
    }
    match FileError::utf8(&bytes) {
        Ok(text) => {
            let text = text.to_owned();
            Ok((bytes, text))
        }
        Err(error) => Err(InputError::file(name, &bytes, &error)),
    }
}

fn load_machine(spec: &str) -> Result<Machine, InputError> {
    if let Some(machine) = builtin(spec) {
        return Ok(machine);
    }
    if !Path::new(spec).exists() {
        return Err(unknown_machine(spec));
    }
    let (bytes, text) = read_data_file(spec, Path::new(spec))?;
    let mut machine = Machine::from_toml(&text).map_err(|e| InputError::file(spec, &bytes, &e))?;
    work::read_body_meshes(&mut machine, Path::new(spec))?;
    Ok(machine)
}

fn load_offsets(path: Option<&Path>) -> Result<Offsets, InputError> {
    let Some(path) = path else {
        return Ok(Offsets::default());
    };
    let name = path.display().to_string();
    let (bytes, text) = read_data_file(&name, path)?;
    let tool_table = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("tbl"));
    if tool_table {
        Offsets::from_tool_table(&text).map_err(|e| InputError::file(&name, &bytes, &e))
    } else {
        Offsets::from_toml(&text).map_err(|e| InputError::file(&name, &bytes, &e))
    }
}

/// [`load_offsets`] for a machine: a work offset may not give more values
/// than the machine has axes.
fn load_offsets_checked(path: Option<&Path>, machine: &Machine) -> Result<Offsets, InputError> {
    let offsets = load_offsets(path)?;
    if let Some(path) = path {
        offsets
            .check_axes(machine.axis_count())
            .map_err(|e| InputError(format!("error: {}: {e}", path.display())))?;
    }
    Ok(offsets)
}

/// The offsets of a run: the `--offsets` file (TOML, or a LinuxCNC tool
/// table `.tbl`), else the tool table the machine file names
/// (`[parameters] tool_table`, relative to the machine file's folder),
/// else all zero.
fn load_offsets_for(
    machine_spec: &str,
    machine: &Machine,
    path: Option<&Path>,
) -> Result<Offsets, InputError> {
    if path.is_some() {
        return load_offsets_checked(path, machine);
    }
    let machine_file = Path::new(machine_spec);
    match &machine.params.tool_table {
        Some(table) if machine_file.is_file() => {
            let base = machine_file.parent().unwrap_or(Path::new("."));
            let path = base.join(table);
            let name = path.display().to_string();
            let (bytes, text) = read_data_file(&name, &path)?;
            Offsets::from_tool_table(&text).map_err(|e| InputError::file(&name, &bytes, &e))
        }
        _ => Ok(Offsets::default()),
    }
}

/// The control whose own language the program is in (SINUMERIK: `.mpf`,
/// `.spf`, a `%_N_` header; HEIDENHAIN: `.h`, a `BEGIN PGM` first line),
/// from its name and first bytes; `file` is left at its start.
pub fn program_language(spec: &str, file: &mut File) -> Option<fiveaxis_machine::Control> {
    let mut head = [0u8; fiveaxis_control::HEAD_BYTES];
    let mut read = 0;
    while read < head.len() {
        match file.read(&mut head[read..]) {
            Ok(0) | Err(_) => break,
            Ok(n) => read += n,
        }
    }
    let _ = file.rewind();
    fiveaxis_control::program_language(Some(Path::new(spec)), &head[..read])
}

/// The machine a program runs on: a clone of `machine` with the control
/// whose language the program is in ([`program_language`]) when that is
/// another control.
pub fn machine_for_program(machine: &Machine, spec: &str, file: &mut File) -> Option<Machine> {
    let language = program_language(spec, file);
    match fiveaxis_control::machine_for_language(machine, language) {
        std::borrow::Cow::Owned(m) => Some(m),
        std::borrow::Cow::Borrowed(_) => None,
    }
}

/// The program as a seekable file: a regular file itself, or standard
/// input (or a device, a pipe) spooled to an anonymous temporary file, so
/// that subprogram calls can jump back and memory stays constant.
fn open_program(spec: &str) -> Result<File, InputError> {
    if spec == "-" {
        return spool(&mut io::stdin().lock(), "standard input");
    }
    let file = File::open(spec).map_err(|e| InputError::io(spec, &e))?;
    let regular = file.metadata().is_ok_and(|m| m.is_file());
    if regular {
        Ok(file)
    } else {
        spool(&mut BufReader::new(file), spec)
    }
}

/// Copies a program from a stream to a temporary file, refusing a line
/// longer than [`MAX_LINE_BYTES`] or more than [`MAX_SPOOL_BYTES`] in all
/// as soon as it shows (`/dev/zero` is refused after 64 KiB, not after
/// filling the disk).
fn spool(input: &mut dyn io::BufRead, name: &str) -> Result<File, InputError> {
    let temp_error = |e: &io::Error| InputError::io("temporary file", e);
    let mut spool = tempfile::tempfile().map_err(|e| temp_error(&e))?;
    let mut total: u64 = 0;
    let mut line_len: usize = 0;
    let mut line: u64 = 1;
    loop {
        let chunk = match input.fill_buf() {
            Ok([]) => break,
            Ok(chunk) => chunk,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(InputError::io(name, &e)),
        };
        for &b in chunk {
            if b == b'\n' {
                line += 1;
                line_len = 0;
            } else {
                line_len += 1;
                if line_len > MAX_LINE_BYTES + 1 {
                    return Err(InputError(format!(
                        "error: {name}: line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a program text"
                    )));
                }
            }
        }
        total += chunk.len() as u64;
        if total > MAX_SPOOL_BYTES {
            return Err(InputError(format!(
                "error: {name}: more than {MAX_SPOOL_BYTES} bytes: too large to read from a stream (give the program as a file)"
            )));
        }
        spool.write_all(chunk).map_err(|e| temp_error(&e))?;
        let n = chunk.len();
        input.consume(n);
    }
    spool.rewind().map_err(|e| temp_error(&e))?;
    Ok(spool)
}

fn run(args: &RunArgs) -> Result<u8, InputError> {
    let machine = load_machine(&args.machine)?;
    let offsets = load_offsets_for(&args.machine, &machine, args.offsets.as_deref())?;
    let mut file = open_program(&args.program)?;
    let machine = machine_for_program(&machine, &args.program, &mut file).unwrap_or(machine);
    let program_name = if args.program == "-" {
        "<stdin>"
    } else {
        args.program.as_str()
    };
    let source = AheadSource::new(file);
    let options = RunOptions {
        block_delete: args.block_delete,
        interpolation: args.step.map(|step| Interpolation {
            step,
            step_angle: args.step_angle,
        }),
        max_blocks: args.max_blocks,
        optional_stop: args.optional_stop,
        lift_soft_limits: false,
    };
    let variables = match &args.variables {
        Some(path) => {
            let name = path.display().to_string();
            let values = load_variables(&name, path)?;
            Some((name, values))
        }
        None => None,
    };
    let mut runner = with_memory(
        Runner::new(&machine, offsets, source, options),
        args.programs.as_deref(),
        variables.as_ref().map(|(n, v)| (n.as_str(), v.as_slice())),
        library::ngc_folders(
            &args.machine,
            &machine.params.subroutine_path,
            &args.program,
        ),
    )?;
    let writer = RowWriter::new(args.format, &machine, args.digits);

    let status = match &args.output {
        None => {
            let result = stream(&mut runner, &writer, io::stdout());
            finish(result, program_name, "standard output")
        }
        Some(path) => write_output_file(path, &mut runner, &writer, program_name),
    };
    if args.verbose {
        for note in runner.notes() {
            report(&format!(
                "note: {program_name}: {}",
                diagnostic::escape(note)
            ));
        }
    }
    if let (Ok(_), true, Some(path)) = (&status, args.save_variables, &args.variables) {
        save_variables(path, &runner.kept_variables())?;
    }
    status
}

/// A variables file: `NUMBER = value` lines of TOML (`500 = 1.25`), the
/// number with or without `#` in quotes (`"#500" = 1.25`).
/// A runner given the control's program memory (`--programs DIR`) and the
/// kept macro variables read from a variables file (`name`, its values).
fn with_memory<'m, S: fiveaxis_control::Source>(
    mut runner: Runner<'m, S>,
    programs: Option<&Path>,
    variables: Option<(&str, &[(u32, f64)])>,
    ngc_folders: Vec<std::path::PathBuf>,
) -> Result<Runner<'m, S>, InputError> {
    let dir = match programs {
        Some(dir) => Some(
            library::DirLibrary::new(dir)
                .map_err(|e| InputError::io(&dir.display().to_string(), &e))?,
        ),
        None => None,
    };
    let memory = library::Memory::new(dir, ngc_folders);
    if !memory.is_empty() {
        runner = runner.with_library(Box::new(memory));
    }
    if let Some((name, values)) = variables {
        runner
            .set_variables(values)
            .map_err(|e| InputError(format!("error: {name}: {e}")))?;
    }
    Ok(runner)
}

fn load_variables(name: &str, path: &Path) -> Result<Vec<(u32, f64)>, InputError> {
    let (bytes, text) = read_data_file(name, path)?;
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let at = e.span().map_or(0, |s| s.start);
        let line = text[..at.min(text.len())].matches('\n').count() + 1;
        let error = FileError {
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: 1,
            key: None,
            message: e.message().trim().to_owned(),
        };
        InputError::file(name, &bytes, &error)
    })?;
    let mut values = Vec::with_capacity(table.len());
    for (key, value) in &table {
        let number = key.trim_start_matches('#').parse::<u32>().ok();
        let value = match value {
            toml::Value::Float(v) => Some(*v),
            toml::Value::Integer(v) => Some(*v as f64),
            _ => None,
        };
        match (number, value) {
            (Some(n), Some(v)) => values.push((n, v)),
            _ => {
                return Err(InputError(format!(
                    "error: {name}: `{}`: each line is a variable number and a number, as `500 = 1.25`",
                    diagnostic::escape(key)
                )));
            }
        }
    }
    Ok(values)
}

/// Writes the kept variables back, whole or not at all; the interface
/// signals the file held stay as they were (they are inputs).
fn save_variables(path: &Path, values: &[(u32, f64)]) -> Result<(), InputError> {
    let name = path.display().to_string();
    let mut text = String::from(
        "# fiveaxis custom macro variables: #500-#999 (and #500000- with the option) kept between runs, #1000-#1035 interface signals\n",
    );
    if let Ok(old) = std::fs::read_to_string(path) {
        for line in old.lines() {
            let key = line
                .split('=')
                .next()
                .unwrap_or("")
                .trim()
                .trim_matches('"');
            if key
                .trim_start_matches('#')
                .parse::<u32>()
                .is_ok_and(|n| (1000..=1035).contains(&n))
            {
                text.push_str(line);
                text.push('\n');
            }
        }
    }
    for (n, v) in values {
        text.push_str(&format!("{n} = {v:?}\n"));
    }
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut temp = tempfile::Builder::new()
        .prefix(".fiveaxis-")
        .tempfile_in(dir)
        .map_err(|e| InputError::io(&name, &e))?;
    temp.write_all(text.as_bytes())
        .and_then(|()| temp.flush())
        .map_err(|e| write_error(&name, &e))?;
    if let Ok(m) = std::fs::metadata(path) {
        let _ = std::fs::set_permissions(temp.path(), m.permissions());
    }
    temp.persist(path)
        .map_err(|e| InputError::io(&name, &e.error))?;
    Ok(())
}

/// Runs into the `-o` file. A device or pipe (`-o /dev/null`) is written
/// to as it is. A file is written to a hidden temporary file beside it and
/// renamed over it when the run is over, so that it is never seen half
/// written: after the program's end or an alarm (then it holds the rows
/// before the failing block, as standard output would); after any other
/// failure (an input that cannot be used, a write error, a signal) the
/// temporary file is removed and the target is left as it was.
fn write_output_file<S: Source>(
    path: &Path,
    runner: &mut Runner<'_, S>,
    writer: &RowWriter<'_>,
    program_name: &str,
) -> Result<u8, InputError> {
    let name = path.display().to_string();
    write_whole(path, |file| {
        finish(stream(runner, writer, file), program_name, &name)
    })
}

/// Writes a file whole or not at all: `write` fills it and gives the exit
/// status; the file then replaces `path` (on an `Err`, `path` is left as it
/// was). A device or pipe (`/dev/null`, `/dev/stdout`) is written through;
/// a symbolic link's target is replaced, the link stays; a replaced file
/// keeps its permissions.
fn write_whole(
    path: &Path,
    write: impl FnOnce(File) -> Result<u8, InputError>,
) -> Result<u8, InputError> {
    let name = path.display().to_string();
    // A device or pipe, also behind a link (`/dev/stdout`), is written
    // through.
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| InputError::io(&name, &e))?;
        return write(file);
    }
    let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    // A symbolic link is written through: its target is replaced, the
    // link stays.
    let target = if link {
        std::fs::canonicalize(path).map_err(|e| {
            InputError(format!(
                "error: {name}: a symbolic link whose target cannot be written ({e})"
            ))
        })?
    } else {
        path.to_path_buf()
    };
    let existing = std::fs::metadata(&target).ok();
    let dir = target
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut builder = tempfile::Builder::new();
    builder.prefix(".fiveaxis-").suffix(".tmp");
    // A new file gets the usual permissions (0666 less the umask); a
    // replaced file keeps its own.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        if existing.is_none() {
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
    }
    let temp = builder
        .tempfile_in(dir)
        .map_err(|e| InputError::io(&name, &e))?;
    if let Some(m) = &existing {
        // Exactly the old mode, whatever the umask.
        std::fs::set_permissions(temp.path(), m.permissions())
            .map_err(|e| InputError::io(&name, &e))?;
    }
    let cleanup = signals::remove_on_signal(temp.path());
    let file = temp.reopen().map_err(|e| InputError::io(&name, &e))?;
    let status = write(file);
    cleanup.finish(|| match status {
        Ok(code) => temp
            .persist(&target)
            .map(|_| code)
            .map_err(|e| InputError::io(&name, &e.error)),
        Err(error) => {
            drop(temp);
            Err(error)
        }
    })
}

/// Why streaming stopped, besides reaching the end.
enum Stop {
    Alarm(Box<RunError>),
    Write(io::Error),
}

/// Segments handed from the controller thread to the writer thread at once.
const BATCH: usize = 1024;

/// Runs the program and writes every row. The controller runs on this
/// thread; the sampling of segments (`--step`), forward kinematics,
/// formatting and writing on a second one, fed with batches of segments
/// whose buffers travel back for reuse.
fn stream<S: Source, W: Write + Send>(
    runner: &mut Runner<'_, S>,
    writer: &RowWriter<'_>,
    out: W,
) -> Result<(), Stop> {
    let machine = runner.controller().machine();
    std::thread::scope(|scope| {
        let (full_tx, full_rx) = mpsc::sync_channel::<(Vec<Segment>, Option<Alarm>)>(4);
        let (empty_tx, empty_rx) = mpsc::channel::<Vec<Segment>>();
        let formatter = scope.spawn(move || -> io::Result<()> {
            let mut out = out;
            let mut text = Text::default();
            writer.header(&mut text);
            for (mut segments, alarm) in full_rx {
                for segment in &segments {
                    // The runner has divided the block for `--step` (1
                    // without): the rows inside it, then always its end.
                    for s in segment.row_fractions() {
                        writer.row(&mut text, &segment.row(machine, s));
                        if text.is_full() {
                            out.write_all(text.as_bytes())?;
                            text.clear();
                        }
                    }
                }
                if let Some(alarm) = alarm {
                    writer.alarm(&mut text, &alarm);
                }
                segments.clear();
                // The producer may be gone already; then the buffer is dropped.
                let _ = empty_tx.send(segments);
            }
            out.write_all(text.as_bytes())?;
            out.flush()
        });

        let mut segments = Vec::with_capacity(BATCH);
        let outcome = loop {
            let filled = runner.fill(&mut segments, BATCH);
            let (more, alarm, outcome) = match filled {
                Ok(more) => (more, None, Ok(())),
                Err(error) => {
                    let alarm = match &error {
                        RunError::Alarm { alarm, .. } => Some(alarm.clone()),
                        RunError::Io(_) | RunError::LineTooLong { .. } => None,
                    };
                    (false, alarm, Err(Stop::Alarm(Box::new(error))))
                }
            };
            let next = empty_rx
                .try_recv()
                .unwrap_or_else(|_| Vec::with_capacity(BATCH));
            let full = std::mem::replace(&mut segments, next);
            let sent = full_tx.send((full, alarm)).is_ok();
            if !(sent && more) {
                break outcome;
            }
        };
        drop(full_tx);
        let written = formatter
            .join()
            .unwrap_or_else(|_| Err(io::Error::other("the writer thread panicked")));
        written.map_err(Stop::Write)?;
        outcome
    })
}

/// Reports how the run ended and gives its exit status.
fn finish(result: Result<(), Stop>, program: &str, output: &str) -> Result<u8, InputError> {
    match result {
        Ok(()) => Ok(EXIT_OK),
        // A reader that stopped reading (`| head`) is not an error.
        Err(Stop::Write(e)) if e.kind() == io::ErrorKind::BrokenPipe => Ok(EXIT_OK),
        Err(Stop::Write(e)) => Err(write_error(output, &e)),
        Err(Stop::Alarm(error)) => match *error {
            RunError::Alarm {
                alarm,
                text,
                program: library_file,
            } => {
                let program = library_file.as_deref().unwrap_or(program);
                let span = alarm.span.map(|s| (s.start, s.end));
                let message = diagnostic::escape(&alarm.message);
                // The contract's line says it all; the location and the
                // caret follow, without the message a second time.
                report(&format!(
                    "ALARM {} line {}: {message}\n{}",
                    alarm.code,
                    alarm.line,
                    diagnostic::render_location(program, alarm.line, &text, span, "here")
                        .trim_end()
                ));
                Ok(EXIT_ALARM)
            }
            RunError::LineTooLong { line } => Err(InputError(format!(
                "error: {program}: line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a program text"
            ))),
            RunError::Io(e) => Err(InputError::io(program, &e)),
        },
    }
}

fn write_error(output: &str, error: &io::Error) -> InputError {
    InputError::io(output, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_names_are_suggested_and_far_ones_not() {
        let names = builtin_names();
        assert_eq!(nearest_names("trunion-ac", names), ["trunnion-ac"]);
        assert_eq!(nearest_names("TRUNNION-CA", names), ["trunnion-ac"]);
        assert_eq!(nearest_names("haas-umc-750", names), ["haas-umc750"]);
        assert_eq!(nearest_names("mill-3", names), Vec::<&str>::new());
        assert_eq!(nearest_names("my-machine.toml", names), Vec::<&str>::new());
        assert_eq!(nearest_names("", names), Vec::<&str>::new());
        // Two at the same distance: both.
        assert_eq!(
            nearest_names("trunnion-xc", names),
            ["trunnion-ac", "trunnion-bc"]
        );
    }
}
