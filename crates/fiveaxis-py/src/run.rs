//! `run`: a program's rows as numpy columns, straight from the segments
//! (no text on the way), and `RunStream`, the same in chunks from a
//! thread that runs ahead while Python consumes.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::mpsc;

use fiveaxis_control::{
    Alarm, DEFAULT_MAX_BLOCKS, Interpolation, Motion, RunError, RunOptions, Runner, Segment,
    Source, displayed,
};
use fiveaxis_machine::Machine;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::errors::{input_error, invalid, run_error};
use crate::inputs::{ProgramSource, machine_for_program, open_program};
use crate::library::{Programs, with_programs};
use crate::machine::PyMachine;
use crate::offsets::PyOffsets;

/// The motion names, by the codes of the `motion` column.
pub const MOTIONS: [&str; 4] = ["rapid", "linear", "cw", "ccw"];

fn motion_code(m: Motion) -> u8 {
    match m {
        Motion::Rapid => 0,
        Motion::Linear => 1,
        Motion::Cw => 2,
        Motion::Ccw => 3,
    }
}

/// Segments taken from the runner at once.
const BATCH: usize = 1024;

/// Rows by column, as the `run` contract's CSV has them: `line`, `s`,
/// `motion`, one column per machine axis (rollover axes in [0, 360)), the
/// tip and the tool direction in the part frame, and the feed (NaN for
/// rapid moves, where the CSV leaves the field empty).
#[derive(Debug)]
pub struct Columns {
    line: Vec<u32>,
    s: Vec<f64>,
    motion: Vec<u8>,
    axes: Vec<Vec<f64>>,
    tip: Vec<f64>,
    tool: Vec<f64>,
    feed: Vec<f64>,
}

impl Columns {
    fn new(axis_count: usize, capacity: usize) -> Self {
        Self {
            line: Vec::with_capacity(capacity),
            s: Vec::with_capacity(capacity),
            motion: Vec::with_capacity(capacity),
            axes: (0..axis_count)
                .map(|_| Vec::with_capacity(capacity))
                .collect(),
            tip: Vec::with_capacity(3 * capacity),
            tool: Vec::with_capacity(3 * capacity),
            feed: Vec::with_capacity(capacity),
        }
    }

    fn len(&self) -> usize {
        self.line.len()
    }

    /// Appends the rows of one segment: inside it with interpolation,
    /// then its end.
    fn push_segment(&mut self, machine: &Machine, seg: &Segment) {
        let code = motion_code(seg.motion);
        let feed = seg.feed.unwrap_or(f64::NAN);
        for s in seg.row_fractions() {
            let row = seg.row(machine, s);
            let shown = displayed(machine, &row.joints);
            self.line.push(row.line);
            self.s.push(row.s);
            self.motion.push(code);
            for (column, x) in self.axes.iter_mut().zip(shown) {
                column.push(x);
            }
            self.tip.extend_from_slice(row.tip.as_slice());
            self.tool.extend_from_slice(row.dir.as_slice());
            self.feed.push(feed);
        }
    }

    /// The columns as a dict of numpy arrays (the buffers move, no copy):
    /// `line`, `s`, `motion`, `axes` (a list, machine order), `tip` and
    /// `tool` `(n, 3)`, `feed`.
    fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let n = self.len();
        let d = PyDict::new(py);
        d.set_item("line", PyArray1::from_vec(py, self.line))?;
        d.set_item("s", PyArray1::from_vec(py, self.s))?;
        d.set_item("motion", PyArray1::from_vec(py, self.motion))?;
        let axes: Vec<_> = self
            .axes
            .into_iter()
            .map(|c| PyArray1::from_vec(py, c))
            .collect();
        d.set_item("axes", axes)?;
        let shape =
            |v: Vec<f64>| Array2::from_shape_vec((n, 3), v).map_err(|e| invalid(py, e.to_string()));
        d.set_item("tip", shape(self.tip)?.into_pyarray(py))?;
        d.set_item("tool", shape(self.tool)?.into_pyarray(py))?;
        d.set_item("feed", PyArray1::from_vec(py, self.feed))?;
        Ok(d)
    }
}

