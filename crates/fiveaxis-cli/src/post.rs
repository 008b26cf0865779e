//! `fiveaxis post`: runs a program that uses tool centre point control or
//! the tilted working plane, and writes the same motion as a program in
//! machine axes for the same machine with those options off (the
//! conversion itself is `fiveaxis-post`).

use std::io::{Read, Write};
use std::path::PathBuf;

use fiveaxis_control::{ReaderSource, RunOptions, Runner};
use fiveaxis_post::{PostOptions, program};

use crate::{
    EXIT_OK, InputError, Stop, finish, library, load_machine, load_offsets, open_program,
    print_out, write_error, write_whole,
};

/// Options of `fiveaxis post`.
#[derive(Debug, clap::Args)]
pub struct PostArgs {
    /// Program file (G43.4 / G43.5, G68.2), or `-` for standard input.
    program: String,
    /// Built-in machine name or machine file (TOML).
    #[arg(long, default_value = fiveaxis_machine::DEFAULT_MACHINE)]
    machine: String,
    /// Offsets file (TOML): the output is for its tool lengths and is
    /// written in its G54; default: all offsets zero.
    #[arg(long)]
    offsets: Option<PathBuf>,
    /// Write the program to this file (whole or not at all) instead of
    /// standard output.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Largest distance of the tool tip from the programmed path (mm).
    #[arg(long, default_value_t = fiveaxis_post::DEFAULT_TOLERANCE, value_parser = crate::positive)]
    tolerance: f64,
    /// Largest angle of the tool direction from the programmed one
    /// (degrees).
    #[arg(long, default_value_t = fiveaxis_post::DEFAULT_ANGLE_TOLERANCE, value_parser = crate::positive)]
    angle_tolerance: f64,
    /// The control's program memory: a folder of programs that M98 / G65
    /// call by number.
    #[arg(long)]
    programs: Option<PathBuf>,
    /// Read the program as APT / CL data (`GOTO/x,y,z,i,j,k`, `FEDRAT`,
    /// `CIRCLE`, ...); the default for files named `.apt`, `.cl`, `.cls`.
    #[arg(long)]
    apt: bool,
    /// With APT / CL input: write the TCPC program (`G43.5` with tool
    /// vectors) for a machine with the option, not machine axes.
    #[arg(long)]
    tcpc: bool,
}

/// Runs `fiveaxis post`.
pub fn post(args: &PostArgs) -> Result<u8, InputError> {
    let machine = load_machine(&args.machine)?;
    let offsets = load_offsets(args.offsets.as_deref())?;
    let program_name = if args.program == "-" {
        "<stdin>"
    } else {
        args.program.as_str()
    };
    let mut bytes = Vec::new();
    open_program(&args.program)?
        .read_to_end(&mut bytes)
        .map_err(|e| InputError::io(program_name, &e))?;
    let is_apt = args.apt
        || std::path::Path::new(&args.program)
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| ["apt", "cl", "cls"].contains(&e.to_ascii_lowercase().as_str()));
    if args.tcpc && !is_apt {
        return Err(InputError(
            "error: --tcpc writes the TCPC program of APT / CL input: give --apt".into(),
        ));
    }
    if is_apt {
        let text = std::str::from_utf8(&bytes).map_err(|_| {
            InputError(format!(
                "error: {program_name}: APT / CL data must be text (UTF-8)"
            ))
        })?;
        let tcpc = fiveaxis_post::apt::to_tcpc(text, program_name)
            .map_err(|e| InputError(format!("error: {program_name}:{e}")))?;
        if args.tcpc {
            return emit(args.output.as_ref(), &tcpc);
        }
        bytes = tcpc.into_bytes();
    }
    let options = PostOptions {
        tolerance: args.tolerance,
        angle_tolerance: args.angle_tolerance,
        // The output is written in G54 (with the external offset).
        origin: fiveaxis_post::g54_origin(&offsets),
    };
    let mut runner = Runner::new(
        &machine,
        offsets,
        ReaderSource::new(std::io::Cursor::new(&bytes[..])),
        RunOptions::default(),
    );
    if let Some(dir) = &args.programs {
        let library = library::DirLibrary::new(dir)
            .map_err(|e| InputError::io(&dir.display().to_string(), &e))?;
        runner = runner.with_library(Box::new(library));
    }
    let post = match fiveaxis_post::convert(&mut runner, options) {
        Ok(post) => post,
        // An alarm: nothing is written.
        Err(error) => {
            let output = args
                .output
                .as_ref()
                .map_or("standard output".to_owned(), |p| p.display().to_string());
            return finish(Err(Stop::Alarm(Box::new(error))), program_name, &output);
        }
    };
    let header = program::Header {
        source: program_name,
        number: None,
    };
    let text = program::write(&machine, &post, &options, &header);
    emit(args.output.as_ref(), &text)
}

/// Writes `text` to `output` (whole or not at all), or standard output.
fn emit(output: Option<&PathBuf>, text: &str) -> Result<u8, InputError> {
    match output {
        None => print_out(text),
        Some(path) => {
            let name = path.display().to_string();
            write_whole(path, |mut file| {
                file.write_all(text.as_bytes())
                    .and_then(|()| file.flush())
                    .map_err(|e| write_error(&name, &e))?;
                Ok(EXIT_OK)
            })
        }
    }
}
