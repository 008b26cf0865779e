//! Conformance run over the shared corpus of real programs written by
//! others (`../shared/corpus/` beside the workspace; never copied into the
//! repository).
//!
//! The programs are FANUC-family, LinuxCNC, SINUMERIK (read as SINUMERIK
//! by their `.mpf` / `.spf` names) and HEIDENHAIN (not read yet). What
//! every one of them must get is a clean
//! ending: it runs to its end (exit 0), or it stops with one alarm line
//! `ALARM <code> line <n>: <message>` and the source line rendered under
//! it (exit 1). Never a panic (101), a signal, a hang, or "unusable input"
//! (2). Run with `--nocapture` to see one summary line per file.

mod common;

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

/// Longest a single corpus program may take in a debug build.
const DEADLINE: Duration = Duration::from_secs(300);

/// The corpus programs, by name.
fn programs(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("the corpus folder is readable")
        .map(|entry| entry.expect("corpus entry").path())
        .filter(|path| {
            path.extension()
                .is_some_and(|ext| ext == "ngc" || ext == "mpf")
        })
        .collect();
    files.sort();
    files
}

/// Where the NMV5000 program stops, and why.
const NMV5000_STOP: Option<(&str, usize, &str)> = Some((
    "PS0045",
    630,
    "the post writes `G83 … Q0.0`: a FANUC control stops there with PS0045 \
     (G73/G83 without Q, or Q0). Everything before it runs: milling, G05.1 \
     AI contour control, G43.4 TCPC, G28/G30/G53, G73 and G74 cycles under TCPC",
));

/// B/C programs run on the B/C trunnion, everything else on the default.
fn machine_for(name: &str) -> &'static str {
    if name.contains("bc") {
        "trunnion-bc"
    } else {
        "trunnion-ac"
    }
}

/// How one run ended.
struct Outcome {
    /// `None`: killed at the deadline.
    status: Option<ExitStatus>,
    rows: usize,
    stderr: String,
    /// The header and the first row of each line asked for (`pick`).
    picked: Vec<String>,
}

