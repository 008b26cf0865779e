//! `fiveaxis post`: runs a program that uses tool centre point control or
//! the tilted working plane, and writes the same motion as a program in
//! machine axes for the same machine with those options off (the
//! conversion itself is `fiveaxis-post`).

use std::io::{Read, Write};
use std::path::PathBuf;

use fiveaxis_control::{ReaderSource, RunOptions, Runner};
use fiveaxis_post::{Axes, PostOptions, program};

use crate::{
    EXIT_OK, InputError, Stop, finish, library, load_machine, load_offsets, open_program,
    write_error, write_whole,
};

/// Options of `fiveaxis post`.
#[derive(Debug, clap::Args)]
pub struct PostArgs {
    /// Program file (G43.4 / G43.5, G68.2), or `-` for standard input.
    program: String,
    /// Built-in machine name or machine file (TOML).
    #[arg(long, default_value = fiveaxis_machine::DEFAULT_MACHINE)]
    machine: String,
    /// Offsets file (TOML): the output is for the lengths of the tools
    /// the program selects and is written in its G54; default: all
    /// offsets zero (then give --tool-length).
    #[arg(long)]
    offsets: Option<PathBuf>,
    /// Write the program to this file (whole or not at all) instead of
    /// standard output.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Largest distance of the tool tip from the programmed path (mm).
    #[arg(long, default_value_t = fiveaxis_post::DEFAULT_TOLERANCE, value_parser = tolerance)]
    tolerance: f64,
    /// Largest angle of the tool direction from the programmed one
    /// (degrees).
    #[arg(long, default_value_t = fiveaxis_post::DEFAULT_ANGLE_TOLERANCE, value_parser = angle_tolerance)]
    angle_tolerance: f64,
    /// The control's program memory: a folder of programs that M98 / G65
    /// call by number.
    #[arg(long)]
    programs: Option<PathBuf>,
    /// Read the program as APT / CL data (`GOTO/x,y,z,i,j,k`, `FEDRAT`,
    /// `CIRCLE`, ...); the default for files named `.apt`, `.cl`, `.cls`,
    /// `.ncl` (also `.ncl.N`), `.aptsource`.
    #[arg(long)]
    apt: bool,
    /// With APT / CL input: write the TCPC program (`G43.5` with tool
    /// vectors) for a machine with the option, not machine axes.
    #[arg(long)]
    tcpc: bool,
    /// Retract of a flip along the tool axis (mm): where the rotary axes
    /// must jump, the tool backs off this far, the axes turn, and it comes
    /// back to the same tip.
    #[arg(long, default_value_t = fiveaxis_post::DEFAULT_RETRACT, value_parser = crate::positive)]
    retract: f64,
    /// Feed style: `inverse-time` (G93; the default), `dpm` (G94, F per
    /// block from the composite travel, degrees as mm; the default and
    /// the only time-keeping style for a HEIDENHAIN machine, which has no
    /// inverse time) or `programmed` (G94, F kept; the header states the
    /// tip feed error).
    #[arg(long, value_parser = feed_style)]
    feed: Option<fiveaxis_post::FeedStyle>,
    /// Whose rotary solution: `source` (the control's, as TCPC would move
    /// the axes; the default for G-code on the same machine) or `post`
    /// (the post's own: continuous, flips with a retract, the singular
    /// cone; the default for APT / CL input and retargeting).
    #[arg(long, value_parser = ["source", "post"])]
    axes: Option<String>,
    /// The machine the program was written for (built-in name or machine
    /// file): its axes are turned into the same tool path on `--machine`.
    #[arg(long)]
    from_machine: Option<String>,
    /// Offsets file of `--from-machine` (default: `--offsets`).
    #[arg(long, requires = "from_machine")]
    from_offsets: Option<PathBuf>,
    /// The tool length (mm) the output is for: the length of every tool
    /// the offsets do not give one (no --offsets, or the program's H not
    /// in the file), and the length a machine-axis source was written
    /// for, whose tip the output follows where no length compensation is
    /// in force (default there: the length the header of a `fiveaxis
    /// post` output names). A machine-axis program is right for one tool
    /// length only: without a length from the offsets or here, `post`
    /// stops (exit status 2).
    #[arg(long, value_name = "MM", value_parser = crate::positive)]
    tool_length: Option<f64>,
}

