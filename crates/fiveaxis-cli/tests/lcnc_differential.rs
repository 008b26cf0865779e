//! Differential test against LinuxCNC's own interpreter.
//!
//! `rs274 -g` (Debian package `linuxcnc-uspace`) reads an RS274/NGC
//! program and prints the canonical machining calls it makes of it; its
//! `STRAIGHT_TRAVERSE`, `STRAIGHT_FEED` and `ARC_FEED` calls carry the end
//! point of every move, to four decimals, in the coordinates the program
//! stands in; `SET_G5X_OFFSET`, `SET_G92_OFFSET` and
//! `USE_TOOL_LENGTH_OFFSET` give the offsets that LinuxCNC's canonical
//! layer adds to make them machine positions, with `SET_XY_ROTATION`
//! (`G10 L2 R`) turning the point and the G92 offset about the G5x origin:
//! machine = G5x offset + Rz·(point + G92 offset) + tool offset. On a
//! machine whose axes are the
//! positions rs274 prints (three linear axes, no rotaries, work offsets 0,
//! no tool length), `fiveaxis run` under `control = "linuxcnc"` must give
//! the same sequence of move end points.
//!
//! Two sources of programs:
//!
//! * random programs (seeded, [`Generator`]) that use what LinuxCNC's
//!   language has beyond plain G code: O-word loops (`repeat`, `while`,
//!   `do … while`) and conditions (`if/elseif/else`), subroutines with
//!   arguments and `return`, numbered and named parameters (local and
//!   global), expressions with LinuxCNC's operators and functions, G90 and
//!   G91, arcs in the three planes given by centre (with turns, `P`) or
//!   radius, canned cycles with G98/G99 and `L` repeats, work offsets
//!   (G10 L2 / L20, rotated systems with `R`), G92 and G52;
//! * the LinuxCNC programs of the shared corpus whose motion rs274 can
//!   print without the configuration's remaps (see [`CORPUS`]).
//!
//! Consecutive equal end points are merged on both sides (a move of zero
//! length is a canonical call for rs274 and no segment for the kernel).
//! When `rs274` is not installed the test says so and passes, unless `CI`
//! is set: `.ci/run` installs it, so there its absence is a failure.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// rs274 prints four decimals: a printed number is within half a unit of
/// its last digit of the value it stands for. A machine position is the
/// printed point plus the printed offsets in force (G5x, G92, tool), so
/// each of them that is not 0 adds its own half unit.
const HALF_UNIT: f64 = 0.5e-4;

/// What floating-point arithmetic may add to a comparison.
const ARITHMETIC: f64 = 1e-9;

/// A position agrees with rs274's when every axis is within this of it
/// (the half units of the printed numbers it is made of).
type Tolerance = [f64; 9];

/// What rs274 says of a move besides its end: the tolerance, and whether
/// it is a circle (`ARC_FEED`).
#[derive(Clone, Copy)]
struct Expected {
    tolerance: Tolerance,
    arc: bool,
}

/// What the kernel's row says besides its end: whether it ends a circle,
/// and whether that circle goes on in the next row of the same block.
#[derive(Clone, Copy)]
struct Row {
    arc: bool,
    piece: bool,
}

/// Random programs per run.
const PROGRAMS: u64 = 120;

/// A machine whose axes are rs274's positions: X Y Z with travels no
/// random program reaches, read as LinuxCNC reads programs.
const MACHINE: &str = r#"
name = "LinuxCNC differential mill"
type = "none"
control = "linuxcnc"

[[linear]]
name = "X"
min = -100000.0
max = 100000.0

[[linear]]
name = "Y"
min = -100000.0
max = 100000.0

[[linear]]
name = "Z"
min = -100000.0
max = 100000.0
"#;

/// Whether `rs274` can be run; `None` with the reason when it cannot.
fn rs274_available() -> Result<(), String> {
    match Command::new("rs274")
        .arg("-h")
        .stdin(Stdio::null())
        .output()
    {
        Ok(_) => Ok(()),
        Err(e) => Err(format!(
            "rs274 cannot be run ({e}): install linuxcnc-uspace"
        )),
    }
}

/// Skips (returns false) when rs274 is missing outside CI; fails in CI.
fn require_rs274() -> bool {
    match rs274_available() {
        Ok(()) => true,
        Err(why) if std::env::var_os("CI").is_some() => panic!("{why}"),
        Err(why) => {
            eprintln!("skipped: {why}");
            false
        }
    }
}

/// One move's end point: X Y Z A B C U V W (an axis the machine does not
/// have stays 0).
type Point = [f64; 9];

/// The axis letters of a [`Point`], in order.
const AXES: [&str; 9] = ["X", "Y", "Z", "A", "B", "C", "U", "V", "W"];

/// Held while rs274 runs.
static RS274: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// How rs274 is run: the program, and the INI and tool table if any.
struct Rs274<'a> {
    program: &'a Path,
    ini: Option<&'a Path>,
    tool_table: Option<&'a Path>,
}

