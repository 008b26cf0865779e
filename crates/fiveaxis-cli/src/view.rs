//! `fiveaxis view`: runs a program on its machine and writes one
//! self-contained HTML page that shows it in 3-D (the backplot): the tool
//! tip path, the machine moving by forward kinematics, a timeline, the
//! program text, plots of every axis and the findings.
//!
//! This module gathers the data (rows of every block, sampled as `run
//! --step` does); [`pack`] packs it into typed arrays; [`html`] writes the
//! page.

pub mod blocks;
pub mod html;
pub mod pack;
pub mod stock;

use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use fiveaxis_control::{
    AheadSource, Alarm, Interpolation, Motion, Row, RunError, RunOptions, Runner, Segment, Stock,
};
use fiveaxis_machine::{Machine, MachineType, SetupError, Side, Vec3};
use serde_json::{Value, json};

use crate::progress::DelayedBar;
use crate::{
    EXIT_ALARM, EXIT_OK, InputError, MAX_LINE_BYTES, diagnostic, load_machine, load_variables,
    open_program, report, write_error, write_whole,
};
use blocks::BlockTable;
use pack::{PathPacker, Point};

/// Options of `fiveaxis view`.
#[derive(Debug, clap::Args)]
pub struct ViewArgs {
    /// Program file, or `-` for standard input.
    program: String,
    /// Built-in machine name or machine file (TOML).
    #[arg(long, default_value = fiveaxis_machine::DEFAULT_MACHINE)]
    machine: String,
    /// Offsets file (TOML), or a LinuxCNC tool table (`.tbl`); default:
    /// the machine file's `tool_table`, else all offsets zero.
    #[arg(long)]
    offsets: Option<PathBuf>,
    /// Write the page here (whole or not at all); default: the program
    /// file's name with `.html`, in the current directory (`stdin.html`
    /// for standard input).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Rows inside each block: tool tips at most this far apart (mm), so
    /// arcs and TCPC blocks are drawn as the machine moves.
    #[arg(long, default_value_t = 1.0, value_parser = crate::positive)]
    step: f64,
    /// Most rotary motion between rows (degrees).
    #[arg(long, default_value_t = 1.0, value_parser = crate::positive)]
    step_angle: f64,
    /// No rows inside blocks: each block drawn from its end alone (for
    /// very large programs whose blocks swing the rotary axes far).
    #[arg(long)]
    ends_only: bool,
    /// Leave out rows closer than this to the straight line through their
    /// neighbours (mm, and degrees for the axes).
    #[arg(long, default_value_t = pack::DEFAULT_TOLERANCE, value_parser = crate::positive)]
    tolerance: f64,
    /// Block delete switch on: skip blocks that start with `/`.
    #[arg(long)]
    block_delete: bool,
    /// Stop a program that has not ended after this many lines with alarm
    /// FX0102.
    #[arg(long, default_value_t = fiveaxis_control::DEFAULT_MAX_BLOCKS, value_parser = clap::value_parser!(u64).range(1..))]
    max_blocks: u64,
    /// Optional stop switch on.
    #[arg(long)]
    optional_stop: bool,
    /// The control's program memory: a folder of programs that M98 / G65
    /// call by number.
    #[arg(long)]
    programs: Option<PathBuf>,
    /// Custom macro variables file (TOML, `500 = 1.25`).
    #[arg(long)]
    variables: Option<PathBuf>,
    /// Say on standard error what was skipped and why.
    #[arg(short, long)]
    verbose: bool,
    /// The work: fixtures, stock, part, collisions (as for `check`; the
    /// page shows the fixtures, the stock left and the findings).
    #[command(flatten)]
    work: crate::work::WorkArgs,
}

/// Cells of the stock drawn along its longer side at most (the model's
/// rays are merged into them, each at their highest material).
const STOCK_CELLS: usize = 320;

/// Triangles of one body mesh drawn at most (the page holds them as
/// JSON); a bigger mesh is left out of the drawing.
const BODY_MESH_TRIANGLES: usize = 100_000;

/// Triangles of all fixtures drawn at most; a mesh beyond is drawn as its
/// bounding box.
const FIXTURE_TRIANGLES: usize = 300_000;

/// Findings whose message the page holds; beyond them the viewer shows a
/// finding by its kind, line, axis and value (the check report has every
/// message). Bounds the page: a random 5-axis program has 1.5 findings per
/// block, 150 bytes of message each.
pub const FINDING_MESSAGES: usize = 10_000;

/// Findings the page holds (line, kind, axis, value: 14 bytes each);
/// beyond them it gives their count by kind (the check report has every
/// one).
pub const FINDING_ROWS: usize = 100_000;

/// Program text the page holds, bytes (whole lines); beyond it the page
/// says how many lines it leaves out.
pub const TEXT_BYTES: usize = 16 << 20;