/// The options of a run, from Python's keywords.
fn run_options(
    py: Python<'_>,
    step: Option<f64>,
    step_angle: f64,
    block_delete: bool,
    optional_stop: bool,
    max_blocks: u64,
    lift_soft_limits: bool,
) -> PyResult<RunOptions> {
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if let Some(s) = step.filter(|s| !positive(*s)) {
        return Err(invalid(
            py,
            format!("step must be a positive number, not {s}"),
        ));
    }
    if !positive(step_angle) {
        return Err(invalid(
            py,
            format!("step_angle must be a positive number, not {step_angle}"),
        ));
    }
    if max_blocks == 0 {
        return Err(invalid(py, "max_blocks must be at least 1"));
    }
    Ok(RunOptions {
        block_delete,
        interpolation: step.map(|step| Interpolation { step, step_angle }),
        max_blocks,
        optional_stop,
        lift_soft_limits,
    })
}

/// Runs `work` on a runner of the program with its variables set, with
/// the interpreter free for other threads meanwhile (the runner is built
/// inside: it does not cross threads). `Err` holds a refused variable.
#[allow(clippy::too_many_arguments)]
pub fn with_runner<T: Send>(
    py: Python<'_>,
    machine: &Machine,
    offsets: &PyOffsets,
    source: ProgramSource,
    options: RunOptions,
    variables: &[(u32, f64)],
    programs: &Programs,
    work: impl FnOnce(&mut Runner<'_, ProgramSource>) -> T + Send,
) -> PyResult<T> {
    let offsets = offsets.offsets.clone();
    let outcome = py.detach(move || {
        let mut runner = with_programs(Runner::new(machine, offsets, source, options), programs);
        runner.set_variables(variables)?;
        Ok(work(&mut runner))
    });
    outcome.map_err(|m: String| input_error(py, m, Some("variables"), None, None, None))
}

/// Runs until the columns hold at least `rows` rows, the program ends
/// (`Ok(false)`) or it stops with an error (the rows before the failing
/// block are in the columns).
fn fill_columns<S: Source>(
    runner: &mut Runner<'_, S>,
    columns: &mut Columns,
    segments: &mut Vec<Segment>,
    rows: usize,
) -> Result<bool, RunError> {
    let machine = runner.controller().machine();
    while columns.len() < rows {
        segments.clear();
        // Fewer segments than rows wanted: a chunk ends near its size.
        let count = (rows - columns.len()).clamp(1, BATCH);
        let filled = runner.fill(segments, count);
        for seg in segments.iter() {
            columns.push_segment(machine, seg);
        }
        if !filled? {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Most rows reserved ahead (4 Mi rows, 32 MiB per column): beyond it the
/// columns grow as rows come.
const MAX_RESERVED_ROWS: usize = 1 << 22;

/// Rows reserved at the start of a run: one per 12 bytes of program (a
/// short block), so that a program of short blocks fills its columns
/// without moving them; the pages are only touched as rows come.
fn row_capacity(path: Option<&std::path::Path>, code_len: Option<usize>) -> usize {
    let bytes = match (path, code_len) {
        (Some(p), _) => std::fs::metadata(p).map_or(0, |m| m.len()),
        (None, Some(n)) => n as u64,
        (None, None) => 0,
    };
    usize::try_from(bytes / 12)
        .unwrap_or(usize::MAX)
        .clamp(1024, 1 << 26)
}

/// Why a two-thread run gave no columns.
#[derive(Debug)]
enum Failure {
    /// A variable was refused.
    Variables(String),
    /// The runner thread failed.
    Thread,
    /// Python asked to stop (Ctrl-C): the exception it raised.
    Interrupted(PyErr),
}

/// Batches between two looks at Python's signals (Ctrl-C) during a run.
const SIGNAL_BATCHES: usize = 64;

/// One batch of segments from the runner thread, and the error that
/// ended the run after them.
type Batch = (Vec<Segment>, Option<RunError>);

/// Runs a program on two threads, as the command line does: a thread of
/// its own reads, parses and executes the program into batches of
/// segments; this one samples them into rows (forward kinematics) and
/// fills the columns. Batches travel back for reuse.
fn pipelined(
    machine: &Machine,
    offsets: fiveaxis_machine::Offsets,
    source: ProgramSource,
    options: RunOptions,
    variables: &[(u32, f64)],
    programs: &Programs,
    capacity: usize,
) -> Result<(Columns, Result<(), RunError>), Failure> {
    std::thread::scope(|scope| {
        let (full_tx, full_rx) = mpsc::sync_channel::<Batch>(4);
        let (empty_tx, empty_rx) = mpsc::channel::<Vec<Segment>>();
        let producer = scope.spawn(move || -> Result<(), Failure> {
            let mut runner =
                with_programs(Runner::new(machine, offsets, source, options), programs);
            runner
                .set_variables(variables)
                .map_err(Failure::Variables)?;
            loop {
                let mut batch = empty_rx
                    .try_recv()
                    .unwrap_or_else(|_| Vec::with_capacity(BATCH));
                batch.clear();
                let (more, error) = match runner.fill(&mut batch, BATCH) {
                    Ok(more) => (more, None),
                    Err(e) => (false, Some(e)),
                };
                // The consumer only leaves at the last batch.
                if full_tx.send((batch, error)).is_err() || !more {
                    return Ok(());
                }
            }
        });
        let mut columns = Columns::new(machine.axis_count(), capacity);
        let mut outcome = Ok(());
        let mut interrupted = None;
        for (k, (batch, error)) in full_rx.iter().enumerate() {
            for seg in &batch {
                columns.push_segment(machine, seg);
            }
            if k % SIGNAL_BATCHES == SIGNAL_BATCHES - 1
                && let Err(e) = Python::attach(|py| py.check_signals())
            {
                interrupted = Some(e);
                break;
            }
            // The producer may have finished; then the buffer is dropped.
            let _ = empty_tx.send(batch);
            if let Some(e) = error {
                outcome = Err(e);
                break;
            }
        }
        // The runner thread stops at its next batch once no one listens.
        drop(full_rx);
        producer.join().map_err(|_| Failure::Thread)??;
        match interrupted {
            Some(e) => Err(Failure::Interrupted(e)),
            None => Ok((columns, outcome)),
        }
    })
}

/// Runs a program to its end: a dict of columns, or the exception of its
/// alarm with the rows before it (`rows` attribute, as a dict).
#[pyfunction]
#[pyo3(signature = (machine, offsets, program = None, code = None, *, step = None,
    step_angle = 1.0, block_delete = false, optional_stop = false,
    max_blocks = DEFAULT_MAX_BLOCKS, variables = None, programs = None))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    machine: &Bound<'py, PyMachine>,
    offsets: &Bound<'py, PyOffsets>,
    program: Option<PathBuf>,
    code: Option<Bound<'_, PyBytes>>,
    step: Option<f64>,
    step_angle: f64,
    block_delete: bool,
    optional_stop: bool,
    max_blocks: u64,
    variables: Option<Vec<(u32, f64)>>,
    programs: Option<Programs>,
) -> PyResult<Bound<'py, PyDict>> {
    let programs = programs.unwrap_or_default();
    let options = run_options(
        py,
        step,
        step_angle,
        block_delete,
        optional_stop,
        max_blocks,
        false,
    )?;
    let capacity = row_capacity(
        program.as_deref(),
        code.as_ref().map(|c| c.as_bytes().len()),
    );
    let (source, name, language) =
        open_program(py, program.as_deref(), code.map(|c| c.as_bytes().to_vec()))?;
    // SINUMERIK text runs on the machine read as a SINUMERIK.
    let machine = &*machine_for_program(&machine.get().machine, language);
    let variables = variables.unwrap_or_default();
    let offsets = offsets.get().offsets.clone();
    let (columns, outcome) = py
        .detach(|| {
            pipelined(
                machine, offsets, source, options, &variables, &programs, capacity,
            )
        })
        .map_err(|m| match m {
            Failure::Variables(m) => input_error(py, m, Some("variables"), None, None, None),
            Failure::Thread => invalid(py, "the run thread stopped unexpectedly"),
            Failure::Interrupted(e) => e,
        })?;
    let dict = columns.into_dict(py)?;
    match outcome {
        Ok(_) => Ok(dict),
        Err(error) => {
            let err = run_error(py, &error, &name);
            // The rows before the failing block travel with the alarm.
            err.value(py).setattr("rows", dict)?;
            Err(err)
        }
    }
}

