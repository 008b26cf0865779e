//! Reading what Python hands over: data files (machine, offsets) and
//! programs (a file or text), with the command line's bounds.

use std::borrow::Cow;
use std::fs::File;
use std::io::{Cursor, Read, Seek};
use std::path::Path;

use fiveaxis_control::AheadSource;
use fiveaxis_machine::{Control, FileError, Machine};
use pyo3::prelude::*;

use crate::errors::input_error;

/// The largest machine or offsets file read, bytes (as the command line).
pub const MAX_DATA_FILE_BYTES: u64 = 1 << 20;

/// A machine or offsets file as UTF-8 text, at most
/// [`MAX_DATA_FILE_BYTES`]; an error names the file (and the line and
/// column of the first byte that is not UTF-8).
pub fn read_data_file(py: Python<'_>, path: &Path) -> PyResult<String> {
    let name = path.display().to_string();
    let io = |e: std::io::Error| input_error(py, e.to_string(), Some(&name), None, None, None);
    let file = File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_DATA_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_DATA_FILE_BYTES {
        return Err(input_error(
            py,
            format!("larger than {MAX_DATA_FILE_BYTES} bytes: not a machine or offsets file"),
            Some(&name),
            None,
            None,
            None,
        ));
    }
    match FileError::utf8(&bytes) {
        Ok(text) => Ok(text.to_owned()),
        Err(e) => Err(input_error(
            py,
            e.message,
            Some(&name),
            Some(e.line),
            Some(e.column),
            None,
        )),
    }
}

/// A readable, seekable program.
pub trait ReadSeek: Read + Seek + Send {}

impl<T: Read + Seek + Send> ReadSeek for T {}

/// A program's source and the name messages give it.
pub type ProgramSource = AheadSource<Box<dyn ReadSeek>>;

/// Bytes of a program file read to find the language it is in.
const HEAD_BYTES: usize = fiveaxis_control::HEAD_BYTES;

/// The control whose own language a program is in, as the command line
/// decides (`fiveaxis_control::program_language`): SINUMERIK for `.mpf` /
/// `.spf` or a `%_N_` header, HEIDENHAIN for `.h` or a `BEGIN PGM` first
/// line; `None` for the machine control's own. `head` is the program's
/// first bytes (or all of them).
pub fn language(path: Option<&Path>, head: &[u8]) -> Option<Control> {
    fiveaxis_control::program_language(path, head)
}

/// The machine a program runs on: `machine`, or a clone with the control
/// whose language the program is in ([`language`]) when that is another.
pub fn machine_for_program(machine: &Machine, language: Option<Control>) -> Cow<'_, Machine> {
    fiveaxis_control::machine_for_language(machine, language)
}

/// The first bytes of `file` (at most [`HEAD_BYTES`]), leaving it at its
/// start.
fn file_head(file: &mut File) -> Vec<u8> {
    let mut head = Vec::with_capacity(HEAD_BYTES);
    let _ = file.by_ref().take(HEAD_BYTES as u64).read_to_end(&mut head);
    let _ = file.rewind();
    head
}

/// The program: the file at `path`, or `code` (its text). Exactly one.
/// With its name for messages and the language it is in ([`language`]).
pub fn open_program(
    py: Python<'_>,
    path: Option<&Path>,
    code: Option<Vec<u8>>,
) -> PyResult<(ProgramSource, String, Option<Control>)> {
    match (path, code) {
        (Some(path), None) => {
            let name = path.display().to_string();
            let mut file = File::open(path)
                .map_err(|e| input_error(py, e.to_string(), Some(&name), None, None, None))?;
            if file.metadata().is_ok_and(|m| m.is_dir()) {
                return Err(input_error(
                    py,
                    "a directory, not a program file",
                    Some(&name),
                    None,
                    None,
                    None,
                ));
            }
            let language = language(Some(path), &file_head(&mut file));
            Ok((
                AheadSource::new(Box::new(file) as Box<dyn ReadSeek>),
                name,
                language,
            ))
        }
        (None, Some(code)) => {
            let language = language(None, &code);
            Ok((
                AheadSource::new(Box::new(Cursor::new(code)) as Box<dyn ReadSeek>),
                "<string>".to_owned(),
                language,
            ))
        }
        _ => Err(crate::errors::invalid(
            py,
            "give the program as a file path or as code=..., one of them",
        )),
    }
}

/// The whole program as bytes (for `post`, which reads it at once), its
/// name and the language it is in ([`language`]).
pub fn read_program(
    py: Python<'_>,
    path: Option<&Path>,
    code: Option<Vec<u8>>,
) -> PyResult<(Vec<u8>, String, Option<Control>)> {
    match (path, code) {
        (Some(path), None) => {
            let name = path.display().to_string();
            let bytes = std::fs::read(path)
                .map_err(|e| input_error(py, e.to_string(), Some(&name), None, None, None))?;
            let language = language(Some(path), &bytes);
            Ok((bytes, name, language))
        }
        (None, Some(code)) => {
            let language = language(None, &code);
            Ok((code, "<string>".to_owned(), language))
        }
        _ => Err(crate::errors::invalid(
            py,
            "give the program as a file path or as code=..., one of them",
        )),
    }
}