/// The findings of the program as the `check` contract has them
/// (`check-contract.md`: `severity`, `kind`, `line`, `message`, and `axis`,
/// `value` where they apply): the check report of the same run
/// (`fiveaxis-check`, fed the segments the view draws), the alarm that
/// stopped the program among them. As columns for the page: the line, the
/// kind (its index in `finding_kinds`), the axis (its letter's code, 0 for
/// none) and the value (NaN for none) of each, and the first
/// [`FINDING_MESSAGES`] messages.
#[derive(Debug, Default)]
pub struct FindingColumns {
    /// 1-based program line of each finding.
    pub lines: Vec<u32>,
    /// Index of each finding's kind in [`fiveaxis_check::Kind::ALL`].
    pub kinds: Vec<u8>,
    /// The axis letter of each finding (ASCII), 0 when none.
    pub axes: Vec<u8>,
    /// The value of each finding, NaN when none.
    pub values: Vec<f64>,
    /// Where each finding happened (X, Y, Z in the table frame, where
    /// the path is drawn), NaN when it has no place apart from its block.
    pub points: Vec<f32>,
    /// The messages of the first findings.
    pub messages: Vec<String>,
}

impl FindingColumns {
    /// Adds the next finding of the report, if fewer than [`FINDING_ROWS`]
    /// are held.
    pub fn push(&mut self, f: fiveaxis_check::Finding) {
        if self.lines.len() >= FINDING_ROWS {
            return;
        }
        self.lines.push(f.line);
        let kind = fiveaxis_check::Kind::ALL
            .iter()
            .position(|k| *k == f.kind)
            .unwrap_or_default();
        self.kinds.push(u8::try_from(kind).unwrap_or_default());
        self.axes
            .push(f.axis.filter(char::is_ascii).map_or(0, |a| a as u8));
        self.values
            .push(f.value.filter(|v| v.is_finite()).unwrap_or(f64::NAN));
        let point = f.point.unwrap_or([f64::NAN; 3]);
        self.points.extend(point.map(|v| v as f32));
        if self.messages.len() < FINDING_MESSAGES {
            self.messages.push(f.message.to_string());
        }
    }
}

/// The kinds of findings as the page names them, in the order of the
/// `finding_kinds` codes.
fn finding_kinds() -> Value {
    fiveaxis_check::Kind::ALL
        .iter()
        .map(|k| json!({ "kind": k.name(), "severity": k.severity().name() }))
        .collect()
}

/// How many findings of each kind the run had, by kind name.
fn finding_counts(counts: &[usize]) -> Value {
    fiveaxis_check::Kind::ALL
        .iter()
        .map(|k| (k.name().to_string(), json!(counts[k.index()])))
        .collect::<serde_json::Map<_, _>>()
        .into()
}

/// Motion codes of the `motion` array (`viewer/src/data.js`).
fn motion_code(motion: Motion) -> u8 {
    match motion {
        Motion::Rapid => 0,
        Motion::Linear => 1,
        Motion::Cw => 2,
        Motion::Ccw => 3,
    }
}

/// What turns machine coordinates into the reported tool tip for a run of
/// blocks: the tool, the work offset and the setup error.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Frame {
    tool: u32,
    tool_length: f64,
    tool_radius: f64,
    work: Vec3,
    setup: SetupError,
}

impl Frame {
    /// The frame as the viewer reads it: the tool, and the affine map from
    /// table coordinates to the part frame as a 3×4 matrix, row by row
    /// (`tip_part = setup⁻¹(tip_table − W)`, `machine-model.md` §3).
    fn to_json(self) -> Value {
        let origin = self.setup.inverse_point(&(-self.work));
        let columns: Vec<Vec3> = (0..3)
            .map(|i| {
                let mut e = Vec3::zeros();
                e[i] = 1.0;
                self.setup.inverse_vector(&e)
            })
            .collect();
        let matrix: Vec<f64> = (0..3)
            .flat_map(|r| [columns[0][r], columns[1][r], columns[2][r], origin[r]])
            .collect();
        json!({
            "tool": self.tool,
            "tool_length": self.tool_length,
            "tool_radius": self.tool_radius,
            "to_part": matrix,
        })
    }
}

/// Runner calls (a block each, or more) between two updates of the
/// progress bar.
const PROGRESS_BLOCKS: u64 = 256;

/// Tool radius drawn when the offsets give the tool none, mm.
const DEFAULT_TOOL_RADIUS: f64 = 5.0;