/// What the binary reads: a corpus file as it is, or its text after an
/// operator's edits, given on standard input (`-`).
enum Input<'a> {
    File(&'a Path),
    Edited(&'a [u8]),
}

/// Runs the binary on `program`, counting output lines and keeping
/// standard error, with a deadline.
fn run(program: &Path, machine: &str) -> Outcome {
    run_with(Input::File(program), &["--machine", machine], &[])
}

/// Runs the binary on `input` with `args`, keeping the header and the
/// first row of each program line in `pick`.
fn run_with(input: Input<'_>, args: &[&str], pick: &[usize]) -> Outcome {
    let mut command = Command::new(env!("CARGO_BIN_EXE_fiveaxis"));
    command.arg("run");
    match input {
        Input::File(path) => command.arg(path).stdin(Stdio::null()),
        Input::Edited(_) => command.arg("-").stdin(Stdio::piped()),
    };
    let mut child = command
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the fiveaxis binary starts");
    let feeder = match input {
        Input::File(_) => None,
        Input::Edited(text) => {
            let mut stdin = child.stdin.take().expect("piped stdin");
            let text = text.to_vec();
            Some(thread::spawn(move || {
                use std::io::Write;
                let _ = stdin.write_all(&text);
            }))
        }
    };
    let stdout = child.stdout.take().expect("piped stdout");
    let mut stderr = child.stderr.take().expect("piped stderr");
    let pick = pick.to_vec();
    let rows = thread::spawn(move || {
        let mut count: usize = 0;
        let mut picked = Vec::new();
        let mut seen = Vec::new();
        for row in BufReader::new(stdout).split(b'\n') {
            let Ok(row) = row else { break };
            let row = String::from_utf8_lossy(&row).into_owned();
            let line = row.split(',').next().and_then(|n| n.parse::<usize>().ok());
            if count == 0 {
                picked.push(row);
            } else if let Some(n) = line.filter(|n| pick.contains(n) && !seen.contains(n)) {
                seen.push(n);
                picked.push(row);
            }
            count += 1;
        }
        (count.saturating_sub(1), picked)
    });
    let errors = thread::spawn(move || {
        let mut bytes = Vec::new();
        let _ = stderr.read_to_end(&mut bytes);
        String::from_utf8_lossy(&bytes).into_owned()
    });
    let status = wait_until(&mut child, Instant::now() + DEADLINE);
    if let Some(feeder) = feeder {
        feeder.join().expect("stdin writer");
    }
    let (rows, picked) = rows.join().expect("stdout reader");
    Outcome {
        status,
        rows,
        stderr: errors.join().expect("stderr reader"),
        picked,
    }
}

fn wait_until(child: &mut Child, deadline: Instant) -> Option<ExitStatus> {
    loop {
        if let Some(status) = child.try_wait().expect("waiting for fiveaxis") {
            return Some(status);
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        thread::sleep(Duration::from_millis(20));
    }
}

/// The parts of an `ALARM <code> line <n>: <message>` line.
fn parse_alarm_line(line: &str) -> Option<(&str, usize, &str)> {
    let rest = line.strip_prefix("ALARM ")?;
    let (code, rest) = rest.split_once(' ')?;
    let rest = rest.strip_prefix("line ")?;
    let (number, message) = rest.split_once(": ")?;
    let valid = !code.is_empty()
        && !code.contains(char::is_whitespace)
        && !number.is_empty()
        && number.bytes().all(|b| b.is_ascii_digit())
        && !message.trim().is_empty();
    valid.then_some((code, number.parse().ok()?, message))
}

/// Whether standard error shows line `n` of `source` under a `n |` gutter.
fn renders_source_line(stderr: &str, source: &str, n: usize) -> bool {
    let words = |text: &str| text.split_whitespace().collect::<Vec<_>>().join(" ");
    let Some(expected) = source.lines().nth(n.saturating_sub(1)).map(words) else {
        return false;
    };
    let gutter = format!("{n} |");
    stderr
        .lines()
        .filter_map(|line| line.trim_start().strip_prefix(&gutter))
        .any(|shown| words(shown) == expected)
}

/// What is wrong with how a run of `source` ended, if anything; and its
/// summary.
fn judge(source: &[u8], outcome: &Outcome) -> (String, Option<String>) {
    let Some(status) = outcome.status else {
        return (
            "timeout".into(),
            Some(format!("still running after {DEADLINE:?}")),
        );
    };
    let first_alarm = outcome.stderr.lines().find(|l| l.starts_with("ALARM "));
    let exit = status
        .code()
        .map_or_else(|| format!("{status}"), |code| format!("exit {code}"));
    let summary = format!(
        "{exit}, {} rows, {}",
        outcome.rows,
        first_alarm.unwrap_or("no alarm")
    );
    let problem = match status.code() {
        Some(0) => None,
        Some(1) => match first_alarm.and_then(parse_alarm_line) {
            None => Some(format!(
                "exit 1 without an `ALARM <code> line <n>: <message>` line:\n{}",
                outcome.stderr
            )),
            Some((_, n, _)) => {
                let source = String::from_utf8_lossy(source);
                (!renders_source_line(&outcome.stderr, &source, n))
                    .then(|| format!("source line {n} is not rendered:\n{}", outcome.stderr))
            }
        },
        _ => Some(format!(
            "{exit} (a panic, a signal or unusable input):\n{}",
            outcome.stderr
        )),
    };
    (summary, problem)
}

#[test]
fn every_corpus_program_ends_cleanly_or_with_one_rendered_alarm() {
    let Some(dir) = common::corpus::corpus_path("MANIFEST.tsv").map(|_| common::corpus_dir())
    else {
        return;
    };
    let mut failures = Vec::new();
    for program in programs(&dir) {
        let name = program
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default()
            .to_owned();
        let machine = machine_for(&name);
        let source = std::fs::read(&program).expect("corpus file");
        let (summary, problem) = judge(&source, &run(&program, machine));
        println!("corpus: {name} on {machine}: {summary}");
        if let Some(problem) = problem {
            failures.push(format!("{name}: {problem}"));
        }
    }
    assert!(
        failures.is_empty(),
        "{} corpus programs did not end cleanly:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn alarm_lines_are_recognised_only_in_the_contract_form() {
    assert_eq!(
        parse_alarm_line("ALARM PS0010 line 3: G5.1 is bad"),
        Some(("PS0010", 3, "G5.1 is bad"))
    );
    assert_eq!(
        parse_alarm_line("ALARM P34 line 12: x"),
        Some(("P34", 12, "x"))
    );
    assert_eq!(parse_alarm_line("ALARM PS0010 line x: bad"), None);
    assert_eq!(parse_alarm_line("ALARM  line 3: no code"), None);
    assert_eq!(parse_alarm_line("ALARM PS0010 line 3: "), None);
    assert_eq!(parse_alarm_line("error: PS0010 line 3: x"), None);
}

/// The FANUC-family programs of the corpus (FANUC, and Haas's FANUC-like
/// control), each on a machine that fits it (machine and offsets files in
/// `tests/corpus-setups/`), and how each must end: at its end, or with the
/// alarm a real control raises there too.
struct Conformance {
    program: &'static str,
    /// A machine file of `tests/corpus-setups/` (`….toml`) or a built-in.
    machine: &'static str,
    offsets: &'static str,
    /// Edits an operator makes before running the program on the control
    /// (in memory; the corpus file is never changed), each with its reason.
    edits: &'static [Edit],
    /// `None`: runs to its end; `Some((code, line, why))`: stops there.
    stop: Option<(&'static str, usize, &'static str)>,
    /// Machine positions the run must reach, worked out by hand.
    positions: &'static [Position],
}

/// One line of the program replaced, as an operator does at the control.
struct Edit {
    /// 1-based line number.
    line: usize,
    /// The line as the corpus has it (checked, so that an edit cannot
    /// silently land on another line).
    was: &'static str,
    /// The line the operator writes instead.
    now: &'static str,
    /// Why a real control needs the edit.
    why: &'static str,
}

/// A machine position in the first row of a program line, computed by hand.
struct Position {
    line: usize,
    /// Output column (`X`, `Y`, `Z`, `feed`, …).
    column: &'static str,
    value: f64,
    /// How the value was worked out.
    why: &'static str,
}

/// Rows are printed in the shortest round-trip form of values computed in
/// binary: a hand-computed millimetre value matches them to this.
const POSITION_TOLERANCE: f64 = 1e-9;

/// Millimetres in an inch (Haas Setting 9 = INCH: the corpus program's
/// numbers are inches).
const MM_PER_INCH: f64 = 25.4;

/// The Haas setup's G54 (`haas-vf2tr-offsets.toml`), mm.
const HAAS_G54: [f64; 3] = [-381.0, -203.0, -550.0];
/// The length of tool 8 in the Haas setup, mm.
const HAAS_TOOL_8: f64 = 140.0;

const FANUC_FAMILY: &[Conformance] = &[
    Conformance {
        program: "fanuc_nx_nmv5000_mm.nc",
        machine: "nmv5000.toml",
        offsets: "nmv5000-offsets.toml",
        edits: &[],
        stop: NMV5000_STOP,
        positions: &[],
    },
    Conformance {
        program: "fanuc_nx_nmv5000_mm.nc",
        machine: "nmv5000.toml",
        offsets: "nmv5000-offsets.toml",
        edits: &[Edit {
            line: 630,
            was: "G99 G83 Z-3. R3. F250. Q0.0",
            now: "G99 G83 Z-3. R3. F250. Q1.",
            why: "the post writes a peck depth of zero, with which a FANUC control \
                  stops (PS0045, the case above): the operator enters the peck the \
                  operation needs, 1 mm for the 6 mm from R to the bottom",
        }],
        stop: None,
        positions: &[],
    },
    Conformance {
        program: "haas_nx_vf2tr_5T.nc",
        machine: "haas-vf2-tr160",
        offsets: "haas-vf2tr-offsets.toml",
        edits: &[
            Edit {
                line: 2,
                was: "O ENTER OP AND LAST 3 DIGITS",
                now: "O1201",
                why: "the post leaves this placeholder for the operator, who writes the \
                      program number it asks for (operation 1, part UGTI0201): a Haas \
                      control refuses an O line without a number, and so does the kernel \
                      (FX0004, `haas_control.rs`)",
            },
            Edit {
                line: 977,
                was: "G83 X.9879 Y-.9882 Z1.8504 R2.0866 F9.8 Q0.0",
                now: "G83 X.9879 Y-.9882 Z1.8504 R2.0866 F9.8 Q.1",
                why: "the post writes a peck depth of zero, with which no control can peck \
                      (FANUC PS0045, the kernel's FX0131): the operator enters the peck \
                      the operation needs, 0.1 inch for the 7 mm drill",
            },
        ],
        stop: None,
        positions: &[
            Position {
                line: 34,
                column: "X",
                value: HAAS_G54[0] - 0.2377 * MM_PER_INCH,
                why: "`G90 G43 G00 X-.2377 … H008`: G54 X - 0.2377 in",
            },
            Position {
                line: 34,
                column: "Y",
                value: HAAS_G54[1] + 0.2521 * MM_PER_INCH,
                why: "`Y.2521`: G54 Y + 0.2521 in",
            },
            Position {
                line: 34,
                column: "Z",
                value: HAAS_G54[2] + HAAS_TOOL_8 + 8.0 * MM_PER_INCH,
                why: "`Z8. … H008`: G54 Z + tool 8 + 8 in",
            },
            Position {
                line: 38,
                column: "feed",
                value: 9.8 * MM_PER_INCH,
                why: "`G01 Z1.7224 F9.8`: 9.8 inch/min",
            },
            Position {
                line: 1082,
                column: "Y",
                value: 0.0,
                why: "`G90 G53 G00 Y0.0`, the last move before M30: machine Y 0",
            },
        ],
    },
];

/// The program text after the operator's `edits`, or what is wrong with
/// an edit.
fn edited(source: &[u8], edits: &[Edit]) -> Result<Vec<u8>, String> {
    let mut lines: Vec<&[u8]> = source.split(|&b| b == b'\n').collect();
    for edit in edits {
        let Some(line) = lines.get_mut(edit.line - 1) else {
            return Err(format!("edit of line {}: no such line", edit.line));
        };
        let text = String::from_utf8_lossy(line);
        if text.trim_end() != edit.was {
            return Err(format!(
                "edit of line {}: the line is `{text}`, not `{}`",
                edit.line, edit.was
            ));
        }
        *line = edit.now.as_bytes();
    }
    Ok(lines.join(&b'\n'))
}

/// What is wrong with the rows of `positions`, if anything.
fn check_positions(outcome: &Outcome, positions: &[Position]) -> Vec<String> {
    let Some(header) = outcome.picked.first() else {
        return vec!["no output header".into()];
    };
    let columns: Vec<&str> = header.split(',').collect();
    let mut problems = Vec::new();
    for p in positions {
        let row = outcome.picked.iter().skip(1).find(|row| {
            row.split(',').next().and_then(|n| n.parse::<usize>().ok()) == Some(p.line)
        });
        let value = columns
            .iter()
            .position(|&c| c == p.column)
            .zip(row)
            .and_then(|(i, row)| row.split(',').nth(i))
            .and_then(|v| v.parse::<f64>().ok());
        match value {
            Some(v) if (v - p.value).abs() <= POSITION_TOLERANCE => {}
            other => problems.push(format!(
                "line {} {}: {other:?}, expected {} ({})",
                p.line, p.column, p.value, p.why
            )),
        }
    }
    problems
}

#[test]
fn fanuc_family_programs_run_to_their_end_or_stop_where_the_control_would() {
    let Some(dir) = common::corpus::corpus_path("MANIFEST.tsv").map(|_| common::corpus_dir())
    else {
        return;
    };
    let setups = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus-setups");
    let mut failures = Vec::new();
    for case in FANUC_FAMILY {
        let machine = if case.machine.ends_with(".toml") {
            setups.join(case.machine).display().to_string()
        } else {
            case.machine.to_owned()
        };
        let offsets = setups.join(case.offsets).display().to_string();
        let case = Case {
            program: case.program,
            edits: case.edits,
            stop: case.stop,
            positions: case.positions,
        };
        failures.extend(conform(
            "conformance",
            &dir,
            &case,
            &["--machine", &machine, "--offsets", &offsets],
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One corpus program's run against how it must end.
struct Case<'a> {
    program: &'a str,
    edits: &'a [Edit],
    stop: Option<(&'a str, usize, &'a str)>,
    positions: &'a [Position],
}

/// Runs `case` (after its operator's edits) with `args` and says what is
/// wrong: an end other than the one asked for, or a position off its
/// hand-computed value. Prints one summary line under `label`.
fn conform(label: &str, dir: &Path, case: &Case<'_>, args: &[&str]) -> Vec<String> {
    let mut failures = Vec::new();
    let program = dir.join(case.program);
    if !program.is_file() {
        return vec![format!("{}: not in the corpus", case.program)];
    }
    let source = std::fs::read(&program).expect("corpus file");
    let text = match edited(&source, case.edits) {
        Ok(text) => text,
        Err(problem) => return vec![format!("{}: {problem}", case.program)],
    };
    let input = if case.edits.is_empty() {
        Input::File(&program)
    } else {
        Input::Edited(&text)
    };
    let pick: Vec<usize> = case.positions.iter().map(|p| p.line).collect();
    let outcome = run_with(input, args, &pick);
    let (summary, _) = judge(&text, &outcome);
    println!(
        "{label}: {} ({} operator edits): {summary}",
        case.program,
        case.edits.len()
    );
    for edit in case.edits {
        println!(
            "  line {}: `{}` -> `{}`: {}",
            edit.line, edit.was, edit.now, edit.why
        );
    }
    let first_alarm = outcome
        .stderr
        .lines()
        .find(|l| l.starts_with("ALARM "))
        .and_then(parse_alarm_line)
        .map(|(code, line, _)| (code.to_owned(), line));
    let code = outcome.status.and_then(|s| s.code());
    match case.stop {
        None if code != Some(0) => failures.push(format!(
            "{} should run to its end: {summary}\n{}",
            case.program, outcome.stderr
        )),
        Some((want, line, why)) if first_alarm != Some((want.to_owned(), line)) => {
            failures.push(format!(
                "{} should stop with {want} at line {line} ({why}): {summary}\n{}",
                case.program, outcome.stderr
            ))
        }
        _ => {}
    }
    for problem in check_positions(&outcome, case.positions) {
        failures.push(format!("{}: {problem}", case.program));
    }
    failures
}

/// The LinuxCNC programs of the corpus read as LinuxCNC reads them: on
/// the built-in trunnions with `control = "linuxcnc"`
/// (`tests/corpus-setups/trunnion-*-linuxcnc.toml`), and where each stops
/// for now. Most are subroutine files (`o<name> sub` … `endsub`): run
/// alone, the definition is skipped and the file ends without M2 or `%`,
/// FX0126 at its last line, as `rs274` stops ("File ended with no percent
/// sign or program end"); one has its M2. The others stop at what these
/// machine files lack: the
/// configurations' own M codes (`M428`/`M429`, remapped kinematics
/// switches), a B axis on the A/C trunnion, the soft limits of the
/// built-in machine, and the tilted-working-plane codes (`G68.2 … Q`),
/// which LinuxCNC has only through the remap these machine files do not
/// declare (`twp_remap`; the demos run to M2 with it in
/// `linuxcnc_twp_demos.rs`).
#[test]
fn linuxcnc_programs_read_as_linuxcnc() {
    if common::corpus::corpus_path("MANIFEST.tsv").is_none() {
        return;
    }
    const CLEAN: Option<(&str, usize)> = None;
    let cases: [(&str, Option<(&str, usize)>); 22] = [
        ("lcnc_boat-xyzac.ngc", Some(("FX0011", 2))),
        ("lcnc_boat-xyzbc.ngc", Some(("FX0011", 2))),
        ("lcnc_bridgemill_5axisgui.ngc", Some(("FX0004", 18))),
        ("lcnc_centering.ngc", Some(("FX0126", 42))),
        ("lcnc_gmoccapy_test-xyzac.ngc", Some(("FX0126", 47))),
        ("lcnc_gmoccapy_test-xyzbc.ngc", Some(("FX0126", 47))),
        ("lcnc_helix_ac.ngc", Some(("FX0126", 22))),
        ("lcnc_helix_bc.ngc", Some(("FX0126", 22))),
        ("lcnc_impeller-7bl-xyzac.ngc", Some(("FX0011", 4))),
        ("lcnc_suite_twp_simple_example.ngc", Some(("FX0501", 6))),
        ("lcnc_trsrn_circular_pocket.ngc", CLEAN),
        ("lcnc_trsrn_incremental_repetition.ngc", Some(("FX0010", 4))),
        (
            "lcnc_trsrn_incremental_repetition_back_and_forth.ngc",
            Some(("FX0010", 4)),
        ),
        (
            "lcnc_trsrn_incremental_repetition_g533.ngc",
            Some(("FX0010", 4)),
        ),
        ("lcnc_trsrn_simple_example.ngc", Some(("FX0500", 4))),
        ("lcnc_trsrn_square.ngc", Some(("FX0126", 9))),
        ("lcnc_xyzab-tdr-demo.ngc", Some(("FX0011", 4))),
        ("lcnc_xyzac_switchkins_sub.ngc", Some(("FX0126", 47))),
        ("lcnc_xyzac_switchkins_test_1.ngc", Some(("FX0011", 4))),
        ("lcnc_xyzac_switchkins_test_2.ngc", Some(("FX0011", 4))),
        ("lcnc_xyzac_switchkins_test_3.ngc", Some(("FX0011", 2))),
        ("lcnc_xyzbc_switchkins_sub.ngc", Some(("FX0126", 47))),
    ];
    let Some(dir) = common::corpus::corpus_path("MANIFEST.tsv").map(|_| common::corpus_dir())
    else {
        return;
    };
    let setups = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus-setups");
    let mut failures = Vec::new();
    for (name, stop) in cases {
        let program = dir.join(name);
        if !program.exists() {
            continue;
        }
        let machine = if name.contains("bc") {
            "trunnion-bc-linuxcnc.toml"
        } else {
            "trunnion-ac-linuxcnc.toml"
        };
        let machine = setups.join(machine).display().to_string();
        let outcome = run_with(Input::File(&program), &["--machine", &machine], &[]);
        let alarm = outcome.stderr.lines().find_map(parse_alarm_line);
        let got = alarm.map(|(code, line, _)| (code, line));
        let ended = outcome.status.is_some();
        if !ended || got != stop {
            failures.push(format!(
                "{name}: expected {stop:?}, got {got:?} (ended: {ended}); stderr: {}",
                outcome.stderr.lines().next().unwrap_or("")
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The SINUMERIK programs of the corpus, each on a SINUMERIK machine that
/// fits it (`tests/corpus-setups/`), with the program memory a shop keeps
/// beside them (`tests/corpus-setups/sinumerik-programs/`: the builder's
/// and the shop's user cycles the programs call, as stand-ins written for
/// these tests), and how each must end.
struct SinumerikCase {
    program: &'static str,
    machine: &'static str,
    edits: &'static [Edit],
    stop: Option<(&'static str, usize, &'static str)>,
    positions: &'static [Position],
}

const SINUMERIK: &[SinumerikCase] = &[
    SinumerikCase {
        program: "siemens_pyronc_atsumu.mpf",
        machine: "sinumerik-3axis.toml",
        edits: &[],
        stop: None,
        positions: &[
            Position {
                line: 16,
                column: "Y",
                value: 0.0,
                why: "`TRANS Y-110 Z26` then `G1 X52.609 Y110 Z6`: Y 110 - 110",
            },
            Position {
                line: 16,
                column: "Z",
                value: 32.0,
                why: "Z 6 + 26 (the programmable frame); D1 of a tool without data: no length",
            },
        ],
    },
    SinumerikCase {
        program: "siemens_pyronc_strojnica.mpf",
        machine: "sinumerik-3axis.toml",
        edits: &[],
        stop: None,
        positions: &[],
    },
    SinumerikCase {
        program: "siemens_spinner_u5_achskreuz.mpf",
        machine: "spinner-u5.toml",
        edits: &[],
        stop: None,
        positions: &[],
    },
    SinumerikCase {
        program: "siemens_spinner_u5_bottle_opener.mpf",
        machine: "spinner-u5.toml",
        edits: &[],
        stop: None,
        positions: &[],
    },
    SinumerikCase {
        program: "siemens_spinner_u5_keychain.mpf",
        machine: "spinner-u5.toml",
        edits: &[],
        stop: None,
        positions: &[
            Position {
                line: 19,
                column: "X",
                value: -365.0,
                why: "`SUPA G0 X=_X_HOME …` with `_X_HOME=-365.`: machine X, frames suppressed",
            },
            Position {
                line: 19,
                column: "Y",
                value: 224.0,
                why: "`Y=_Y_HOME`, `_Y_HOME=224.`: machine Y",
            },
        ],
    },
    SinumerikCase {
        program: "siemens_nx_ftv5_840d.mpf",
        machine: "cincinnati-ftv5.toml",
        edits: &[],
        stop: Some((
            "14011",
            362,
            "the post writes `TRAOOF`, a misspelling of TRAFOOF: to the control a name \
             alone is a subprogram call, and no program of that name exists (14011)",
        )),
        positions: &[
            Position {
                line: 15,
                column: "X",
                value: 2.212 * MM_PER_INCH,
                why: "`G70` inch: `G0 X2.212 … A0 C0` under TRAORI(1), head upright, no tool length",
            },
            Position {
                line: 15,
                column: "Y",
                value: 0.4884 * MM_PER_INCH,
                why: "`Y.4884` inch",
            },
        ],
    },
    SinumerikCase {
        program: "siemens_nx_ftv5_840d.mpf",
        machine: "cincinnati-ftv5.toml",
        edits: &[
            Edit {
                line: 362,
                was: "TRAOOF",
                now: "TRAFOOF",
                why: "the operator corrects the post's misspelling of TRAFOOF",
            },
            Edit {
                line: 388,
                was: "TRAOOF",
                now: "TRAFOOF",
                why: "the same misspelling, a second time",
            },
        ],
        stop: Some((
            "12470",
            431,
            "the post selects the settable frame with `G503`: an 840D has G54–G57 and \
             G505–G599 (ONE p145, MD28080), no G501–G504, so the control refuses the \
             G function (12470)",
        )),
        positions: &[],
    },
    SinumerikCase {
        program: "siemens_nx_ftv5_840d.mpf",
        machine: "cincinnati-ftv5.toml",
        edits: &[
            Edit {
                line: 362,
                was: "TRAOOF",
                now: "TRAFOOF",
                why: "the operator corrects the post's misspelling of TRAFOOF",
            },
            Edit {
                line: 388,
                was: "TRAOOF",
                now: "TRAFOOF",
                why: "the same misspelling, a second time",
            },
            Edit {
                line: 431,
                was: "G503",
                now: "G505",
                why: "the operator puts the part's zero in settable frame 5 and selects it",
            },
            Edit {
                line: 481,
                was: "G503",
                now: "G505",
                why: "the same selection, a second time",
            },
            Edit {
                line: 889,
                was: "G503",
                now: "G505",
                why: "the same selection, a third time",
            },
            Edit {
                line: 908,
                was: "G503",
                now: "G505",
                why: "the same selection, a fourth time",
            },
            Edit {
                line: 927,
                was: "G503",
                now: "G505",
                why: "the same selection, a fifth time",
            },
        ],
        stop: Some((
            "61001",
            860,
            "the tapping operation calls `MCALL CYCLE84(… , , 3, , , , 900., 0, …)` with \
             neither MPIT nor PIT: the cycle has no thread pitch and stops at the first \
             hole (61001). Before it: CYCLE800 swivels (mode 57), TRAORI, the MCALL \
             CYCLE83 deep-hole drilling",
        )),
        positions: &[],
    },
    SinumerikCase {
        program: "siemens_bladmill_starrag_traori.spf",
        machine: "starrag-hx151.toml",
        edits: &[],
        stop: None,
        positions: &[Position {
            line: 3784,
            column: "Z",
            value: 290.0,
            why: "`G0 G53 D0 Z290.0`: machine Z, frames and length off",
        }],
    },
    SinumerikCase {
        program: "siemens_bladmill_starrag_main.mpf",
        machine: "starrag-hx151.toml",
        edits: &[],
        stop: None,
        positions: &[],
    },
];

/// The program memory of the SINUMERIK runs, in a temporary folder: the
/// fixture user cycles and definitions, the corpus's operation program
/// 4444411 (the Starrag main program calls it by `EXTCALL`), and for the
/// other operation programs the main program calls, which the corpus does
/// not hold, stand-ins that return at once.
fn sinumerik_memory(corpus: &Path) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let fixtures =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus-setups/sinumerik-programs");
    for entry in std::fs::read_dir(&fixtures).expect("the fixture programs") {
        let path = entry.expect("fixture entry").path();
        std::fs::copy(
            &path,
            dir.path().join(path.file_name().expect("a file name")),
        )
        .expect("copied");
    }
    std::fs::copy(
        corpus.join("siemens_bladmill_starrag_traori.spf"),
        dir.path().join("4444411.SPF"),
    )
    .expect("copied");
    let main = std::fs::read_to_string(corpus.join("siemens_bladmill_starrag_main.mpf"))
        .unwrap_or_default();
    for call in main.split("EXTCALL(\"").skip(1) {
        let name: String = call.chars().take_while(char::is_ascii_digit).collect();
        let path = dir.path().join(format!("{name}.SPF"));
        if !name.is_empty() && !path.exists() {
            std::fs::write(
                &path,
                "; a stand-in for an operation program not in the corpus\nM17\n",
            )
            .expect("written");
        }
    }
    dir
}

#[test]
fn sinumerik_programs_run_to_their_end_or_stop_where_the_control_would() {
    let Some(dir) = common::corpus::corpus_path("MANIFEST.tsv").map(|_| common::corpus_dir())
    else {
        return;
    };
    let setups = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus-setups");
    let memory = sinumerik_memory(&dir);
    let memory = memory.path().display().to_string();
    let mut failures = Vec::new();
    for case in SINUMERIK {
        let machine = setups.join(case.machine).display().to_string();
        let case = Case {
            program: case.program,
            edits: case.edits,
            stop: case.stop,
            positions: case.positions,
        };
        failures.extend(conform(
            "sinumerik",
            &dir,
            &case,
            &["--machine", &machine, "--programs", &memory],
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The HEIDENHAIN programs of the corpus (hyperMILL output for a DMG DMU
/// 85 monoBLOCK, TNC 640) on that machine (`tests/corpus-setups/
/// dmu85-monoblock.toml`, the preset and tools in `dmu85-offsets.toml`).
/// The rotary positions are the programs' own comments (`; A-90 C0` before
/// each `PLANE … STAY`); the tips are worked out from the datum shift and
/// the plane's rotation by hand.
const HEIDENHAIN: &[Conformance] = &[
    Conformance {
        program: "heidenhain_hypermill_dmu85_a7.h",
        machine: "dmu85-monoblock.toml",
        offsets: "dmu85-offsets.toml",
        edits: &[],
        stop: None,
        positions: &[
            Position {
                line: 59,
                column: "A",
                value: -90.0,
                why: "PLANE SPATIAL SPA90 SPB0 SPC180 STAY SEQ-, then L A+Q120: the comment's A-90",
            },
            Position {
                line: 59,
                column: "C",
                value: 0.0,
                why: "the comment's C0",
            },
            Position {
                line: 62,
                column: "tip_x",
                value: -159.0,
                why: "shift (0, 55, -25) + Rz(180)·Rx(90)·(159, 7, 70) = (-159, 125, -18)",
            },
            Position {
                line: 62,
                column: "tip_y",
                value: 125.0,
                why: "55 + 70: the plane's Z is the part's +Y",
            },
            Position {
                line: 62,
                column: "tip_z",
                value: -18.0,
                why: "-25 + 7: the plane's Y is the part's +Z",
            },
            Position {
                line: 90,
                column: "C",
                value: 270.0,
                why: "PLANE SPATIAL SPA90 SPB0 SPC90 … SEQ-: the comment's A-90 C270",
            },
        ],
    },
    Conformance {
        program: "heidenhain_hypermill_dmu85_a10.h",
        machine: "dmu85-monoblock.toml",
        offsets: "dmu85-offsets.toml",
        edits: &[],
        stop: None,
        positions: &[Position {
            line: 109,
            column: "A",
            value: 0.0,
            why: "PLANE SPATIAL SPA0 SPB0 SPC0 STAY SEQ+: the comment's A0 C0",
        }],
    },
    Conformance {
        program: "heidenhain_hypermill_dmu85_b5.h",
        machine: "dmu85-monoblock.toml",
        offsets: "dmu85-offsets.toml",
        edits: &[],
        stop: None,
        positions: &[
            Position {
                line: 27624,
                column: "A",
                value: -20.0,
                why: "SPA20 SPC55 SEQ-: the tool along Rz(55)·Rx(20)·Z needs A -20 with C 235 (or A 20 with C 55)",
            },
            Position {
                line: 27624,
                column: "C",
                value: 235.0,
                why: "C = 55 + 180 on the negative A solution",
            },
        ],
    },
];

#[test]
fn heidenhain_programs_run_to_their_end() {
    let Some(dir) = common::corpus::corpus_path("MANIFEST.tsv").map(|_| common::corpus_dir())
    else {
        return;
    };
    let setups = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus-setups");
    let mut failures = Vec::new();
    for case in HEIDENHAIN {
        let machine = setups.join(case.machine).display().to_string();
        let offsets = setups.join(case.offsets).display().to_string();
        let run = Case {
            program: case.program,
            edits: case.edits,
            stop: case.stop,
            positions: case.positions,
        };
        failures.extend(conform(
            "heidenhain",
            &dir,
            &run,
            &["--machine", &machine, "--offsets", &offsets],
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
