//! `check` and `post`: the reports of `fiveaxis check` and `fiveaxis
//! post` as Python dicts (the Python side makes objects of them).

use std::path::PathBuf;

use fiveaxis_check::check_run;
use fiveaxis_control::{AheadSource, DEFAULT_MAX_BLOCKS, RunOptions};
use fiveaxis_post::{PostOptions, program};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::errors::{input_error, invalid, run_error};
use crate::inputs::{ReadSeek, machine_for_program, open_program, read_program};
use crate::library::Programs;
use crate::machine::PyMachine;
use crate::offsets::PyOffsets;
use crate::run::with_runner;

/// Checks a program as `fiveaxis check` does (soft limits lifted, every
/// excursion measured): the report as a dict with the check contract's
/// keys, findings as tuples `(kind, severity, line, axis, value,
/// message)`.
#[pyfunction]
#[pyo3(signature = (machine, offsets, program = None, code = None, *,
    block_delete = false, optional_stop = false, max_blocks = DEFAULT_MAX_BLOCKS,
    variables = None, programs = None, keep_going = false))]
#[allow(clippy::too_many_arguments)]
pub fn check<'py>(
    py: Python<'py>,
    machine: &Bound<'py, PyMachine>,
    offsets: &Bound<'py, PyOffsets>,
    program: Option<PathBuf>,
    code: Option<Bound<'_, PyBytes>>,
    block_delete: bool,
    optional_stop: bool,
    max_blocks: u64,
    variables: Option<Vec<(u32, f64)>>,
    programs: Option<Programs>,
    keep_going: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let programs = programs.unwrap_or_default();
    if max_blocks == 0 {
        return Err(invalid(py, "max_blocks must be at least 1"));
    }
    let options = RunOptions {
        block_delete,
        interpolation: None,
        max_blocks,
        optional_stop,
        lift_soft_limits: true,
    };
    let (source, name, language) =
        open_program(py, program.as_deref(), code.map(|c| c.as_bytes().to_vec()))?;
    // SINUMERIK text runs on the machine read as a SINUMERIK.
    let machine = &*machine_for_program(&machine.get().machine, language);
    let variables = variables.unwrap_or_default();
    let report = with_runner(
        py,
        machine,
        offsets.get(),
        source,
        options,
        &variables,
        &programs,
        |runner| check_run(runner, keep_going, |_| {}),
    )?
    .map_err(|e| run_error(py, &e, &name))?;

    let d = PyDict::new(py);
    d.set_item("program", &name)?;
    d.set_item("machine", &report.machine)?;
    d.set_item("ended", report.ended)?;
    d.set_item("blocks", report.blocks)?;
    let alarm = match &report.alarm {
        Some(a) => {
            let ad = PyDict::new(py);
            ad.set_item("code", &a.code)?;
            ad.set_item("line", a.line)?;
            ad.set_item("message", &a.message)?;
            Some(ad)
        }
        None => None,
    };
    d.set_item("alarm", alarm)?;
    let time = PyDict::new(py);
    time.set_item("programmed", report.time.programmed)?;
    time.set_item("estimated", report.time.estimated)?;
    d.set_item("time", time)?;
    d.set_item("feed_limited_seconds", report.feed_limited_seconds)?;
    let axes: Vec<_> = report
        .axes
        .iter()
        .map(|a| (a.name.to_string(), a.min, a.max, a.limits))
        .collect();
    d.set_item("axes", axes)?;
    let findings: Vec<_> = report
        .findings
        .iter()
        .map(|f| {
            (
                f.kind.name(),
                f.severity().name(),
                f.line,
                f.axis.map(String::from),
                f.value,
                f.message.to_string(),
            )
        })
        .collect();
    d.set_item("findings", findings)?;
    Ok(d)
}

/// Whether a file name is one of CL data (`.apt`, `.cl`, `.cls`, `.ncl`,
/// `.ncl.N`, `.aptsource`), as `fiveaxis post` decides.
#[pyfunction]
pub fn is_cl_file_name(name: &str) -> bool {
    fiveaxis_post::apt::is_cl_file_name(name)
}

/// APT / CL text to a TCPC program (`G43.5` with tool vectors).
#[pyfunction]
#[pyo3(signature = (text, name = "<string>"))]
pub fn apt_to_tcpc(py: Python<'_>, text: &str, name: &str) -> PyResult<String> {
    fiveaxis_post::apt::to_tcpc(text, name)
        .map_err(|e| input_error(py, e.message, Some(name), Some(e.line), None, None))
}

/// Converts a TCPC / tilted-plane program (or APT / CL data with `apt`)
/// into a machine-axis program, as `fiveaxis post`: its text, the largest
/// deviation reached and its counts.
#[pyfunction]
#[pyo3(signature = (machine, offsets, program = None, code = None, *,
    tolerance = fiveaxis_post::DEFAULT_TOLERANCE,
    angle_tolerance = fiveaxis_post::DEFAULT_ANGLE_TOLERANCE, apt = false, programs = None,
    feed = None, retract = fiveaxis_post::DEFAULT_RETRACT, from_machine = None,
    from_offsets = None, tool_length = None))]