/// A tip tolerance: positive and at least [`fiveaxis_post::MIN_TOLERANCE`].
fn tolerance(text: &str) -> Result<f64, String> {
    at_least(text, fiveaxis_post::MIN_TOLERANCE, "mm")
}

/// A direction tolerance: at least [`fiveaxis_post::MIN_ANGLE_TOLERANCE`].
fn angle_tolerance(text: &str) -> Result<f64, String> {
    at_least(text, fiveaxis_post::MIN_ANGLE_TOLERANCE, "degrees")
}

fn at_least(text: &str, floor: f64, unit: &str) -> Result<f64, String> {
    let x = crate::positive(text)?;
    if x < floor {
        return Err(format!(
            "`{text}` is finer than a program can hold: at least {floor:e} {unit}"
        ));
    }
    Ok(x)
}

/// A feed style by name.
fn feed_style(name: &str) -> Result<fiveaxis_post::FeedStyle, String> {
    fiveaxis_post::FeedStyle::parse(name)
        .ok_or_else(|| format!("`{name}`: expected inverse-time, dpm or programmed"))
}

/// Runs `fiveaxis post`.
pub fn post(args: &PostArgs) -> Result<u8, InputError> {
    let machine = load_machine(&args.machine)?;
    let feed = fiveaxis_post::FeedStyle::for_control(args.feed, machine.control)
        .map_err(|e| InputError(format!("error: --{e}")))?;
    let mut offsets = crate::load_offsets_for(&args.machine, &machine, args.offsets.as_deref())?;
    let source_machine = match &args.from_machine {
        Some(name) => Some(load_machine(name)?),
        None => None,
    };
    let mut source_offsets = match (&args.from_machine, &args.from_offsets) {
        (Some(_), Some(path)) => load_offsets(Some(path))?,
        _ => offsets.clone(),
    };
    if let Some(length) = args.tool_length {
        offsets = fiveaxis_post::with_tool_length(&offsets, length);
        source_offsets = fiveaxis_post::with_tool_length(&source_offsets, length);
    }
    let program_name = if args.program == "-" {
        "<stdin>"
    } else {
        args.program.as_str()
    };
    let mut bytes = Vec::new();
    open_program(&args.program)?
        .read_to_end(&mut bytes)
        .map_err(|e| InputError::io(program_name, &e))?;
    let is_apt = args.apt || fiveaxis_post::apt::is_cl_file_name(&args.program);
    if args.tcpc && !is_apt {
        return Err(InputError(
            "error: --tcpc writes the TCPC program of APT / CL input: give --apt".into(),
        ));
    }
    // CL input: the conversion with its line map, and the CL text.
    let mut cl = None;
    if is_apt {
        let text = std::str::from_utf8(&bytes).map_err(|_| {
            InputError(format!(
                "error: {program_name}: APT / CL data must be text (UTF-8)"
            ))
        })?;
        let converted = fiveaxis_post::apt::to_tcpc_mapped(text, program_name)
            .map_err(|e| InputError(format!("error: {program_name}:{e}")))?;
        // Records skipped: unknown words (warning), known words not
        // carried out (note); one line per word.
        for w in &converted.warnings {
            crate::report(&format!(
                "{}: {}:{w}",
                if w.note { "note" } else { "warning" },
                crate::diagnostic::escape(program_name)
            ));
        }
        if args.tcpc {
            return emit(args.output.as_ref(), &converted.program);
        }
        let tcpc = converted.program.clone();
        cl = Some((converted, text.to_owned()));
        bytes = tcpc.into_bytes();
    }
    let axes = match args.axes.as_deref() {
        Some("source") if source_machine.is_some() => {
            return Err(InputError(
                "error: --axes source keeps the source's axes: not with --from-machine".into(),
            ));
        }
        Some("source") => Axes::Source,
        Some(_) => Axes::Post {
            great_circle: is_apt,
        },
        None => fiveaxis_post::default_axes(is_apt, source_machine.is_some()),
    };
    let header_length = program::header_tool_length(&String::from_utf8_lossy(&bytes));
    let options = PostOptions {
        tolerance: args.tolerance,
        angle_tolerance: args.angle_tolerance,
        // The output is written in G54 (with the external offset).
        origin: fiveaxis_post::g54_origin(&offsets),
        axes,
        retract: args.retract,
        feed,
        source_tool_length: args.tool_length.or(header_length),
    };
    let carried = program::carried_words(&String::from_utf8_lossy(&bytes));
    let run_on = source_machine.as_ref().unwrap_or(&machine);
    // SINUMERIK and HEIDENHAIN text is read by its own front end on any
    // machine.
    let language = (!is_apt)
        .then(|| {
            fiveaxis_control::program_language(Some(std::path::Path::new(&args.program)), &bytes)
        })
        .flatten();
    let sinumerik = match fiveaxis_control::machine_for_language(run_on, language) {
        std::borrow::Cow::Owned(m) => Some(m),
        std::borrow::Cow::Borrowed(_) => None,
    };
    let run_on = sinumerik.as_ref().unwrap_or(run_on);
    let mut runner = Runner::new(
        run_on,
        source_offsets,
        ReaderSource::new(std::io::Cursor::new(&bytes[..])),
        RunOptions::default(),
    );
    if let Some(dir) = &args.programs {
        let library = library::DirLibrary::new(dir)
            .map_err(|e| InputError::io(&dir.display().to_string(), &e))?;
        runner = runner.with_library(Box::new(library));
    }
    let post = match fiveaxis_post::convert(&mut runner, &machine, options) {
        Ok(post) => post,
        // An alarm: nothing is written.
        Err(error) => {
            let error = match &cl {
                Some((converted, text)) => converted.on_cl_lines(error, text, program_name),
                None => error,
            };
            let output = args
                .output
                .as_ref()
                .map_or("standard output".to_owned(), |p| p.display().to_string());
            return finish(Err(Stop::Alarm(Box::new(error))), program_name, &output);
        }
    };
    // Nothing to convert (no TCPC, no tilted plane, no CL data, the same
    // machine): the program is a machine-axis program already.
    if !post.kinematic && !is_apt && source_machine.is_none() {
        crate::report(&format!(
            "note: {}: nothing to convert: the program uses no TCPC or tilted working plane; written unchanged",
            crate::diagnostic::escape(program_name)
        ));
        return emit_bytes(args.output.as_ref(), &bytes);
    }
    if !post.has_tool_length() && args.tool_length.or(header_length).is_none() {
        return Err(InputError(format!(
            "error: {}: no tool length: a machine-axis program is right only for the tool length it is made for, and the offsets give the program's tool none (no --offsets, or its H number is not in the file); give it with --tool-length MM, or with --offsets FILE holding the tool (`[tools]` `1 = {{ length = 120.0 }}`)",
            crate::diagnostic::escape(program_name)
        )));
    }
    if let Some(line) = post.capped_line {
        let line = cl
            .as_ref()
            .and_then(|(converted, _)| converted.source_line(line))
            .unwrap_or(line);
        return Err(InputError(format!(
            "error: {}: {} (--tolerance, --angle-tolerance)",
            crate::diagnostic::escape(program_name),
            fiveaxis_post::capped_message(line, args.tolerance, args.angle_tolerance)
        )));
    }
    let header = program::Header {
        source: program_name,
        number: None,
        source_machine: source_machine.as_ref().map(|m| m.name.as_str()),
        carried: &carried,
    };
    let text = program::write(&machine, &post, &options, &header);
    emit(args.output.as_ref(), &text)
}

/// Writes `text` to `output` (whole or not at all), or standard output.
fn emit(output: Option<&PathBuf>, text: &str) -> Result<u8, InputError> {
    emit_bytes(output, text.as_bytes())
}

/// Writes `bytes` to `output` (whole or not at all), or standard output.
fn emit_bytes(output: Option<&PathBuf>, bytes: &[u8]) -> Result<u8, InputError> {
    match output {
        None => print_bytes(bytes),
        Some(path) => {
            let name = path.display().to_string();
            write_whole(path, |mut file| {
                file.write_all(bytes)
                    .and_then(|()| file.flush())
                    .map_err(|e| write_error(&name, &e))?;
                Ok(EXIT_OK)
            })
        }
    }
}

/// Writes `bytes` to standard output whole; a reader that went away
/// (`| head`) is not an error.
fn print_bytes(bytes: &[u8]) -> Result<u8, InputError> {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Ok(EXIT_OK),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(EXIT_OK),
        Err(e) => Err(write_error("standard output", &e)),
    }
}