/// The move end points rs274 prints, or its error message.
fn rs274_moves(run: &Rs274<'_>) -> Result<Vec<(Point, Expected)>, String> {
    let dir = run.program.parent().expect("the program is in a folder");
    let mut command = Command::new("rs274");
    if let Some(ini) = run.ini {
        command.arg("-i").arg(ini);
    }
    if let Some(table) = run.tool_table {
        command.arg("-t").arg(table);
    }
    // Two rs274 at once share its tool data memory and crash (SIGBUS):
    // one at a time.
    let _one = RS274
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    command
        .arg("-g")
        .arg(run.program)
        .current_dir(dir)
        .stdin(Stdio::null());
    let mut output = command
        .output()
        .map_err(|e| format!("rs274 did not start: {e}"))?;
    // rs274 itself has been seen to die of SIGBUS now and then on a busy
    // machine, with no other rs274 running; the same run then passes. A
    // run killed by a signal is tried once more; a second death, or any
    // error it reports, stands.
    if std::os::unix::process::ExitStatusExt::signal(&output.status).is_some() {
        output = command
            .output()
            .map_err(|e| format!("rs274 did not start: {e}"))?;
    }
    // rs274 reports an error on standard error, not always in its exit
    // status; it writes nothing else there but "executing".
    let errors = String::from_utf8_lossy(&output.stderr);
    let errors = errors.trim().trim_start_matches("executing").trim();
    if !output.status.success() || !errors.is_empty() {
        return Err(format!("rs274 exit {}: {errors}", output.status));
    }
    let text = String::from_utf8_lossy(&output.stdout);
    let mut plane = Plane::Xy;
    let mut moves = Vec::new();
    // Offsets the canonical layer adds: G5x, G92, tool.
    let mut g5x = [0.0; 9];
    let mut g92 = [0.0; 9];
    let mut tool = [0.0; 9];
    // The XY rotation of the coordinate system in use, degrees: the point
    // and the G92 offset turn about the G5x origin (coordinates.adoc).
    let mut rotation = 0.0f64;
    let machine = |p: Point, g5x: &Point, g92: &Point, tool: &Point, rotation: f64| {
        let mut m = p;
        let mut tolerance = [HALF_UNIT + ARITHMETIC; 9];
        for i in 0..9 {
            m[i] += g92[i];
            let rounded = [g5x[i], g92[i], tool[i]]
                .iter()
                .filter(|v| **v != 0.0)
                .count();
            tolerance[i] += HALF_UNIT * rounded as f64;
        }
        if rotation != 0.0 {
            let (sin, cos) = rotation.to_radians().sin_cos();
            let (x, y) = (m[0], m[1]);
            m[0] = cos * x - sin * y;
            m[1] = sin * x + cos * y;
            // Printed X and Y errors mix under the turn.
            let both = tolerance[0].max(tolerance[1]) * std::f64::consts::SQRT_2;
            tolerance[0] = both;
            tolerance[1] = both;
        }
        for i in 0..9 {
            m[i] += g5x[i] + tool[i];
        }
        (m, tolerance)
    };
    for line in text.lines() {
        let trimmed = line.trim_start();
        // Canonical calls are numbered: "   12 N..... CALL(args)".
        let Some(call) = canonical_call(trimmed) else {
            if !trimmed.is_empty() {
                return Err(format!("rs274: {trimmed}"));
            }
            continue;
        };
        let (name, args) = call;
        match name {
            "SELECT_PLANE" => {
                plane = match args.trim() {
                    "CANON_PLANE_XY" => Plane::Xy,
                    "CANON_PLANE_YZ" => Plane::Yz,
                    "CANON_PLANE_XZ" => Plane::Xz,
                    other => return Err(format!("rs274: unknown plane {other}")),
                }
            }
            "SET_G5X_OFFSET" => {
                // index, x, y, z, a, b, c[, u, v, w].
                let v = numbers(args, 7)?;
                g5x = axes(&v[1..]);
            }
            "SET_G92_OFFSET" => g92 = axes(&numbers(args, 6)?),
            "USE_TOOL_LENGTH_OFFSET" => {
                // "x y z, a b c, u v w".
                tool = axes(&numbers(&args.replace(' ', ","), 3)?);
            }
            "SET_XY_ROTATION" => rotation = numbers(args, 1)?[0],
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" => {
                // x, y, z, a, b, c[, u, v, w].
                let p = axes(&numbers(args, 6)?);
                let (m, tolerance) = machine(p, &g5x, &g92, &tool, rotation);
                moves.push((
                    m,
                    Expected {
                        tolerance,
                        arc: false,
                    },
                ));
            }
            "RIGID_TAP" => {
                // x, y, z: down to the point and back to where it began
                // (g-code.adoc, G33.1), the other axes standing.
                let v = numbers(args, 3)?;
                let Some(&(back, back_expected)) = moves.last() else {
                    return Err("rs274: RIGID_TAP before any move".into());
                };
                let mut p = back;
                for (i, value) in v.iter().enumerate() {
                    p[i] = *value;
                }
                // The printed point is in program coordinates: the
                // offsets in force turn it into a machine position.
                let (m, tolerance) = machine(
                    [p[0], p[1], p[2], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                    &g5x,
                    &g92,
                    &tool,
                    rotation,
                );
                let mut m_full = back;
                m_full[..3].copy_from_slice(&m[..3]);
                moves.push((
                    m_full,
                    Expected {
                        tolerance,
                        arc: false,
                    },
                ));
                moves.push((back, back_expected));
            }
            "ARC_FEED" => {
                // first_end, second_end, first_axis, second_axis, rotation,
                // axis_end_point, a, b, c[, u, v, w].
                let v = numbers(args, 9)?;
                let (first, second, axis) = (v[0], v[1], v[5]);
                let [x, y, z] = match plane {
                    Plane::Xy => [first, second, axis],
                    Plane::Yz => [axis, first, second],
                    Plane::Xz => [second, axis, first],
                };
                let mut p = [x, y, z, v[6], v[7], v[8], 0.0, 0.0, 0.0];
                for (i, w) in v.iter().skip(9).take(3).enumerate() {
                    p[6 + i] = *w;
                }
                let (m, tolerance) = machine(p, &g5x, &g92, &tool, rotation);
                moves.push((
                    m,
                    Expected {
                        tolerance,
                        arc: true,
                    },
                ));
            }
            _ => {}
        }
    }
    Ok(moves)
}

#[derive(Clone, Copy)]
enum Plane {
    Xy,
    Yz,
    Xz,
}