#[allow(clippy::too_many_arguments)]
pub fn post<'py>(
    py: Python<'py>,
    machine: &Bound<'py, PyMachine>,
    offsets: &Bound<'py, PyOffsets>,
    program: Option<PathBuf>,
    code: Option<Bound<'_, PyBytes>>,
    tolerance: f64,
    angle_tolerance: f64,
    apt: bool,
    programs: Option<Programs>,
    feed: Option<&str>,
    retract: f64,
    from_machine: Option<Bound<'py, PyMachine>>,
    from_offsets: Option<Bound<'py, PyOffsets>>,
    tool_length: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let programs = programs.unwrap_or_default();
    fiveaxis_post::check_tolerances(tolerance, angle_tolerance).map_err(|e| invalid(py, e))?;
    if !(retract >= 0.0 && retract.is_finite()) {
        return Err(invalid(
            py,
            format!("retract must be a number of mm, 0 or more, not {retract}"),
        ));
    }
    if tool_length.is_some_and(|l| !l.is_finite()) {
        return Err(invalid(py, "tool_length must be a finite number of mm"));
    }
    let feed = feed
        .map(|name| {
            fiveaxis_post::FeedStyle::parse(name).ok_or_else(|| {
                invalid(
                    py,
                    format!("feed `{name}`: expected inverse-time, dpm or programmed"),
                )
            })
        })
        .transpose()?;
    // The default: inverse time, the composite style on a HEIDENHAIN
    // (it has no inverse time, asked for is refused).
    let feed = fiveaxis_post::FeedStyle::for_control(feed, machine.get().machine.control)
        .map_err(|e| invalid(py, e))?;
    let (mut bytes, name, language) =
        read_program(py, program.as_deref(), code.map(|c| c.as_bytes().to_vec()))?;
    // CL input: the conversion with its line map (an alarm names the CL
    // record's line and text), and the CL text.
    let mut cl = None;
    if apt {
        let text = std::str::from_utf8(&bytes).map_err(|_| {
            input_error(
                py,
                "APT / CL data must be text (UTF-8)",
                Some(&name),
                None,
                None,
                None,
            )
        })?;
        let converted = fiveaxis_post::apt::to_tcpc_mapped(text, &name)
            .map_err(|e| input_error(py, e.message, Some(&name), Some(e.line), None, None))?;
        let text = text.to_owned();
        bytes = converted.program.clone().into_bytes();
        cl = Some((converted, text));
    }
    let machine = &machine.get().machine;
    // A tool length given fills in the tools the offsets give none, as
    // `fiveaxis post --tool-length` does.
    let filled = |o: &PyOffsets| PyOffsets {
        offsets: match tool_length {
            Some(length) => fiveaxis_post::with_tool_length(&o.offsets, length),
            None => o.offsets.clone(),
        },
    };
    let target_offsets = filled(offsets.get());
    let offsets = &target_offsets.offsets;
    // Retargeting: the source runs on its own machine (and offsets).
    let source_machine = from_machine.as_ref().map(|m| &m.get().machine);
    // SINUMERIK text (not CL data) runs on that machine read as a
    // SINUMERIK; the output is written for `machine` as it is.
    let run_on =
        &*machine_for_program(source_machine.unwrap_or(machine), language.filter(|_| !apt));
    let run_offsets = match (&from_machine, &from_offsets) {
        (Some(_), Some(o)) => filled(o.get()),
        _ => filled(&target_offsets),
    };
    let source_text = String::from_utf8_lossy(&bytes).into_owned();
    let text = &source_text;
    let header_length = program::header_tool_length(text);
    let options = PostOptions {
        tolerance,
        angle_tolerance,
        origin: fiveaxis_post::g54_origin(offsets),
        axes: fiveaxis_post::default_axes(apt, source_machine.is_some()),
        retract,
        feed,
        source_tool_length: tool_length.or(header_length),
    };
    let carried = program::carried_words(text);
    let source = AheadSource::new(Box::new(std::io::Cursor::new(bytes)) as Box<dyn ReadSeek>);
    let post = with_runner(
        py,
        run_on,
        &run_offsets,
        source,
        RunOptions::default(),
        &[],
        &programs,
        |runner| fiveaxis_post::convert(runner, machine, options),
    )?
    .map_err(|e| {
        let e = match &cl {
            Some((converted, text)) => converted.on_cl_lines(e, text, &name),
            None => e,
        };
        run_error(py, &e, &name)
    })?;
    if let Some(line) = post.capped_line {
        let line = cl
            .as_ref()
            .and_then(|(converted, _)| converted.source_line(line))
            .unwrap_or(line);
        return Err(input_error(
            py,
            fiveaxis_post::capped_message(line, tolerance, angle_tolerance),
            Some(&name),
            Some(line),
            None,
            None,
        ));
    }
    // Nothing to convert: the program is returned unchanged, as the
    // command line writes it.
    let converted = post.kinematic || apt || source_machine.is_some();
    if converted && !post.has_tool_length() && tool_length.or(header_length).is_none() {
        return Err(input_error(
            py,
            "no tool length: a machine-axis program is right only for the tool length it is made for, and the offsets give the program's tool none; give tool_length=MM, or offsets holding the tool ({\"tools\": {1: {\"length\": 120.0}}})",
            Some(&name),
            None,
            None,
            None,
        ));
    }
    let header = program::Header {
        source: &name,
        number: None,
        source_machine: source_machine.map(|m| m.name.as_str()),
        carried: &carried,
    };
    let text = if converted {
        program::write(machine, &post, &options, &header)
    } else {
        source_text
    };
    let d = PyDict::new(py);
    d.set_item("converted", converted)?;
    d.set_item("text", text)?;
    d.set_item("deviation_tip", post.deviation.tip)?;
    d.set_item("deviation_angle", post.deviation.angle)?;
    d.set_item("source_blocks", post.source_blocks)?;
    d.set_item("blocks", post.moves.len())?;
    d.set_item("unresolved", post.unresolved)?;
    d.set_item("tool_lengths", post.tool_lengths.clone())?;
    let warnings: Vec<_> = cl
        .iter()
        .flat_map(|(converted, _)| &converted.warnings)
        .map(|w| (w.line, w.word.as_str(), w.message.as_str(), w.count, w.note))
        .collect();
    d.set_item("cl_warnings", warnings)?;
    Ok(d)
}