/// Everything gathered from the run.
struct Gathered {
    path: PathPacker,
    /// The blocks: lines, motions, frames, end times.
    blocks: BlockTable<Frame>,
    rows: u64,
    alarm: Option<Alarm>,
    bbox: Option<(Vec3, Vec3)>,
    /// The check report's findings (over-travel, singular passages, …),
    /// taken from the checker as they settle: a program with millions of
    /// findings is held as these columns, not as millions of messages.
    findings: FindingColumns,
    /// How many findings of each kind the run had, by
    /// [`fiveaxis_check::Kind::index`] (the page may hold fewer).
    finding_counts: [usize; fiveaxis_check::Kind::ALL.len()],
    /// The check report's machining time.
    time: fiveaxis_check::Time,
    /// Which of them the timeline (`ends`, the vertex times) follows.
    time_kind: fiveaxis_check::TimeKind,
    /// The stock the program declares (HEIDENHAIN `BLK FORM`), in
    /// workpiece coordinates, as read by the end of the run (or by its
    /// alarm).
    stock: Option<Stock>,
    /// The stock model along the run, when there is one.
    stock_history: Option<stock::StockHistory>,
}

/// Runs `fiveaxis view`.
pub fn view(args: &ViewArgs) -> Result<u8, InputError> {
    let machine = load_machine(&args.machine)?;
    let offsets = crate::load_offsets_for(&args.machine, &machine, args.offsets.as_deref())?;
    let program_name = if args.program == "-" {
        "<stdin>"
    } else {
        args.program.as_str()
    };
    // The program is read as it runs (standard input spooled to a file);
    // the page's copy of its text is read again afterwards, bounded.
    let mut file = open_program(&args.program)?;
    let machine = crate::machine_for_program(&machine, &args.program, &mut file).unwrap_or(machine);
    let io_error = |e: &std::io::Error| InputError::io(program_name, e);
    let mut source = file.try_clone().map_err(|e| io_error(&e))?;
    let lines = count_lines(&mut source).map_err(|e| io_error(&e))?;
    let options = RunOptions {
        block_delete: args.block_delete,
        interpolation: (!args.ends_only).then_some(Interpolation {
            step: args.step,
            step_angle: args.step_angle,
        }),
        max_blocks: args.max_blocks,
        optional_stop: args.optional_stop,
        // As `check`: an over-travel is a finding drawn on the path, and
        // the program goes on.
        lift_soft_limits: true,
    };
    let work = crate::work::Work::read(&args.work, 1, &offsets)?;
    let tools = tools_json(&offsets);
    let fixtures = work.fixtures_for_page(FIXTURE_TRIANGLES);
    let mut runner = Runner::new(&machine, offsets.clone(), AheadSource::new(file), options);
    let variables = match &args.variables {
        Some(path) => {
            let name = path.display().to_string();
            let values = load_variables(&name, path)?;
            Some((name, values))
        }
        None => None,
    };
    runner = crate::with_memory(
        runner,
        args.programs.as_deref(),
        variables.as_ref().map(|(n, v)| (n.as_str(), v.as_slice())),
        crate::library::ngc_folders(
            &args.machine,
            &machine.params.subroutine_path,
            &args.program,
        ),
    )?;

    // Where the page goes is settled before the run: a page that would
    // replace the program is refused at once, not after a long run.
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.program));
    if args.program != "-" && same_file(&output, Path::new(&args.program)) {
        return Err(InputError(format!(
            "error: {}: the page would replace the program: give another -o",
            output.display()
        )));
    }
    let name = output.display().to_string();

    let progress = DelayedBar::new(
        lines,
        "{spinner} view [{bar:30}] line {pos}/{len}, {msg} {elapsed}",
    );
    let (checks, kept_stock) = work.checks(&args.work, &machine, &offsets)?;
    let gathered = gather(
        &mut runner,
        &machine,
        args.tolerance,
        program_name,
        &progress,
        checks,
    )?;
    if let Some(path) = &args.work.stock_out {
        match kept_stock.lock().ok().and_then(|mut s| s.take()) {
            Some(left) => crate::work::write_stl(path, &left.dexels)?,
            None => {
                return Err(InputError(format!(
                    "error: {program_name}: --stock-out needs a stock: give --stock (the program declares none)"
                )));
            }
        }
    }
    let history = gathered.stock_history.as_ref();
    let no_floats: &[f32] = &[];
    let stock_model = history.map(stock::StockHistory::model);
    let status = if gathered.alarm.is_some() {
        EXIT_ALARM
    } else {
        EXIT_OK
    };
    let text = read_text(&mut source, TEXT_BYTES).map_err(|e| io_error(&e))?;
    let findings = &gathered.findings;
    let mut meta = meta(
        &machine,
        &gathered,
        findings,
        program_name,
        args.tolerance,
        &text,
    );
    meta["tools"] = tools;
    meta["fixtures"] = fixtures.0;
    meta["stock_model"] = stock_model.unwrap_or(Value::Null);
    use pack::Column;
    let blocks = &gathered.blocks;
    let arrays = [
        ("joints", Column::F32(gathered.path.joints())),
        ("times", Column::F64(gathered.path.times())),
        ("lines", Column::U32(&blocks.lines)),
        ("ends", Column::F64(&blocks.ends)),
        ("motions", Column::U8(&blocks.motions)),
        ("finding_lines", Column::U32(&findings.lines)),
        ("finding_kinds", Column::U8(&findings.kinds)),
        ("finding_axes", Column::U8(&findings.axes)),
        ("finding_values", Column::F64(&findings.values)),
        ("finding_points", Column::F32(&findings.points)),
        ("fixture_triangles", Column::F32(&fixtures.1)),
        (
            "stock_tops",
            Column::F32(history.map_or(no_floats, |h| &h.start)),
        ),
        (
            "stock_cells",
            Column::U32(history.map_or(&[], |h| &h.cells)),
        ),
        (
            "stock_values",
            Column::F32(history.map_or(no_floats, |h| &h.values)),
        ),
    ]
    .map(|(name, column)| html::Array { name, column });
    if let Some(bar) = progress.visible() {
        bar.set_position(lines);
        bar.set_message("writing the page");
    }
    let written = write_whole(&output, |file| {
        let mut out = BufWriter::new(file);
        html::write_page(&mut out, program_name, &meta, &arrays, &text.text)
            .and_then(|()| out.flush())
            .map_err(|e| write_error(&name, &e))?;
        Ok(status)
    });
    progress.finish();
    if args.verbose {
        for note in runner.notes() {
            report(&format!(
                "note: {program_name}: {}",
                diagnostic::escape(note)
            ));
        }
    }
    if let Some(alarm) = &gathered.alarm {
        report(&format!(
            "ALARM {} line {}: {} (shown in the view)",
            alarm.code,
            alarm.line,
            diagnostic::escape(&alarm.message)
        ));
    }
    let status = written?;
    // A device (`-o /dev/null`) has no size worth telling.
    let size = std::fs::metadata(&output)
        .ok()
        .filter(std::fs::Metadata::is_file)
        .map(|m| format!(" ({})", size_text(m.len())))
        .unwrap_or_default();
    report(&format!(
        "wrote {}{size}: open it in a browser",
        diagnostic::escape(&name)
    ));
    Ok(status)
}

