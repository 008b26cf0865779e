//! Reading what Python hands over: data files (machine, offsets) and
//! programs (a file or text), with the command line's bounds.

use std::borrow::Cow;
use std::fs::File;
use std::io::{Cursor, Read, Seek};
use std::path::Path;

use fiveaxis_control::ReaderSource;
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
pub type ProgramSource = ReaderSource<Box<dyn ReadSeek>>;

/// Bytes of a program file read to find a SINUMERIK transfer header.
const HEAD_BYTES: usize = 64;

/// Whether a program is SINUMERIK text, as the command line decides: a
/// file named `.mpf` / `.spf` (any case), or a text starting with a
/// transfer header `%_N_` (after a UTF-8 byte-order mark, if any). `head`
/// is the program's first bytes (or all of them).
pub fn is_sinumerik(path: Option<&Path>, head: &[u8]) -> bool {
    let named = path
        .and_then(|p| p.extension())
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("mpf") || e.eq_ignore_ascii_case("spf"));
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    named || head.starts_with(b"%_N_")
}

/// The machine a program runs on: `machine`, read as a SINUMERIK (a
/// clone with `control = "sinumerik"`) when the program is SINUMERIK text
/// ([`is_sinumerik`]) and the machine's control is another.
pub fn machine_for_program(machine: &Machine, sinumerik: bool) -> Cow<'_, Machine> {
    if sinumerik && machine.control != Control::Sinumerik {
        Cow::Owned(Machine {
            control: Control::Sinumerik,
            ..machine.clone()
        })
    } else {
        Cow::Borrowed(machine)
    }
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
/// With its name for messages and whether it is SINUMERIK text
/// ([`is_sinumerik`]).
pub fn open_program(
    py: Python<'_>,
    path: Option<&Path>,
    code: Option<Vec<u8>>,
) -> PyResult<(ProgramSource, String, bool)> {
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
            let sinumerik = is_sinumerik(Some(path), &file_head(&mut file));
            Ok((
                ReaderSource::new(Box::new(file) as Box<dyn ReadSeek>),
                name,
                sinumerik,
            ))
        }
        (None, Some(code)) => {
            let sinumerik = is_sinumerik(None, &code);
            Ok((
                ReaderSource::new(Box::new(Cursor::new(code)) as Box<dyn ReadSeek>),
                "<string>".to_owned(),
                sinumerik,
            ))
        }
        _ => Err(crate::errors::invalid(
            py,
            "give the program as a file path or as code=..., one of them",
        )),
    }
}

/// The whole program as bytes (for `post`, which reads it at once), its
/// name and whether it is SINUMERIK text ([`is_sinumerik`]).
pub fn read_program(
    py: Python<'_>,
    path: Option<&Path>,
    code: Option<Vec<u8>>,
) -> PyResult<(Vec<u8>, String, bool)> {
    match (path, code) {
        (Some(path), None) => {
            let name = path.display().to_string();
            let bytes = std::fs::read(path)
                .map_err(|e| input_error(py, e.to_string(), Some(&name), None, None, None))?;
            let sinumerik = is_sinumerik(Some(path), &bytes);
            Ok((bytes, name, sinumerik))
        }
        (None, Some(code)) => {
            let sinumerik = is_sinumerik(None, &code);
            Ok((code, "<string>".to_owned(), sinumerik))
        }
        _ => Err(crate::errors::invalid(
            py,
            "give the program as a file path or as code=..., one of them",
        )),
    }
}
