//! Conformance run over the shared corpus of real programs written by
//! others (`../shared/corpus/` beside the workspace; never copied into the
//! repository).
//!
//! Most of these programs are in dialects the kernel does not speak yet
//! (LinuxCNC, Sinumerik). What every one of them must get is a clean
//! ending: it runs to its end (exit 0), or it stops with one alarm line
//! `ALARM <code> line <n>: <message>` and the source line rendered under
//! it (exit 1). Never a panic (101), a signal, a hang, or "unusable input"
//! (2). Run with `--nocapture` to see one summary line per file.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

/// Longest a single corpus program may take in a debug build.
const DEADLINE: Duration = Duration::from_secs(300);

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
}

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
}

/// Runs the binary on `program`, counting output lines and keeping
/// standard error, with a deadline.
fn run(program: &Path, machine: &str) -> Outcome {
    run_with(program, &["--machine", machine])
}

/// Runs the binary on `program` with `args`.
fn run_with(program: &Path, args: &[&str]) -> Outcome {
    let mut child = Command::new(env!("CARGO_BIN_EXE_fiveaxis"))
        .arg("run")
        .arg(program)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the fiveaxis binary starts");
    let stdout = child.stdout.take().expect("piped stdout");
    let mut stderr = child.stderr.take().expect("piped stderr");
    let rows = thread::spawn(move || {
        BufReader::new(stdout)
            .split(b'\n')
            .count()
            .saturating_sub(1)
    });
    let errors = thread::spawn(move || {
        let mut bytes = Vec::new();
        let _ = stderr.read_to_end(&mut bytes);
        String::from_utf8_lossy(&bytes).into_owned()
    });
    let status = wait_until(&mut child, Instant::now() + DEADLINE);
    Outcome {
        status,
        rows: rows.join().expect("stdout reader"),
        stderr: errors.join().expect("stderr reader"),
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

/// What is wrong with how a run ended, if anything; and its summary.
fn judge(program: &Path, outcome: &Outcome) -> (String, Option<String>) {
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
                let source = String::from_utf8_lossy(&std::fs::read(program).expect("corpus file"))
                    .into_owned();
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
    let dir = corpus_dir();
    if !dir.is_dir() {
        println!("corpus: {} not found, skipped", dir.display());
        return;
    }
    let mut failures = Vec::new();
    for program in programs(&dir) {
        let name = program
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default()
            .to_owned();
        let machine = machine_for(&name);
        let (summary, problem) = judge(&program, &run(&program, machine));
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

/// The FANUC-family programs of the corpus, each on a machine that fits it
/// (machine and offsets files in `tests/corpus-setups/`), and how each must
/// end: at its end, or with the alarm a real control raises there too.
struct Conformance {
    program: &'static str,
    machine: &'static str,
    offsets: &'static str,
    /// `None`: runs to its end; `Some((code, line, why))`: stops there.
    stop: Option<(&'static str, usize, &'static str)>,
}

const FANUC_FAMILY: &[Conformance] = &[
    Conformance {
        program: "fanuc_nx_nmv5000_mm.nc",
        machine: "nmv5000.toml",
        offsets: "nmv5000-offsets.toml",
        stop: NMV5000_STOP,
    },
    Conformance {
        program: "haas_nx_vf2tr_5T.nc",
        machine: "haas-vf2tr.toml",
        offsets: "haas-vf2tr-offsets.toml",
        stop: Some((
            "PS0009",
            2,
            "the post left its placeholder `O ENTER OP AND LAST 3 DIGITS` as the program \
             number: the control refuses an O line that is neither a number nor a name",
        )),
    },
];

#[test]
fn fanuc_family_programs_run_to_their_end_or_stop_where_the_control_would() {
    let dir = corpus_dir();
    if !dir.is_dir() {
        println!("corpus: {} not found, skipped", dir.display());
        return;
    }
    let setups = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus-setups");
    let mut failures = Vec::new();
    for case in FANUC_FAMILY {
        let program = dir.join(case.program);
        if !program.is_file() {
            failures.push(format!("{}: not in the corpus", case.program));
            continue;
        }
        let machine = setups.join(case.machine);
        let offsets = setups.join(case.offsets);
        let outcome = run_with(
            &program,
            &[
                "--machine",
                &machine.display().to_string(),
                "--offsets",
                &offsets.display().to_string(),
            ],
        );
        let (summary, _) = judge(&program, &outcome);
        println!("conformance: {}: {summary}", case.program);
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
            Some((want, line, why)) if first_alarm != Some((want.to_owned(), line)) => failures
                .push(format!(
                    "{} should stop with {want} at line {line} ({why}): {summary}",
                    case.program
                )),
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