/// Counts the program's lines (for the progress bar), reading it once from
/// the start, and goes back to the start.
fn count_lines(file: &mut std::fs::File) -> std::io::Result<u64> {
    use std::io::Seek;
    file.rewind()?;
    let (newlines, _) = count_newlines(&mut *file)?;
    file.rewind()?;
    Ok(newlines + 1)
}

/// The newlines from the reader's position to its end, and the last byte
/// read.
fn count_newlines(read: impl Read) -> std::io::Result<(u64, Option<u8>)> {
    use std::io::BufRead;
    let mut reader = std::io::BufReader::with_capacity(1 << 16, read);
    let (mut newlines, mut last) = (0, None);
    loop {
        let chunk = reader.fill_buf()?;
        if chunk.is_empty() {
            return Ok((newlines, last));
        }
        newlines += chunk.iter().filter(|&&b| b == b'\n').count() as u64;
        last = chunk.last().copied();
        let n = chunk.len();
        reader.consume(n);
    }
}

/// The program text the page holds: whole lines from the start, at most
/// `limit` bytes, and how many lines were left out.
struct PageText {
    text: String,
    left_out: u64,
}

/// Reads the program's text for the page from its start: whole lines up
/// to `limit` bytes (a single longer first line is cut), then counts the
/// lines left out.
fn read_text(file: &mut std::fs::File, limit: usize) -> std::io::Result<PageText> {
    use std::io::Seek;
    file.rewind()?;
    let mut bytes = Vec::new();
    (&mut *file)
        .take(limit as u64 + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() <= limit {
        return Ok(PageText {
            text: String::from_utf8_lossy(&bytes).into_owned(),
            left_out: 0,
        });
    }
    // Past the limit: back to the end of the last whole line held, and
    // the lines after it counted as the viewer counts them (a last line
    // without its newline is one).
    let keep = bytes[..limit]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(limit, |i| i + 1);
    let held_after = bytes[keep..].iter().filter(|&&b| b == b'\n').count() as u64;
    let (rest, rest_last) = count_newlines(&mut *file)?;
    let last = rest_last.or(bytes.last().copied());
    // A last line without its newline is a line too.
    let left_out = held_after + rest + u64::from(last != Some(b'\n'));
    bytes.truncate(keep);
    Ok(PageText {
        text: String::from_utf8_lossy(&bytes).into_owned(),
        left_out,
    })
}

/// The page's default path: the program file's name with `.html`, in the
/// current directory (as a compiler writes its output where it runs, not
/// beside its source: the program's folder may be a repository or
/// read-only); `stdin.html` for standard input.
fn default_output(program: &str) -> PathBuf {
    if program == "-" {
        return PathBuf::from("stdin.html");
    }
    let mut name = Path::new(program)
        .file_stem()
        .filter(|s| !s.is_empty())
        .map_or_else(|| "program".into(), std::ffi::OsStr::to_os_string);
    name.push(".html");
    PathBuf::from(name)
}

/// Whether two paths name the same file (the same text, or the same file
/// once links and `..` are resolved).
fn same_file(a: &Path, b: &Path) -> bool {
    a == b
        || matches!(
            (std::fs::canonicalize(a), std::fs::canonicalize(b)),
            (Ok(x), Ok(y)) if x == y
        )
}

/// A file size for people: bytes, kB, MB or GB (powers of 1000), three
/// digits at most before the point.
fn size_text(bytes: u64) -> String {
    #[allow(clippy::cast_precision_loss)] // a size, shown to one decimal
    let x = bytes as f64;
    if bytes < 1000 {
        format!("{bytes} B")
    } else if x < 999_950.0 {
        format!("{:.1} kB", x / 1e3)
    } else if x < 999_950_000.0 {
        format!("{:.1} MB", x / 1e6)
    } else {
        format!("{:.1} GB", x / 1e9)
    }
}

/// Runs the program, sampling every segment into rows, packing the path.
fn gather<S: fiveaxis_control::Source>(
    runner: &mut Runner<'_, S>,
    machine: &Machine,
    tolerance: f64,
    program_name: &str,
    progress: &DelayedBar,
    work: fiveaxis_check::WorkChecks<'_>,
) -> Result<Gathered, InputError> {
    let axes = machine.axis_count();
    let mut g = Gathered {
        path: PathPacker::new(axes, tolerance),
        blocks: BlockTable::new(),
        rows: 0,
        alarm: None,
        bbox: None,
        findings: FindingColumns::default(),
        finding_counts: [0; fiveaxis_check::Kind::ALL.len()],
        time: fiveaxis_check::Time {
            programmed: 0.0,
            estimated: 0.0,
        },
        time_kind: fiveaxis_check::TimeKind::Programmed,
        stock: None,
        stock_history: None,
    };
    let mut checker = fiveaxis_check::Checker::new(machine);
    let mut declared = work.install(&mut checker);
    // The timeline is the check's: each segment's end in its estimated
    // time. Those come once the planner has looked ahead past them, so the
    // path is timed by the programmed time first and moved to the
    // estimated time at the end, block by block (`pack::retime`).
    checker.stream_segment_times();
    let mut segments = Vec::new();
    let mut rows: Vec<Row> = Vec::new();
    let mut time = 0.0;
    let mut last: Option<(Motion, fiveaxis_machine::Joints)> = None;
    let mut ticks: u64 = 0;
    loop {
        segments.clear();
        // One block at a time, so that the controller's tool is the
        // block's own.
        let filled = runner.fill(&mut segments, 1);
        declared.offer(runner.stock(), &mut checker);
        // The history begins with the stock model, before its first cut.
        if g.stock_history.is_none()
            && let Some(model) = checker.stock_model()
        {
            g.stock_history = Some(stock::StockHistory::start(model, STOCK_CELLS));
        }
        ticks += 1;
        if ticks.is_multiple_of(PROGRESS_BLOCKS)
            && let Some(bar) = progress.visible()
        {
            if let Some(seg) = segments.last() {
                bar.set_position(u64::from(seg.line));
            }
            bar.set_message(format!("{} blocks", runner.blocks()));
        }
        let tool = runner.controller().spindle_tool();
        let radius = runner.controller().offsets().tool(tool).radius;
        for seg in &segments {
            let frame = Frame {
                tool: seg.tool,
                tool_length: seg.tool_length,
                tool_radius: if radius > 0.0 {
                    radius
                } else {
                    DEFAULT_TOOL_RADIUS
                },
                work: seg.work,
                setup: seg.setup,
            };
            let seconds = if seg.moves() {
                fiveaxis_check::block_minutes(machine, seg) * 60.0
            } else {
                0.0
            };
            let new_frame = g
                .blocks
                .push(seg.line, motion_code(seg.motion), frame, time + seconds);
            checker.segment(seg);
            checker.drain_settled(|f| g.findings.push(f));
            checker.take_segment_times(|t| g.blocks.estimated_end(t));
            sample(seg, machine, &mut rows);
            let start = seg.row(machine, 0.0);
            // A new motion or frame, or a jump of the axes between blocks
            // (none in practice): the vertex before stays.
            let corner = match last {
                None => {
                    // The start position: a vertex, not a row (not in the box).
                    g.path.push(
                        Point {
                            joints: start.joints,
                            tip: start.tip,
                            time,
                        },
                        false,
                    );
                    false
                }
                Some((motion, end)) => {
                    let jumped = end != seg.start;
                    if jumped {
                        g.path.push(
                            Point {
                                joints: start.joints,
                                tip: start.tip,
                                time,
                            },
                            true,
                        );
                    }
                    motion != seg.motion || new_frame || jumped
                }
            };
            for (k, row) in rows.iter().enumerate() {
                let first_row = last.is_none() && k == 0;
                push_point(
                    &mut g,
                    row,
                    time + seconds * row.s,
                    corner && k == 0,
                    first_row,
                );
            }
            time += seconds;
            g.rows += rows.len() as u64;
            last = Some((seg.motion, seg.end));
        }
        // The stock along the run: snapshots now and then (the checker
        // cuts in batches, so only when one is due is it asked for the
        // stock as it stands).
        if let Some(history) = &mut g.stock_history
            && history.due()
            && let Some(model) = checker.stock_model()
        {
            history.snapshot(model, g.blocks.lines.len().saturating_sub(1) as u32);
        }
        match filled {
            Ok(true) => {}
            Ok(false) => break,
            Err(RunError::Alarm { alarm, .. }) => {
                g.alarm = Some(alarm);
                break;
            }
            Err(RunError::LineTooLong { line }) => {
                return Err(InputError(format!(
                    "error: {program_name}: line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a program text"
                )));
            }
            Err(RunError::Io(e)) => return Err(InputError::io(program_name, &e)),
        }
    }
    // Read once both BLK FORM blocks have run, and kept: also when the
    // program stops with an alarm after them.
    g.stock = runner.stock();
    g.path.finish();
    if let (Some(history), Some(model)) = (&mut g.stock_history, checker.stock_model()) {
        history.snapshot(model, g.blocks.lines.len().saturating_sub(1) as u32);
    }
    let (report, kind) = checker.finish_streamed(
        fiveaxis_check::Ending {
            ended: g.alarm.is_none(),
            alarm: g.alarm.as_ref().map(|a| fiveaxis_check::AlarmInfo {
                code: a.code.to_string(),
                line: a.line,
                message: a.message.clone(),
            }),
            blocks: runner.blocks(),
        },
        |t| g.blocks.estimated_end(t),
    );
    for f in report.findings {
        g.findings.push(f);
    }
    g.finding_counts = report.counts;
    if kind == fiveaxis_check::TimeKind::Estimated && g.blocks.fully_estimated() {
        let blocks = &mut g.blocks;
        // The last end is the plan's total, to the rounding of the summed
        // lengths: made exactly the total.
        let total = report.time.estimated;
        for end in blocks.estimated.iter_mut().rev() {
            if (*end - total).abs() > 1e-9 * total {
                break;
            }
            *end = total;
        }
        pack::retime(g.path.times_mut(), &blocks.ends, &blocks.estimated);
        std::mem::swap(&mut blocks.ends, &mut blocks.estimated);
        g.time_kind = fiveaxis_check::TimeKind::Estimated;
    }
    g.time = report.time;
    Ok(g)
}

/// Adds a row to the path and to the bounding box of the rows.
///
/// The program's first row always stays, so that the rows' box is the
/// kept vertices' box less the start position (vertex 0, not a row).
fn push_point(g: &mut Gathered, row: &Row, time: f64, corner: bool, first_row: bool) {
    let point = Point {
        joints: row.joints,
        tip: row.tip,
        time,
    };
    if first_row {
        g.path.push_kept(point);
    } else {
        g.path.push(point, corner);
    }
    let tip = row.tip;
    g.bbox = Some(match g.bbox {
        None => (tip, tip),
        Some((lo, hi)) => (lo.inf(&tip), hi.sup(&tip)),
    });
}

/// The rows of one segment as `run --step` gives them: inside it, then
/// its end.
fn sample(seg: &Segment, machine: &Machine, rows: &mut Vec<Row>) {
    rows.clear();
    let n = seg.rows.max(1);
    rows.extend((1..=n).map(|i| seg.row(machine, f64::from(i) / f64::from(n))));
}

/// The JSON description of the page: the machine, the frames, the counts,
/// the findings.
fn meta(
    machine: &Machine,
    g: &Gathered,
    findings: &FindingColumns,
    program: &str,
    tolerance: f64,
    text: &PageText,
) -> Value {
    let kind = match machine.machine_type() {
        MachineType::None => "none",
        MachineType::Head => "head",
        MachineType::Table => "table",
        MachineType::Mixed => "mixed",
    };
    let vec = |v: &Vec3| json!([v.x, v.y, v.z]);
    let linear: Vec<Value> = machine
        .linear
        .iter()
        .map(|a| json!({ "name": a.name.to_string(), "min": a.min, "max": a.max, "rapid": a.dynamics.rapid }))
        .collect();
    let rotary: Vec<Value> = machine
        .rotary
        .iter()
        .map(|r| {
            json!({
                "name": r.name.to_string(),
                "on": if r.on == Side::Head { "head" } else { "table" },
                "axis": vec(r.axis.as_ref()),
                "center": vec(&r.center),
                "min": r.limits.map(|l| l.0),
                "max": r.limits.map(|l| l.1),
                "rollover": r.rollover,
                "rapid": r.dynamics.rapid,
            })
        })
        .collect();
    let bbox = g
        .bbox
        .map(|(lo, hi)| json!({ "min": vec(&lo), "max": vec(&hi) }));
    let stock = g.stock.map(stock_json);
    json!({
        "format": 1,
        "program": program,
        "machine": {
            "name": machine.name,
            "type": kind,
            "tool_direction": vec(machine.tool_direction.as_ref()),
            "linear": linear,
            "rotary": rotary,
            "bodies": bodies_json(machine),
        },
        "frames": g.blocks.frames.iter().map(|f| f.to_json()).collect::<Vec<_>>(),
        "frame_runs": g.blocks.frame_runs,
        "vertices": g.path.vertex_count(),
        "blocks": g.blocks.len(),
        "segments": g.blocks.segments(),
        "rows": g.rows,
        "bbox": bbox,
        "stock": stock,
        "duration": g.blocks.ends.last().copied().unwrap_or(0.0),
        "time": time_json(g),
        "tolerance": g.path.tolerance(),
        // What the page's bounds changed: the path simplified to a coarser
        // tolerance than asked, neighbouring blocks merged, findings and
        // text left out.
        "thinned": {
            "tolerance": tolerance,
            "path": g.path.tolerance() > tolerance,
            "blocks": g.blocks.merged(),
            "findings": finding_counts(&g.finding_counts),
            "findings_total": g.finding_counts.iter().sum::<usize>(),
            "text_lines_left_out": text.left_out,
            "limits": {
                "vertices": pack::MAX_VERTICES,
                "blocks": blocks::MAX_BLOCKS,
                "findings": FINDING_ROWS,
                "messages": FINDING_MESSAGES,
                "text_bytes": TEXT_BYTES,
            },
        },
        "ended": g.alarm.is_none(),
        "alarm": g.alarm.as_ref().map(|a| json!({ "code": a.code.to_string(), "line": a.line, "message": a.message })),
        "finding_kinds": finding_kinds(),
        "finding_messages": findings.messages,
    })
}

/// The machine's bodies for the page: each solid's shape, size and
/// placement in its link's frame (`geometry.rs`).
fn bodies_json(machine: &Machine) -> Value {
    use fiveaxis_machine::geometry::{Link, Shape};
    let vec = |v: &Vec3| json!([v.x, v.y, v.z]);
    machine
        .bodies
        .iter()
        .map(|body| {
            let on = match body.on {
                Link::Base => json!("base"),
                Link::Head => json!("head"),
                Link::Axis(i) => json!(i),
            };
            let solids: Vec<Value> = body
                .solids
                .iter()
                .map(|solid| {
                    let mut v = match solid.shape {
                        Shape::Box { size } => json!({ "shape": "box", "size": vec(&size) }),
                        Shape::Cylinder { radius, length } => {
                            json!({ "shape": "cylinder", "radius": radius, "length": length })
                        }
                        Shape::Cone {
                            bottom,
                            top,
                            length,
                        } => json!({ "shape": "cone", "bottom": bottom, "top": top, "length": length }),
                        Shape::Sphere { radius } => json!({ "shape": "sphere", "radius": radius }),
                        Shape::Capsule { radius, length } => {
                            json!({ "shape": "capsule", "radius": radius, "length": length })
                        }
                        // The triangles in the solid's own frame, flat.
                        Shape::Mesh { mesh } => {
                            let flat: Vec<f32> = machine
                                .meshes
                                .get(mesh)
                                .filter(|m| m.triangles.len() <= BODY_MESH_TRIANGLES)
                                .map(|m| m.triangles.iter().flatten().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect())
                                .unwrap_or_default();
                            json!({ "shape": "mesh", "triangles": flat })
                        }
                    };
                    v["at"] = vec(&solid.place.at);
                    v["axis"] = vec(solid.place.axis.as_ref());
                    v["turn"] = json!(solid.place.turn);
                    v
                })
                .collect();
            json!({ "name": body.name, "on": on, "solids": solids })
        })
        .collect()
}

/// The tools' shapes for the page, by number: length and radius from the
/// offsets, the cutter, flute, shank and holder steps where the offsets
/// file gives them.
fn tools_json(offsets: &fiveaxis_machine::Offsets) -> Value {
    use fiveaxis_machine::geometry::Cutter;
    let mut tools = serde_json::Map::new();
    for (&n, shape) in &offsets.tool_shapes {
        let offset = offsets.tools.get(&n).cloned().unwrap_or_default();
        let (cutter, extra) = match shape.cutter {
            Cutter::Flat => ("flat", 0.0),
            Cutter::Ball => ("ball", 0.0),
            Cutter::BullNose { corner } => ("bull", corner),
            Cutter::Drill { point_angle } => ("drill", point_angle),
            Cutter::Taper { half_angle } => ("taper", half_angle),
        };
        let holder: Vec<Value> = shape
            .holder
            .iter()
            .map(|h| json!({ "diameter": h.diameter, "tip_diameter": h.tip_diameter, "length": h.length }))
            .collect();
        tools.insert(
            n.to_string(),
            json!({
                "length": offset.length + offset.length_wear,
                "radius": offset.radius + offset.radius_wear,
                "cutter": cutter,
                "cutter_value": extra,
                "flute": shape.flute,
                "shank": shape.shank,
                "holder": holder,
            }),
        );
    }
    Value::Object(tools)
}

/// The declared stock for the page: its corners in workpiece coordinates
/// (the part frame of the work offset: the viewer places it with the
/// first frame's `to_part`, as the workpiece zero).
fn stock_json(stock: Stock) -> Value {
    json!({ "min": stock.min, "max": stock.max })
}

/// What the time axis is, for the page: the kind, the check report's two
/// totals, and the words the viewer shows beside the clock.
fn time_json(g: &Gathered) -> Value {
    let (kind, label) = match g.time_kind {
        fiveaxis_check::TimeKind::Estimated => (
            "estimated",
            "estimated machining time (velocity planner), as fiveaxis check",
        ),
        fiveaxis_check::TimeKind::Programmed => (
            "programmed",
            // The planner gave less or could not plan: check's estimate
            // is the programmed time.
            "programmed machining time (path over F, rapids at the rapid rates), \
             as fiveaxis check",
        ),
    };
    json!({
        "kind": kind,
        "label": label,
        "programmed": g.time.programmed,
        "estimated": g.time.estimated,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_for_people() {
        assert_eq!(size_text(0), "0 B");
        assert_eq!(size_text(999), "999 B");
        assert_eq!(size_text(1000), "1.0 kB");
        assert_eq!(size_text(1_440_000), "1.4 MB");
        assert_eq!(size_text(999_949), "999.9 kB");
        assert_eq!(size_text(999_950), "1.0 MB");
        assert_eq!(size_text(2_600_000_000), "2.6 GB");
    }

    #[test]
    fn the_page_text_is_whole_lines_up_to_the_limit_and_counts_the_rest() {
        let mut file = tempfile::tempfile().expect("a temporary file");
        file.write_all(b"G0 X1\nG0 X2\nG0 X3\nG0 X4")
            .expect("written");
        // All of it within the limit.
        let text = read_text(&mut file, 100).expect("read");
        assert_eq!(
            (text.text.as_str(), text.left_out),
            ("G0 X1\nG0 X2\nG0 X3\nG0 X4", 0)
        );
        // 14 bytes: two whole lines; the third and the last (without its
        // newline) are left out.
        let text = read_text(&mut file, 14).expect("read");
        assert_eq!((text.text.as_str(), text.left_out), ("G0 X1\nG0 X2\n", 2));
        // Exactly at a line's end.
        let text = read_text(&mut file, 12).expect("read");
        assert_eq!((text.text.as_str(), text.left_out), ("G0 X1\nG0 X2\n", 2));
        // A first line longer than the limit is cut.
        let text = read_text(&mut file, 3).expect("read");
        assert_eq!((text.text.as_str(), text.left_out), ("G0 ", 4));
        // The line count for the progress bar, from the start.
        assert_eq!(count_lines(&mut file).expect("counted"), 4);
    }

    #[test]
    fn the_default_page_is_named_after_the_program_in_the_current_directory() {
        assert_eq!(
            default_output("examples/bracket.nc"),
            Path::new("bracket.html")
        );
        assert_eq!(default_output("/a/b/prog"), Path::new("prog.html"));
        assert_eq!(default_output("p.tar.nc"), Path::new("p.tar.html"));
        assert_eq!(default_output("-"), Path::new("stdin.html"));
    }

    #[test]
    fn frame_matrix_is_the_work_offset_alone_without_setup_error() {
        let frame = Frame {
            tool: 1,
            tool_length: 100.0,
            tool_radius: 5.0,
            work: Vec3::new(10.0, -20.0, 30.0),
            setup: SetupError::default(),
        };
        let m = frame.to_json()["to_part"].clone();
        assert_eq!(
            m,
            json!([
                1.0, 0.0, 0.0, -10.0, 0.0, 1.0, 0.0, 20.0, 0.0, 0.0, 1.0, -30.0
            ])
        );
    }
}
