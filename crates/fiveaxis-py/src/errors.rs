//! The package's exceptions, defined in Python (`fiveaxis/_errors.py`)
//! and raised from here with their fields.

use fiveaxis_control::{Alarm, RunError};
use fiveaxis_machine::FileError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// An instance of `fiveaxis._errors.<class>` built with keyword
/// arguments, as a `PyErr`.
fn raise(py: Python<'_>, class: &str, kwargs: &Bound<'_, PyDict>) -> PyErr {
    let built = py
        .import("fiveaxis._errors")
        .and_then(|m| m.getattr(class))
        .and_then(|c| c.call((), Some(kwargs)));
    match built {
        Ok(value) => PyErr::from_value(value),
        Err(e) => e,
    }
}

/// An input that cannot be used: `fiveaxis.InputError` (also a
/// `ValueError`), with the file, line, column and key when known.
pub fn input_error(
    py: Python<'_>,
    message: impl Into<String>,
    file: Option<&str>,
    line: Option<u32>,
    column: Option<u32>,
    key: Option<&str>,
) -> PyErr {
    let kwargs = PyDict::new(py);
    let filled = kwargs
        .set_item("message", message.into())
        .and_then(|()| kwargs.set_item("file", file))
        .and_then(|()| kwargs.set_item("line", line))
        .and_then(|()| kwargs.set_item("column", column))
        .and_then(|()| kwargs.set_item("key", key));
    match filled {
        Ok(()) => raise(py, "InputError", &kwargs),
        Err(e) => e,
    }
}

/// A plain input error with a message only.
pub fn invalid(py: Python<'_>, message: impl Into<String>) -> PyErr {
    input_error(py, message, None, None, None, None)
}

/// A machine or offsets file that was refused.
pub fn file_error(py: Python<'_>, file: &str, error: &FileError) -> PyErr {
    input_error(
        py,
        error.message.clone(),
        Some(file),
        Some(error.line),
        Some(error.column),
        error.key.as_deref(),
    )
}

/// A refused dictionary: the key and what is wrong, no file position.
pub fn dict_error(py: Python<'_>, what: &str, error: &FileError) -> PyErr {
    input_error(
        py,
        error.message.clone(),
        Some(what),
        None,
        None,
        error.key.as_deref(),
    )
}

/// The alarm that stopped a program: `fiveaxis.Alarm` with code, line,
/// column (of the word at fault, when one is), message, program and the
/// text of the failing line.
pub fn alarm(py: Python<'_>, alarm: &Alarm, program: &str, text: &[u8]) -> PyErr {
    let kwargs = PyDict::new(py);
    let filled = kwargs
        .set_item("code", alarm.code.to_string())
        .and_then(|()| kwargs.set_item("line", alarm.line))
        .and_then(|()| kwargs.set_item("column", alarm.span.map(|s| s.start)))
        .and_then(|()| kwargs.set_item("message", alarm.message.clone()))
        .and_then(|()| kwargs.set_item("program", program))
        .and_then(|()| kwargs.set_item("text", String::from_utf8_lossy(text).into_owned()));
    match filled {
        Ok(()) => raise(py, "Alarm", &kwargs),
        Err(e) => e,
    }
}

/// Why a run stopped, as a Python exception.
pub fn run_error(py: Python<'_>, error: &RunError, program: &str) -> PyErr {
    match error {
        RunError::Alarm {
            alarm: a,
            text,
            program: library,
        } => alarm(py, a, library.as_deref().unwrap_or(program), text),
        RunError::Io(e) => input_error(py, e.to_string(), Some(program), None, None, None),
        RunError::LineTooLong { line } => input_error(
            py,
            format!(
                "line {line} is longer than {} bytes: this is not a program text",
                fiveaxis_control::MAX_LINE_BYTES
            ),
            Some(program),
            Some(*line),
            None,
            None,
        ),
    }
}
