//! `fiveaxis._native`: the Rust side of the Python package `fiveaxis`.
//!
//! Glue only: it converts between Python objects (numpy arrays, dicts,
//! strings) and the kernel's types, and raises the package's exceptions
//! (`fiveaxis._errors`). The kernel crates never see a PyO3 type; the
//! Python side (`python/fiveaxis/`) gives the API its shape.

mod errors;
mod inputs;
mod kinematics;
mod library;
mod machine;
mod offsets;
mod report;
mod run;

use pyo3::prelude::*;

/// The names of the built-in machines.
#[pyfunction]
fn builtin_names() -> Vec<&'static str> {
    fiveaxis_machine::builtin_names().to_vec()
}

/// The name of the default machine.
#[pyfunction]
fn default_machine() -> &'static str {
    fiveaxis_machine::DEFAULT_MACHINE
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(builtin_names, m)?)?;
    m.add_function(wrap_pyfunction!(default_machine, m)?)?;
    m.add_class::<machine::PyMachine>()?;
    m.add_class::<offsets::PyOffsets>()?;
    m.add_class::<run::RunStream>()?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_stream, m)?)?;
    m.add_function(wrap_pyfunction!(report::check, m)?)?;
    m.add_function(wrap_pyfunction!(report::post, m)?)?;
    m.add_function(wrap_pyfunction!(report::apt_to_tcpc, m)?)?;
    m.add_function(wrap_pyfunction!(report::is_cl_file_name, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::forward, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::inverse, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::inverse_choice, m)?)?;
    m.add("MOTIONS", run::MOTIONS.to_vec())?;
    m.add("VERSION", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