/// What the running thread hands over.
enum Message {
    Rows(Columns),
    Alarm {
        alarm: Alarm,
        text: Vec<u8>,
        program: Option<String>,
    },
    Failed(String),
    /// The program ended.
    Done,
}

/// A run in a thread of its own, handing chunks of rows over as Python
/// asks for them (at most two chunks ahead): memory stays bounded however
/// long the program. Dropping it stops the thread at its next chunk.
#[pyclass(module = "fiveaxis._native")]
pub struct RunStream {
    receiver: Mutex<Option<mpsc::Receiver<Message>>>,
    name: String,
}

impl std::fmt::Debug for RunStream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunStream")
            .field("name", &self.name)
            .finish()
    }
}

#[pymethods]
impl RunStream {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let mut guard = self
            .receiver
            .lock()
            .map_err(|_| invalid(py, "the run stream is in use by another thread"))?;
        let Some(receiver) = guard.take() else {
            return Ok(None);
        };
        let (receiver, message) = py.detach(move || {
            let message = receiver.recv();
            (receiver, message)
        });
        *guard = Some(receiver);
        match message {
            Ok(Message::Rows(columns)) => columns.into_dict(py).map(Some),
            Ok(Message::Alarm {
                alarm,
                text,
                program,
            }) => {
                *guard = None;
                Err(crate::errors::alarm(
                    py,
                    &alarm,
                    program.as_deref().unwrap_or(&self.name),
                    &text,
                ))
            }
            Ok(Message::Failed(message)) => {
                *guard = None;
                Err(input_error(py, message, Some(&self.name), None, None, None))
            }
            Ok(Message::Done) => {
                *guard = None;
                Ok(None)
            }
            // The thread went without a word: it failed.
            Err(_) => {
                *guard = None;
                Err(invalid(py, "the run thread stopped unexpectedly"))
            }
        }
    }
}