/// `NAME` and the text between its parentheses, of a numbered canonical
/// call line.
fn canonical_call(line: &str) -> Option<(&str, &str)> {
    let (number, rest) = line.split_once(' ')?;
    if number.is_empty() || !number.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let rest = rest.trim_start();
    let rest = rest
        .strip_prefix('N')?
        .trim_start_matches(|c: char| c == '.' || c.is_ascii_digit());
    let rest = rest.trim_start();
    let open = rest.find('(')?;
    let close = rest.rfind(')')?;
    Some((&rest[..open], &rest[open + 1..close]))
}

/// A point of the first nine of `values` (X Y Z A B C U V W).
fn axes(values: &[f64]) -> Point {
    let mut p = [0.0; 9];
    let n = values.len().min(9);
    p[..n].copy_from_slice(&values[..n]);
    p
}

/// The numbers of a call's arguments, at least `least` of them.
fn numbers(args: &str, least: usize) -> Result<Vec<f64>, String> {
    let v = args
        .split(',')
        .map(|a| a.trim())
        .filter(|a| !a.is_empty())
        .map(|a| {
            a.parse::<f64>()
                .map_err(|_| format!("rs274: not a number `{a}`"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    if v.len() >= least {
        Ok(v)
    } else {
        Err(format!("rs274: {} arguments in `{args}`", v.len()))
    }
}

/// The move end points `fiveaxis run` gives for `program` on `machine`
/// (one row per segment end; `true` marks a row that ends a piece of a
/// circle the next row continues in the same block: the kernel may cut a
/// full circle into pieces where rs274 prints one `ARC_FEED`), or its
/// error output.
fn fiveaxis_moves(program: &Path, machine: &Path) -> Result<Vec<(Point, Row)>, String> {
    let output = Command::new(env!("CARGO_BIN_EXE_fiveaxis"))
        .arg("run")
        .arg(program)
        .arg("--machine")
        .arg(machine)
        .stdin(Stdio::null())
        .output()
        .expect("the fiveaxis binary starts");
    if !output.status.success() {
        return Err(String::from_utf8_lossy(&output.stderr).into_owned());
    }
    let text = String::from_utf8_lossy(&output.stdout);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    // Machine-axis columns come between `motion` and `tip_x`.
    let columns: Vec<(usize, usize)> = AXES
        .iter()
        .enumerate()
        .filter_map(|(i, axis)| header.iter().position(|h| h == axis).map(|c| (i, c)))
        .collect();
    let motion = header
        .iter()
        .position(|h| *h == "motion")
        .expect("a motion column");
    let rows: Vec<(Point, &str, bool)> = lines
        .map(|row| {
            let cells: Vec<&str> = row.split(',').collect();
            let mut p = [0.0; 9];
            for &(i, c) in &columns {
                p[i] = cells[c].parse::<f64>().expect("a number");
            }
            let arc = matches!(cells[motion], "cw" | "ccw");
            (p, cells[0], arc)
        })
        .collect();
    Ok(rows
        .iter()
        .enumerate()
        .map(|(k, (p, line, arc))| {
            let continued = rows
                .get(k + 1)
                .is_some_and(|(_, next_line, next_arc)| next_line == line && *next_arc);
            (
                *p,
                Row {
                    arc: *arc,
                    piece: *arc && continued,
                },
            )
        })
        .collect())
}

/// The moves with runs of equal neighbours (within a printed digit)
/// merged; a circle (`is_arc`) ending where it starts is a move.
fn merged<T>(moves: Vec<(Point, T)>, is_arc: fn(&T) -> bool) -> Vec<(Point, T)> {
    let mut out: Vec<(Point, T)> = Vec::with_capacity(moves.len());
    let mut last = [0.0; 9];
    for (p, extra) in moves {
        if is_arc(&extra) || !same(p, last, &[HALF_UNIT + ARITHMETIC; 9]) {
            out.push((p, extra));
            last = p;
        }
    }
    out
}

fn same(a: Point, b: Point, tolerance: &Tolerance) -> bool {
    (0..9).all(|i| (a[i] - b[i]).abs() <= tolerance[i])
}

fn show(p: &Point) -> String {
    let mut text = String::new();
    for (axis, v) in AXES.iter().zip(p) {
        if *v != 0.0 || text.is_empty() {
            let _ = write!(text, "{axis}{v:.4} ");
        }
    }
    text.trim_end().to_string()
}

/// Where the two sequences first disagree, in words; `None` when they
/// agree. A kernel row that ends a piece of a circle continued in the
/// same block is passed over when it is not rs274's next move.
fn difference(expected: &[(Point, Expected)], got: &[(Point, Row)]) -> Option<String> {
    let mut k = 0;
    for (i, (e, Expected { tolerance, .. })) in expected.iter().enumerate() {
        while got
            .get(k)
            .is_some_and(|(g, row)| row.piece && !same(*e, *g, tolerance))
        {
            k += 1;
        }
        let Some((g, _)) = got.get(k) else {
            return Some(format!(
                "rs274 has {} moves, fiveaxis stops after {i} (next expected: {})",
                expected.len(),
                show(e)
            ));
        };
        if !same(*e, *g, tolerance) {
            return Some(format!(
                "move {} (1-based): rs274 {}, fiveaxis {}",
                i + 1,
                show(e),
                show(g)
            ));
        }
        k += 1;
    }
    (k < got.len()).then(|| {
        format!(
            "rs274 has {} moves, fiveaxis more (first extra: {})",
            expected.len(),
            show(&got[k].0)
        )
    })
}

/// Runs `text` through both and compares; the failure names the program
/// file kept for reading.
fn compare(dir: &Path, name: &str, text: &str) -> Result<usize, String> {
    let program = dir.join(format!("{name}.ngc"));
    std::fs::write(&program, text).expect("program written");
    let machine = dir.join("machine.toml");
    if !machine.exists() {
        std::fs::write(&machine, MACHINE).expect("machine written");
    }
    let run = Rs274 {
        program: &program,
        ini: None,
        tool_table: None,
    };
    compare_runs(&run, &machine)
}

fn compare_runs(run: &Rs274<'_>, machine: &Path) -> Result<usize, String> {
    let program = run.program;
    let expected =
        rs274_moves(run).map_err(|e| format!("{}: rs274 refused it: {e}", program.display()))?;
    let got = fiveaxis_moves(program, machine)
        .map_err(|e| format!("{}: fiveaxis stopped:\n{e}", program.display()))?;
    let (expected, got) = (merged(expected, |e| e.arc), merged(got, |r| r.arc));
    match difference(&expected, &got) {
        None => Ok(expected.len()),
        Some(why) => Err(format!("{}: {why}", program.display())),
    }
}

/// A folder that outlives a failing test (so the program can be read),
/// under the target directory.
fn work_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("work folder");
    dir
}

#[test]
fn random_programs_move_as_rs274_moves_them() {
    if !require_rs274() {
        return;
    }
    let dir = work_dir("lcnc_differential");
    let mut failures = Vec::new();
    let mut moves = 0;
    for seed in 1..=PROGRAMS {
        let text = Generator::new(seed).program();
        match compare(&dir, &format!("random_{seed}"), &text) {
            Ok(n) => moves += n,
            Err(why) => failures.push(why),
        }
    }
    eprintln!(
        "{} of {PROGRAMS} random programs agree with rs274 ({moves} moves)",
        PROGRAMS as usize - failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} programs differ:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Random RS274/NGC programs: each seed gives one program, the same on
/// every machine.
struct Generator {
    state: u64,
    text: String,
    /// Next O-word number for a loop or condition.
    label: u32,
    /// Named local parameters defined so far (the main program's).
    names: Vec<&'static str>,
    depth: u32,
}

/// Longest generated block (LinuxCNC refuses lines over 255 characters:
/// "Command too long"), leaving room for the indent.
const MAX_LINE: usize = 200;

/// Named parameters the programs define, in order.
const NAMES: [&str; 4] = ["a", "b", "depth", "step"];

impl Generator {
    fn new(seed: u64) -> Self {
        Self {
            state: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03,
            text: String::new(),
            label: 100,
            names: Vec::new(),
            depth: 0,
        }
    }

    /// SplitMix64.
    fn next(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// A value in [lo, hi) with three decimals.
    fn value(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        ((lo + (hi - lo) * unit) * 1000.0).round() / 1000.0
    }

    fn line(&mut self, text: &str) {
        for _ in 0..self.depth {
            self.text.push_str("  ");
        }
        self.text.push_str(text);
        self.text.push('\n');
    }

    fn program(mut self) -> String {
        let _ = writeln!(self.text, "(random program for the differential test)");
        self.line("G21 G90 G17 G94 G40 G49 G80");
        self.line("#<_scale> = 1.5 (a global)");
        self.line("#101 = 4");
        self.subroutines();
        self.line("F600");
        self.line("G0 X0 Y0 Z20");
        for name in NAMES {
            let v = self.value(-20.0, 20.0);
            self.line(&format!("#<{name}> = {v}"));
            self.names.push(name);
        }
        let statements = 12 + self.below(14);
        for _ in 0..statements {
            self.statement();
        }
        self.line("G90 G0 Z30");
        self.line("M2");
        self.text
    }

    /// `o<shift>`: moves by its two arguments (incremental), returns to
    /// G90; `o<corner>`: a square of side #1 at the current height with a
    /// conditional return.
    fn subroutines(&mut self) {
        self.line("o<shift> sub");
        self.line("  G91 G1 X#1 Y#2");
        self.line("  G90");
        self.line("o<shift> endsub");
        self.line("o<corner> sub");
        self.line("  #<half> = [#1 / 2]");
        self.line("  o11 if [#1 LT 0.5]");
        self.line("    o<corner> return");
        self.line("  o11 endif");
        self.line("  G91 G1 X#<half>");
        self.line("  Y#<half>");
        self.line("  X-#<half>");
        self.line("  Y-#<half>");
        self.line("  G90");
        self.line("o<corner> endsub");
        self.line("o<mid> sub");
        self.line("  o<mid> return [[#1 + #2] / 2]");
        self.line("o<mid> endsub");
    }

    /// A subroutine's value (`return [e]`) read from `#<_value>`.
    fn valued_call(&mut self) {
        let a = self.expression(1);
        let b = self.value(-40.0, 40.0);
        self.line(&format!("o<mid> call [[{a}] MOD 60] [{b}]"));
        self.line("G90 G1 Y#<_value>");
    }

    /// Work offsets and G92: G10 L2 / L20 (the current system, P0, or
    /// G54–G56), a rotated system (G10 L2 R), a change of system, G92 and
    /// its cancel, G52, a G53 move.
    fn offsets(&mut self) {
        let (x, y, z) = (
            self.value(-30.0, 30.0),
            self.value(-30.0, 30.0),
            self.value(-10.0, 10.0),
        );
        match self.below(8) {
            0 => {
                let p = self.below(4);
                self.line(&format!("G10 L2 P{p} X{x} Y{y} Z{z}"));
            }
            6 => {
                // A rotated coordinate system (whole degrees: rs274 prints
                // the angle to four decimals).
                let p = self.below(4);
                let r = self.below(721) as i64 - 360;
                self.line(&format!("G10 L2 P{p} X{x} Y{y} R{r}"));
            }
            7 => self.line(&format!("G52 X{x} Y{y}")),
            1 => self.line(&format!("G10 L20 P0 X{x} Y{y}")),
            2 => {
                let g = ["G54", "G55", "G56"][self.below(3) as usize];
                let p = self.below(3) + 1;
                self.line(&format!("G10 L2 P{p} X{x} Y{y}"));
                self.line(g);
            }
            3 => self.line(&format!("G92 X{x} Z{z}")),
            4 => self.line("G92.1"),
            _ => self.line(&format!("G53 G0 X{x} Y{y}")),
        }
    }

    /// A random expression over the defined names, in brackets.
    fn expression(&mut self, depth: u32) -> String {
        let leaf = depth >= 2 || self.below(3) == 0;
        if leaf {
            return match self.below(6) {
                0 => format!("{}", self.value(-30.0, 30.0)),
                1 => "#<_scale>".to_string(),
                2 => "#101".to_string(),
                // The current position, as predefined named and numbered
                // parameters give it.
                3 => ["#<_x>", "#<_y>", "#<_z>", "#5420", "#5421", "#5422"][self.below(6) as usize]
                    .to_string(),
                _ => {
                    let i = self.below(self.names.len() as u64) as usize;
                    format!("#<{}>", self.names[i])
                }
            };
        }
        let a = self.expression(depth + 1);
        let b = self.expression(depth + 1);
        match self.below(12) {
            0 => format!("[{a} + {b}]"),
            1 => format!("[{a} - {b}]"),
            2 => format!("[{a} * {b} / 10]"),
            3 => format!("[{a} / [ABS[{b}] + 1]]"),
            4 => format!("[[ABS[{a}] + 1] MOD 7]"),
            5 => format!("[SIN[{a} * 10] * 5]"),
            6 => format!("[COS[{b}] * {a}]"),
            7 => format!("[ATAN[{a}]/[ABS[{b}] + 1]]"),
            8 => format!("[SQRT[ABS[{a}]] * 2]"),
            9 => format!("[ROUND[{a}] + FIX[{b}] - FUP[{b}]]"),
            10 => format!("[[ABS[{a}] MOD 3] ** 2]"),
            _ => format!("[{a} + {b} * 0.5]"),
        }
    }

    /// A coordinate word's value: a number or an expression kept in a
    /// range that keeps programs finite.
    fn coordinate(&mut self) -> String {
        if self.below(3) == 0 {
            format!("{}", self.value(-60.0, 60.0))
        } else {
            let e = self.expression(0);
            // Bounded whatever the parameters hold.
            format!("[[{e}] MOD 80]")
        }
    }

    fn statement(&mut self) {
        let choice = if self.depth >= 2 {
            self.below(6)
        } else {
            self.below(13)
        };
        match choice {
            0 => self.absolute_move(),
            1 => match self.below(6) {
                0 => self.offsets(),
                1 => self.valued_call(),
                2 => self.threading(),
                _ => self.absolute_move(),
            },
            2 => self.incremental_move(),
            3 => self.arc(),
            4 => self.assign(),
            5 => self.call(),
            6 => self.repeat(),
            7 => self.while_loop(),
            8 => self.do_while(),
            9 => self.condition(),
            10 => self.cycle(),
            11 => self.absolute_move(),
            _ => self.arc(),
        }
    }

    /// Spindle-synchronized motion: a G33 move, a G33.1 rigid tap, or a
    /// G76 threading cycle (in G18, external or internal, with degression,
    /// compound angle, spring passes and tapers), then back to G17 G1.
    fn threading(&mut self) {
        self.line("S800 M3");
        match self.below(3) {
            0 => {
                let (x, z) = (self.value(-40.0, 40.0), self.value(-30.0, 10.0));
                let k = self.value(0.2, 3.0);
                let mode = if self.below(2) == 0 { "G7" } else { "G8" };
                self.line(&format!("{mode} G33 X{x} Z{z} K{k}"));
                self.line("G8");
            }
            1 => {
                let z = self.value(-30.0, 0.0);
                let (k, i) = (self.value(0.2, 3.0), self.value(0.0, 3.0));
                self.line(&format!("G33.1 Z{z} K{k} I{i}"));
            }
            _ => {
                let (x, z0) = (self.value(-20.0, 20.0), self.value(-5.0, 5.0));
                let length = self.value(6.0, 30.0);
                let z1 = if self.below(2) == 0 {
                    z0 - length
                } else {
                    z0 + length
                };
                let pitch = self.value(0.5, 3.0);
                let peak = self.value(0.3, 3.0) * if self.below(2) == 0 { -1.0 } else { 1.0 };
                let full = self.value(0.3, 2.0);
                let first = self.value(0.05, 0.3).min(full / 2.0).max(0.01);
                let mut words = format!("G76 P{pitch} Z{z1:.3} I{peak:.3} J{first:.3} K{full}");
                if self.below(2) == 0 {
                    let _ = write!(words, " R{}", self.value(1.0, 2.5));
                }
                if self.below(2) == 0 {
                    let _ = write!(words, " Q{}", self.value(0.0, 40.0));
                }
                let _ = write!(words, " H{}", self.below(3));
                if self.below(2) == 0 {
                    let e = self.value(0.1, length / 2.0 - 0.1);
                    let _ = write!(words, " E{e} L{}", self.below(4));
                }
                // Now and then in lathe diameter mode (G7: X, I, J, K
                // are diameters).
                let mode = if self.below(3) == 0 { "G7" } else { "G8" };
                self.line(&format!("G18 {mode} G90 G0 X{x} Z{z0}"));
                self.line(&words);
                self.line("G17 G8");
            }
        }
        self.line("G90 G1");
    }

    fn absolute_move(&mut self) {
        let g = if self.below(3) == 0 { "G0" } else { "G1" };
        let mut words = format!("G90 {g}");
        let mut any = false;
        for axis in ["X", "Y", "Z"] {
            if self.below(3) != 0 {
                let v = self.coordinate();
                let _ = write!(words, " {axis}{v}");
                any = true;
            }
        }
        if !any {
            let v = self.coordinate();
            let _ = write!(words, " X{v}");
        }
        if words.len() > MAX_LINE {
            // LinuxCNC reads at most 256 characters a line.
            let v = self.value(-60.0, 60.0);
            words = format!("G90 {g} X{v}");
        }
        self.line(&words);
    }

    fn incremental_move(&mut self) {
        let (x, y, z) = (
            self.value(-15.0, 15.0),
            self.value(-15.0, 15.0),
            self.value(-5.0, 5.0),
        );
        let words = match self.below(3) {
            0 => format!("G91 G1 X{x} Y{y}"),
            1 => format!("G91 G1 X{x} Z{z}"),
            _ => format!("G91 G0 Y{y} Z{z}"),
        };
        self.line(&words);
        self.line("G90");
    }

    /// An arc written incrementally: start at the current point, centre
    /// at (I, J) from it, swept by a random angle, so the end is on the
    /// circle wherever the program stands. Or by radius R.
    fn arc(&mut self) {
        let plane = self.below(3);
        let (p, first, second, i_word, j_word) = match plane {
            0 => ("G17", "X", "Y", "I", "J"),
            1 => ("G18", "Z", "X", "K", "I"),
            _ => ("G19", "Y", "Z", "J", "K"),
        };
        let i = self.value(-12.0, 12.0);
        let j = self.value(-12.0, 12.0);
        let (i, j) = if i.abs() + j.abs() < 1.0 {
            (i + 3.0, j)
        } else {
            (i, j)
        };
        let sweep = self.value(10.0, 340.0).to_radians();
        let clockwise = self.below(2) == 0;
        let turn = if clockwise { -sweep } else { sweep };
        // Start relative to the centre, turned.
        let (sx, sy) = (-i, -j);
        let (c, s) = (turn.cos(), turn.sin());
        let (ex, ey) = (c * sx - s * sy, s * sx + c * sy);
        let (dx, dy) = (i + ex, j + ey);
        let g = if clockwise { "G2" } else { "G3" };
        let helix = if self.below(4) == 0 {
            let axis = ["Z", "Y", "X"][plane as usize];
            format!(" {axis}{}", self.value(-3.0, 3.0))
        } else {
            String::new()
        };
        if self.below(4) == 0 && sweep < std::f64::consts::PI {
            // Radius form: the shorter arc (R > 0).
            let r = (i * i + j * j).sqrt();
            self.line(&format!(
                "{p} G91 {g} {first}{dx:.6} {second}{dy:.6}{helix} R{r:.6}"
            ));
        } else {
            // LinuxCNC's P: whole turns before the arc's own sweep.
            let turns = if self.below(5) == 0 {
                format!(" P{}", 2 + self.below(2))
            } else {
                String::new()
            };
            self.line(&format!(
                "{p} G91 {g} {first}{dx:.6} {second}{dy:.6}{helix} {i_word}{i} {j_word}{j}{turns}"
            ));
        }
        self.line("G90 G17");
    }

    fn assign(&mut self) {
        let i = self.below(self.names.len() as u64) as usize;
        let name = self.names[i];
        let e = self.expression(0);
        // Kept bounded.
        self.line(&format!("#<{name}> = [[{e}] MOD 50]"));
        if self.below(3) == 0 {
            let e = self.expression(1);
            self.line(&format!("#101 = [[{e}] MOD 9]"));
        }
    }

    fn call(&mut self) {
        if self.below(2) == 0 {
            let (a, b) = (self.value(-10.0, 10.0), self.value(-10.0, 10.0));
            self.line(&format!("o<shift> call [{a}] [{b}]"));
        } else {
            let e = self.expression(1);
            self.line(&format!("o<corner> call [[ABS[{e}] MOD 12]]"));
        }
    }

    fn body(&mut self) {
        self.depth += 1;
        let n = 1 + self.below(3);
        for _ in 0..n {
            self.statement();
        }
        self.depth -= 1;
    }

    fn next_label(&mut self) -> u32 {
        self.label += 1;
        self.label
    }

    fn repeat(&mut self) {
        let o = self.next_label();
        let n = 1 + self.below(3);
        self.line(&format!("o{o} repeat [{n}]"));
        self.body();
        self.line(&format!("o{o} endrepeat"));
    }

    fn while_loop(&mut self) {
        let o = self.next_label();
        let n = 1 + self.below(3);
        self.line(&format!("#<i{o}> = 0"));
        self.line(&format!("o{o} while [#<i{o}> LT {n}]"));
        self.body();
        self.depth += 1;
        if self.below(4) == 0 {
            let inner = self.next_label();
            self.line(&format!("o{inner} if [#<i{o}> EQ 1]"));
            self.line(&format!("  #<i{o}> = [#<i{o}> + 1]"));
            self.line(&format!("  o{o} continue"));
            self.line(&format!("o{inner} endif"));
        }
        self.line(&format!("#<i{o}> = [#<i{o}> + 1]"));
        self.depth -= 1;
        self.line(&format!("o{o} endwhile"));
    }

    fn do_while(&mut self) {
        let o = self.next_label();
        let n = 1 + self.below(3);
        self.line(&format!("#<k{o}> = 0"));
        self.line(&format!("o{o} do"));
        self.body();
        self.depth += 1;
        self.line(&format!("#<k{o}> = [#<k{o}> + 1]"));
        if self.below(3) == 0 {
            let inner = self.next_label();
            self.line(&format!("o{inner} if [#<k{o}> GE 2]"));
            self.line(&format!("  o{o} break"));
            self.line(&format!("o{inner} endif"));
        }
        self.depth -= 1;
        self.line(&format!("o{o} while [#<k{o}> LT {n}]"));
    }

    fn condition(&mut self) {
        let o = self.next_label();
        let a = self.expression(1);
        let b = self.expression(1);
        let op = ["EQ", "NE", "GT", "GE", "LT", "LE"][self.below(6) as usize];
        let join = ["AND", "OR", "XOR"][self.below(3) as usize];
        let c = self.expression(2);
        self.line(&format!("o{o} if [[{a} {op} {b}] {join} [{c} GT 0]]"));
        self.body();
        if self.below(2) == 0 {
            let d = self.expression(1);
            self.line(&format!("o{o} elseif [{d} LT 5]"));
            self.body();
        }
        if self.below(2) == 0 {
            self.line(&format!("o{o} else"));
            self.body();
        }
        self.line(&format!("o{o} endif"));
    }

    /// A drilling cycle from a safe height: R above the bottom, the
    /// initial level above R (LinuxCNC refuses R below Z).
    fn cycle(&mut self) {
        let top = self.value(10.0, 20.0);
        self.line(&format!("G90 G0 Z{top}"));
        let retract = ["G98", "G99"][self.below(2) as usize];
        let r = self.value(1.0, 5.0);
        let z = self.value(-12.0, -1.0);
        let (x, y) = (self.value(-40.0, 40.0), self.value(-40.0, 40.0));
        let cycle = match self.below(4) {
            0 => "G81".to_string(),
            1 => format!("G82 P{}", self.value(0.1, 1.0)),
            2 => format!("G83 Q{}", self.value(1.0, 4.0)),
            _ => format!("G73 Q{}", self.value(1.0, 4.0)),
        };
        if self.below(4) == 0 {
            // Started in G91: R from where the tool stands, Z from R.
            let (dx, dy) = (self.value(-10.0, 10.0), self.value(-10.0, 10.0));
            let (r, z) = (-self.value(1.0, 8.0), -self.value(1.0, 6.0));
            let l = 1 + self.below(3);
            self.line(&format!("G91 {retract} {cycle} X{dx} Y{dy} Z{z} R{r} L{l}"));
            self.line("G90 G80");
            return;
        }
        self.line(&format!("{retract} {cycle} X{x} Y{y} Z{z} R{r}"));
        if self.below(2) == 0 {
            let (dx, dy) = (self.value(-10.0, 10.0), self.value(-10.0, 10.0));
            let l = 2 + self.below(3);
            self.line(&format!("G91 X{dx} Y{dy} L{l}"));
            self.line("G90");
        } else {
            let (x2, y2) = (self.value(-40.0, 40.0), self.value(-40.0, 40.0));
            self.line(&format!("X{x2} Y{y2}"));
        }
        self.line("G80");
    }
}

#[test]
fn every_random_program_is_accepted_by_rs274() {
    // The generator's own check: a program rs274 refuses tests nothing.
    if !require_rs274() {
        return;
    }
    let dir = work_dir("lcnc_generator");
    for seed in 1..=PROGRAMS {
        let text = Generator::new(seed).program();
        let program = dir.join(format!("random_{seed}.ngc"));
        std::fs::write(&program, &text).expect("program written");
        let run = Rs274 {
            program: &program,
            ini: None,
            tool_table: None,
        };
        let moves = rs274_moves(&run).unwrap_or_else(|e| panic!("seed {seed}: {e}\n{text}"));
        assert!(moves.len() >= 3, "seed {seed} moves too little");
    }
}

/// How a corpus file is run.
#[derive(Clone, Copy)]
enum Kind {
    /// A main program, run as it is.
    Main,
    /// A file holding one subroutine `o<NAME> sub … endsub` (an NGCGUI
    /// subfile): run by `o<NAME> call` with the defaults its NGCGUI
    /// comments give (`#<zmax> = #1 (=10)`) and `M2`, followed by the
    /// file (the call finds the subroutine further on), as NGCGUI runs it.
    Subfile(&'static str),
}

/// The LinuxCNC programs of the shared corpus rs274 runs to their end
/// when M428 / M429 / M430 (switch kinematics; no motion) are remapped to
/// empty subroutines: file, how it runs, its rotary axes.
///
/// Left out: the `lcnc_trsrn_*` tilted-work-plane demos and
/// `lcnc_suite_twp_simple_example.ngc` (their `G68.2`, `G53.x`, `G69` are
/// Python remaps of the configuration, which rs274 runs only inside
/// LinuxCNC's task), and `lcnc_xyzab-tdr-demo.ngc` (it reads
/// `#<_hal[…]>` pins, which only a running HAL has), and
/// `lcnc_bridgemill_5axisgui.ngc` (it moves W: rs274 outside LinuxCNC's
/// task takes X Y Z A B C only, "Bad character 'w' used").
const CORPUS: &[(&str, Kind, &str)] = &[
    ("lcnc_boat-xyzac.ngc", Kind::Main, "AC"),
    ("lcnc_boat-xyzbc.ngc", Kind::Main, "BC"),
    ("lcnc_impeller-7bl-xyzac.ngc", Kind::Main, "AC"),
    ("lcnc_xyzac_switchkins_test_1.ngc", Kind::Main, "AC"),
    ("lcnc_xyzac_switchkins_test_2.ngc", Kind::Main, "AC"),
    ("lcnc_xyzac_switchkins_test_3.ngc", Kind::Main, "AC"),
    ("lcnc_helix_ac.ngc", Kind::Subfile("helix_ac"), "AC"),
    ("lcnc_helix_bc.ngc", Kind::Subfile("helix_bc"), "BC"),
    ("lcnc_centering.ngc", Kind::Subfile("centering"), "AC"),
    (
        "lcnc_xyzac_switchkins_sub.ngc",
        Kind::Subfile("xyzac_switchkins_sub"),
        "AC",
    ),
    (
        "lcnc_xyzbc_switchkins_sub.ngc",
        Kind::Subfile("xyzbc_switchkins_sub"),
        "BC",
    ),
    (
        "lcnc_gmoccapy_test-xyzac.ngc",
        Kind::Subfile("test-xyzac"),
        "AC",
    ),
    (
        "lcnc_gmoccapy_test-xyzbc.ngc",
        Kind::Subfile("test-xyzbc"),
        "BC",
    ),
    (
        "lcnc_trsrn_circular_pocket.ngc",
        Kind::Subfile("circular_pocket"),
        "AC",
    ),
    ("lcnc_trsrn_square.ngc", Kind::Subfile("square"), "AC"),
];

/// A machine whose axes are rs274's positions, with the table rotary
/// axes `rotary`; the switch-kinematics M codes move nothing (rs274's
/// empty remaps).
fn corpus_machine(rotary: &str) -> String {
    let mut text = String::from(
        "name = \"LinuxCNC differential machine\"\ncontrol = \"linuxcnc\"\ntype = \"table\"\n",
    );
    for axis in ["X", "Y", "Z"] {
        let _ = writeln!(
            text,
            "\n[[linear]]\nname = \"{axis}\"\nmin = -100000.0\nmax = 100000.0"
        );
    }
    for axis in rotary.chars() {
        let direction = match axis {
            'A' => "[1, 0, 0]",
            'B' => "[0, 1, 0]",
            _ => "[0, 0, 1]",
        };
        let _ = writeln!(
            text,
            "\n[[rotary]]\nname = \"{axis}\"\non = \"table\"\naxis = {direction}\ncenter = [0, 0, 0]\nmin = -100000.0\nmax = 100000.0"
        );
    }
    let _ = writeln!(
        text,
        "\n[parameters]\nsubroutine_path = [{:?}]",
        config_subroutines().display().to_string()
    );
    text.push_str("\n[m_codes]\n428 = \"signal\"\n429 = \"signal\"\n430 = \"signal\"\n");
    text
}

/// Where the corpus' switch-kinematics configuration keeps the
/// subroutines its programs call (`o<helix_ac> call`).
fn config_subroutines() -> PathBuf {
    common::corpus_dir().join("linuxcnc-configs/axis/vismach/5axis/table-rotary-tilting/remap_subs")
}

/// The INI rs274 reads: subroutines from `dir` and the configuration's
/// folder, M428–M430 remapped to the empty subroutines written in `dir`.
fn corpus_ini(dir: &Path) -> PathBuf {
    for m in [428, 429, 430] {
        std::fs::write(
            dir.join(format!("m{m}noop.ngc")),
            format!("o<m{m}noop> sub\no<m{m}noop> endsub\nM2\n"),
        )
        .expect("remap written");
    }
    let ini = dir.join("rs274.ini");
    let mut text = format!(
        "[RS274NGC]\nSUBROUTINE_PATH = {}:{}\n",
        dir.display(),
        config_subroutines().display()
    );
    for m in [428, 429, 430] {
        let _ = writeln!(text, "REMAP = M{m} modalgroup=10 ngc=m{m}noop");
    }
    std::fs::write(&ini, text).expect("INI written");
    ini
}

/// A tool table with tools 1–200 of length and diameter 0 (the kernel
/// runs without offsets: every length 0).
fn zero_tool_table(dir: &Path) -> PathBuf {
    let mut text = String::new();
    for t in 1..=200 {
        let _ = writeln!(text, "T{t} P{t} Z0 D0 ;");
    }
    let path = dir.join("zero.tbl");
    std::fs::write(&path, text).expect("tool table written");
    path
}

#[test]
fn corpus_programs_move_as_rs274_moves_them() {
    if !require_rs274() {
        return;
    }
    let Some(corpus) =
        common::corpus::corpus_path("linuxcnc-configs").map(|_| common::corpus_dir())
    else {
        return;
    };
    let dir = work_dir("lcnc_corpus");
    let ini = corpus_ini(&dir);
    let tools = zero_tool_table(&dir);
    let mut failures = Vec::new();
    let mut moves = 0;
    for (file, kind, rotary) in CORPUS {
        let source = std::fs::read_to_string(corpus.join(file)).expect("corpus file");
        let text = match kind {
            Kind::Main => source,
            Kind::Subfile(name) => {
                let call = common::ngcgui_call(name, &source);
                format!("{call}\nM2\n{source}")
            }
        };
        let program = dir.join(file);
        std::fs::write(&program, &text).expect("program written");
        let machine = dir.join(format!("machine-{rotary}.toml"));
        std::fs::write(&machine, corpus_machine(rotary)).expect("machine written");
        let run = Rs274 {
            program: &program,
            ini: Some(&ini),
            tool_table: Some(&tools),
        };
        match compare_runs(&run, &machine) {
            Ok(n) => {
                eprintln!("{file}: {n} moves agree");
                moves += n;
            }
            Err(why) => failures.push(why),
        }
    }
    eprintln!(
        "{} of {} corpus programs agree with rs274 ({moves} moves)",
        CORPUS.len() - failures.len(),
        CORPUS.len()
    );
    assert!(
        failures.is_empty(),
        "{} corpus programs differ:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn ngcgui_defaults_make_the_call() {
    let text =
        "o<h>sub\n #<zmax> = #1 (=10)\n #<r> = #3 (= -2.5 radius)\n#<x> = #<zmax>\no<h>endsub\n";
    assert_eq!(common::ngcgui_call("h", text), "o<h> call [10] [0] [-2.5]");
}