/// Starts a run in a thread: a `RunStream` giving dicts of at least
/// `chunk_rows` rows (the last one fewer).
#[pyfunction]
#[pyo3(signature = (machine, offsets, program = None, code = None, *, step = None,
    step_angle = 1.0, block_delete = false, optional_stop = false,
    max_blocks = DEFAULT_MAX_BLOCKS, variables = None, programs = None, chunk_rows = 65536))]
#[allow(clippy::too_many_arguments)]
pub fn run_stream(
    py: Python<'_>,
    machine: &Bound<'_, PyMachine>,
    offsets: &Bound<'_, PyOffsets>,
    program: Option<PathBuf>,
    code: Option<Bound<'_, PyBytes>>,
    step: Option<f64>,
    step_angle: f64,
    block_delete: bool,
    optional_stop: bool,
    max_blocks: u64,
    variables: Option<Vec<(u32, f64)>>,
    programs: Option<Programs>,
    chunk_rows: usize,
) -> PyResult<RunStream> {
    let programs = programs.unwrap_or_default();
    let options = run_options(
        py,
        step,
        step_angle,
        block_delete,
        optional_stop,
        max_blocks,
        false,
    )?;
    if chunk_rows == 0 {
        return Err(invalid(py, "chunk_rows must be at least 1"));
    }
    let (source, name, language) =
        open_program(py, program.as_deref(), code.map(|c| c.as_bytes().to_vec()))?;
    // SINUMERIK text runs on the machine read as a SINUMERIK.
    let machine = machine_for_program(&machine.get().machine, language).into_owned();
    let offsets = offsets.get().offsets.clone();
    let variables = variables.unwrap_or_default();
    // The variables are checked here, where the error can be raised.
    {
        let probe = Runner::new(
            &machine,
            offsets.clone(),
            fiveaxis_control::SliceSource::new(b""),
            RunOptions::default(),
        );
        let mut probe = probe;
        probe
            .set_variables(&variables)
            .map_err(|m| input_error(py, m, Some("variables"), None, None, None))?;
    }
    let (sender, receiver) = mpsc::sync_channel(2);
    std::thread::Builder::new()
        .name("fiveaxis-run".into())
        .spawn(move || {
            let mut runner =
                with_programs(Runner::new(&machine, offsets, source, options), &programs);
            if let Err(m) = runner.set_variables(&variables) {
                let _ = sender.send(Message::Failed(m));
                return;
            }
            let mut segments = Vec::with_capacity(BATCH);
            loop {
                let reserve = chunk_rows.min(MAX_RESERVED_ROWS) + BATCH;
                let mut columns = Columns::new(machine.axis_count(), reserve);
                let outcome = fill_columns(&mut runner, &mut columns, &mut segments, chunk_rows);
                if columns.len() > 0 && sender.send(Message::Rows(columns)).is_err() {
                    // Python let go of the stream.
                    return;
                }
                let last = match outcome {
                    Ok(true) => continue,
                    Ok(false) => Message::Done,
                    Err(RunError::Alarm {
                        alarm,
                        text,
                        program,
                    }) => Message::Alarm {
                        alarm,
                        text,
                        program,
                    },
                    Err(other) => Message::Failed(other.to_string()),
                };
                let _ = sender.send(last);
                return;
            }
        })
        .map_err(|e| invalid(py, format!("cannot start the run thread: {e}")))?;
    Ok(RunStream {
        receiver: Mutex::new(Some(receiver)),
        name,
    })
}
