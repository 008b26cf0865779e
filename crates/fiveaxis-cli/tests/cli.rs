//! The command line around `run`: where the program comes from, where the
//! rows go, and how unusable inputs are refused (exit status 2, with a
//! message naming the file, the line and what is wrong).

mod common;

use std::path::Path;
use std::process::Output;

use fiveaxis_control::{RunError, RunOptions, Runner, SliceSource};
use fiveaxis_machine::{DEFAULT_MACHINE, Offsets, builtin, builtin_names};

/// A short program that moves and ends.
const PROGRAM: &str = "G0 X10. Y5.\nG1 Z-1. F100.\nM30\n";

/// Runs the binary with `args` in `dir`, feeding `stdin` to it.
fn fiveaxis_in(dir: &Path, args: &[&str], stdin: &str) -> Output {
    common::run_in(dir, args, stdin.as_bytes())
}

use common::scratch;

/// Runs the binary in a scratch directory holding `program.nc` = `PROGRAM`.
fn fiveaxis(args: &[&str]) -> Output {
    let dir = scratch(&[("program.nc", PROGRAM)]);
    fiveaxis_in(dir.path(), args, "")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Checks that `output` is a refusal of unusable input: status 2, no rows,
/// an error message containing every one of `mentions`.
fn assert_input_refused(output: &Output, mentions: &[&str]) {
    let err = stderr(output);
    assert_eq!(output.status.code(), Some(2), "stderr: {err}");
    assert!(
        output.stdout.is_empty(),
        "rows written for unusable input: {}",
        stdout(output)
    );
    for mention in mentions {
        assert!(
            err.contains(mention),
            "stderr does not mention `{mention}`:\n{err}"
        );
    }
}

fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("directory is readable")
        .map(|entry| {
            entry
                .expect("directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

// ----- program and output --------------------------------------------------

#[test]
fn dash_reads_the_program_from_standard_input() {
    let dir = scratch(&[("program.nc", PROGRAM)]);
    let from_file = fiveaxis_in(dir.path(), &["run", "program.nc"], "");
    let from_stdin = fiveaxis_in(dir.path(), &["run", "-"], PROGRAM);
    assert_eq!(from_stdin.status.code(), Some(0), "{}", stderr(&from_stdin));
    assert_eq!(stdout(&from_stdin), stdout(&from_file));
    assert_eq!(
        stdout(&from_stdin).lines().count(),
        3,
        "header and two rows"
    );
}

#[test]
fn subprogram_calls_work_in_a_program_from_standard_input() {
    let program = "M98 P5 L2\nM30\nO5\nG91 G0 X1.\nM99\n";
    let output = fiveaxis_in(Path::new("."), &["run", "-"], program);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert_eq!(
        stdout(&output).lines().count(),
        3,
        "header and two calls' rows:\n{}",
        stdout(&output)
    );
}

#[test]
fn alarms_in_a_program_from_standard_input_name_stdin() {
    let output = fiveaxis_in(Path::new("."), &["run", "-"], "G0 X1.\nG123 Q1\n");
    assert_eq!(output.status.code(), Some(1));
    let err = stderr(&output);
    assert!(err.starts_with("ALARM PS0010 line 2: "), "{err}");
    assert!(err.contains("<stdin>:2"), "{err}");
}

#[test]
fn output_option_writes_the_rows_to_the_file_and_nothing_to_stdout() {
    let dir = scratch(&[("program.nc", PROGRAM)]);
    let to_stdout = fiveaxis_in(dir.path(), &["run", "program.nc"], "");
    let to_file = fiveaxis_in(dir.path(), &["run", "program.nc", "-o", "rows.csv"], "");
    assert_eq!(to_file.status.code(), Some(0), "{}", stderr(&to_file));
    assert!(to_file.stdout.is_empty());
    let written = std::fs::read_to_string(dir.path().join("rows.csv")).expect("output file exists");
    assert_eq!(written, stdout(&to_stdout));
    assert_eq!(
        file_names(dir.path()),
        ["program.nc", "rows.csv"],
        "no temporary file is left behind"
    );
}

#[test]
fn output_file_of_an_alarmed_run_holds_the_rows_before_the_failing_block() {
    let dir = scratch(&[("program.nc", "G0 X1.\nG0 X2.\nG1 X3.\n")]);
    let output = fiveaxis_in(
        dir.path(),
        &["run", "program.nc", "-o", "rows.jsonl", "--format", "jsonl"],
        "",
    );
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let written =
        std::fs::read_to_string(dir.path().join("rows.jsonl")).expect("output file exists");
    let lines: Vec<&str> = written.lines().collect();
    assert_eq!(lines.len(), 3, "two rows and the alarm object:\n{written}");
    assert!(
        lines[2].starts_with(r#"{"alarm":{"code":"PS0011","line":3,"#),
        "{}",
        lines[2]
    );
}

#[test]
fn output_to_a_device_writes_through_it_instead_of_replacing_it() {
    // `-o /dev/stdout` names a device (through a symbolic link): the rows
    // go to it, and it is not renamed over as a regular file would be.
    let before = std::fs::metadata("/dev/stdout")
        .map(|m| m.file_type().is_file())
        .ok();
    let output = fiveaxis(&["run", "program.nc", "-o", "/dev/stdout"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(
        stdout(&output).starts_with("line,s,motion,"),
        "{}",
        stdout(&output)
    );
    let after = std::fs::metadata("/dev/stdout")
        .map(|m| m.file_type().is_file())
        .ok();
    assert_eq!(before, after);
}

#[test]
fn output_into_a_missing_directory_exits_2_and_leaves_no_file() {
    let dir = scratch(&[("program.nc", PROGRAM)]);
    let output = fiveaxis_in(
        dir.path(),
        &["run", "program.nc", "-o", "missing/rows.csv"],
        "",
    );
    assert_input_refused(&output, &["missing/rows.csv"]);
    assert_eq!(file_names(dir.path()), ["program.nc"]);
}

#[test]
fn output_over_a_directory_exits_2_and_leaves_it_as_it_was() {
    let dir = scratch(&[("program.nc", PROGRAM)]);
    std::fs::create_dir(dir.path().join("rows.csv")).expect("directory made");
    let output = fiveaxis_in(dir.path(), &["run", "program.nc", "-o", "rows.csv"], "");
    assert_input_refused(&output, &["rows.csv"]);
    assert!(dir.path().join("rows.csv").is_dir());
    assert_eq!(
        file_names(dir.path()),
        ["program.nc", "rows.csv"],
        "no temporary file is left behind"
    );
}

#[test]
fn a_missing_program_file_exits_2_naming_it() {
    assert_input_refused(
        &fiveaxis(&["run", "no-such-program.nc"]),
        &["no-such-program.nc"],
    );
}

/// The numbers of every row as the kernel computes them, with the rows
/// `--step STEP` adds (default `--step-angle`): s, the machine axes, tip,
/// tool direction and feed (NaN for none).
fn kernel_rows(machine_name: &str, offsets: &str, program: &str, step: f64) -> Vec<Vec<f64>> {
    let machine = builtin(machine_name).expect("built-in machine");
    let offsets = Offsets::from_toml(offsets).expect("offsets file");
    let source = SliceSource::new(program.as_bytes());
    let mut runner = Runner::new(&machine, offsets, source, RunOptions::default());
    let mut rows = Vec::new();
    loop {
        let segment = match runner.next_segment() {
            Ok(Some(segment)) => segment,
            Ok(None) => return rows,
            Err(RunError::Alarm { alarm, .. }) => panic!("the program alarms: {alarm}"),
            Err(e) => panic!("a program in memory failed to read: {e}"),
        };
        let n = segment
            .steps(&machine, step, 1.0)
            .unwrap_or(fiveaxis_control::MAX_STEPS);
        for s in (1..=n).map(|i| f64::from(i) / f64::from(n)) {
            let row = segment.row(&machine, s);
            let mut numbers = vec![row.s];
            numbers.extend(&row.joints[..machine.axis_count()]);
            numbers.extend(row.tip.iter().chain(row.dir.iter()));
            numbers.push(row.feed.unwrap_or(f64::NAN));
            rows.push(numbers);
        }
    }
}

#[test]
fn row_numbers_read_back_as_exactly_the_floats_the_kernel_computed() {
    // A tilted fork head with G43.1, arcs and --step: irrational values,
    // values a few ulps off round ones, and values near zero.
    let program = "G43.1 H1 G0 X10. Y20. Z30.\nA33.3 C-71.7\nG1 X-12.345 Y6.789 F777.7\n\
                   G3 X8. Y-3. R15.\nG2 I-2.5 J4.5\nG91 G1 Z-0.001\nM30\n";
    let offsets = "[tools]\n1 = { length = 123.456 }\n[work]\nG54 = [1.1, -2.2, 3.3]\n";
    let dir = scratch(&[("program.nc", program), ("offsets.toml", offsets)]);
    let args = [
        "run",
        "program.nc",
        "--machine",
        "head-head-ca",
        "--offsets",
        "offsets.toml",
        "--step",
        "2",
    ];
    let output = fiveaxis_in(dir.path(), &args, "");
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let printed: Vec<Vec<f64>> = stdout(&output)
        .lines()
        .skip(1)
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            // line, s, motion, then numbers; an empty feed is none.
            let numbers = std::iter::once(fields[1]).chain(fields[3..].iter().copied());
            numbers
                .map(|f| {
                    if f.is_empty() {
                        f64::NAN
                    } else {
                        f.parse().expect("a number")
                    }
                })
                .collect()
        })
        .collect();
    let expected = kernel_rows("head-head-ca", offsets, program, 2.0);
    assert!(expected.len() > 50, "only {} rows", expected.len());
    assert_eq!(printed.len(), expected.len());
    for (i, (got, want)) in printed.iter().zip(&expected).enumerate() {
        let same = got.len() == want.len()
            && got
                .iter()
                .zip(want)
                .all(|(g, w)| g == w || (g.is_nan() && w.is_nan()));
        assert!(same, "row {i} printed {got:?}, the kernel has {want:?}");
    }
}

// ----- options ---------------------------------------------------------------

#[test]
fn bad_option_values_exit_2() {
    let cases: &[&[&str]] = &[
        &["--step", "0"],
        &["--step", "-1"],
        &["--step", "abc"],
        &["--step", "inf"],
        &["--step", "NaN"],
        &["--step-angle", "0"],
        &["--format", "xml"],
        &["--frobnicate"],
    ];
    for extra in cases {
        let mut args = vec!["run", "program.nc"];
        args.extend_from_slice(extra);
        let output = fiveaxis(&args);
        assert_eq!(
            output.status.code(),
            Some(2),
            "{extra:?} was accepted: {}",
            stderr(&output)
        );
        assert!(output.stdout.is_empty(), "{extra:?} wrote rows");
    }
}

#[test]
fn run_without_a_program_exits_2() {
    assert_eq!(fiveaxis(&["run"]).status.code(), Some(2));
}

// ----- machines and offsets --------------------------------------------------

#[test]
fn an_unknown_machine_name_exits_2_and_lists_the_built_in_machines() {
    let output = fiveaxis(&["run", "program.nc", "--machine", "hexapod"]);
    let mut mentions = vec!["hexapod"];
    mentions.extend(builtin_names());
    assert_input_refused(&output, &mentions);
}

#[test]
fn a_machine_file_with_an_unknown_key_exits_2_naming_the_file_line_and_key() {
    let shown = fiveaxis(&["machines", "show", DEFAULT_MACHINE]);
    let mut text = stdout(&shown);
    let line = text.lines().count() + 1;
    text.push_str("spindle_speed_max = 12000\n");
    let dir = scratch(&[("program.nc", PROGRAM), ("bad-machine.toml", &text)]);
    let output = fiveaxis_in(
        dir.path(),
        &["run", "program.nc", "--machine", "bad-machine.toml"],
        "",
    );
    assert_input_refused(
        &output,
        &[&format!("bad-machine.toml:{line}:"), "spindle_speed_max"],
    );
}

#[test]
fn an_offsets_file_with_an_unknown_key_exits_2_naming_the_file_line_and_key() {
    let offsets =
        "[tools]\n1 = { length = 100.0 }\n\n[work]\nG54 = [0.0, 0.0, 0.0]\nG60 = [1.0, 2.0, 3.0]\n";
    let dir = scratch(&[("program.nc", PROGRAM), ("bad-offsets.toml", offsets)]);
    let output = fiveaxis_in(
        dir.path(),
        &["run", "program.nc", "--offsets", "bad-offsets.toml"],
        "",
    );
    assert_input_refused(&output, &["bad-offsets.toml:6:", "G60"]);
}

#[test]
fn machines_lists_every_built_in_machine_and_marks_the_default() {
    let output = fiveaxis(&["machines"]);
    assert_eq!(output.status.code(), Some(0));
    let listing = stdout(&output);
    for name in builtin_names() {
        assert!(
            listing.lines().any(|l| l.starts_with(name)),
            "{name} missing from:\n{listing}"
        );
    }
    let default = listing
        .lines()
        .find(|l| l.contains("(default)"))
        .expect("a default is marked");
    assert!(default.starts_with(DEFAULT_MACHINE), "{default}");
}

#[test]
fn machines_show_prints_a_file_that_runs_exactly_like_the_built_in_machine() {
    // Inside the travels of every built-in (the Haas machines travel
    // negative from home, in inches).
    let fanuc = "G43 H1 G0 X-10. Y-5. Z-20.\nG1 X-15. F300.\nG91 G28 Z0\nM30\n";
    // The same in the Siemens language: tool 1's length with D1, and the
    // retract in machine coordinates.
    let siemens = "T1 D1 G0 X-10 Y-5 Z-20\nG1 X-15 F300\nG0 G53 Z500 D0\nM30\n";
    // And in Klartext, on a machine whose datum is at the top of Z: the
    // tool called, a cut below the datum, the spindle to machine Z 0.
    let heidenhain = "0 BEGIN PGM P MM\n1 TOOL CALL 1 Z\n2 L X-10 Y-5 Z-300 R0 FMAX\n\
                      3 L X-15 F300\n4 L Z+0 R0 FMAX M91\n5 END PGM P MM\n";
    let offsets = "[tools]\n1 = { length = 100.0 }\n";
    for name in builtin_names() {
        let shown = fiveaxis(&["machines", "show", name]);
        assert_eq!(shown.status.code(), Some(0), "{name}: {}", stderr(&shown));
        let text = stdout(&shown);
        let program = if text.contains("control = \"sinumerik\"") {
            siemens
        } else if text.contains("control = \"heidenhain\"") {
            heidenhain
        } else {
            fanuc
        };
        let dir = scratch(&[
            ("program.nc", program),
            ("offsets.toml", offsets),
            ("machine.toml", &stdout(&shown)),
        ]);
        let run_on = |machine: &str| {
            fiveaxis_in(
                dir.path(),
                &[
                    "run",
                    "program.nc",
                    "--offsets",
                    "offsets.toml",
                    "--machine",
                    machine,
                ],
                "",
            )
        };
        let (by_name, by_file) = (run_on(name), run_on("machine.toml"));
        assert_eq!(
            by_file.status.code(),
            Some(0),
            "{name}: the shown file does not load: {}",
            stderr(&by_file)
        );
        assert_eq!(
            stdout(&by_file),
            stdout(&by_name),
            "{name}: the shown file runs differently"
        );
    }
}

#[test]
fn machines_show_with_an_unknown_name_exits_2() {
    assert_input_refused(&fiveaxis(&["machines", "show", "hexapod"]), &["hexapod"]);
}

#[test]
fn a_mistyped_machine_name_gets_the_nearest_built_in_names() {
    for command in ["run", "check", "view", "post"] {
        let output = fiveaxis(&[command, "program.nc", "--machine", "trunion-ac"]);
        assert_input_refused(&output, &["`trunion-ac`", "did you mean `trunnion-ac`?"]);
    }
    // Two at the same distance: both; none near: no guess.
    let output = fiveaxis(&["run", "program.nc", "--machine", "trunnion-xc"]);
    assert_input_refused(&output, &["did you mean `trunnion-ac` or `trunnion-bc`?"]);
    let output = fiveaxis(&["run", "program.nc", "--machine", "hexapod"]);
    assert!(
        !stderr(&output).contains("did you mean"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn machines_show_takes_names_only_and_says_so() {
    let output = fiveaxis(&["machines", "show", "haas-umc-750"]);
    let mut mentions =
        vec!["`haas-umc-750` is not a built-in machine name; did you mean `haas-umc750`?"];
    mentions.extend(builtin_names());
    assert_input_refused(&output, &mentions);
    assert!(
        !stderr(&output).contains("machine file"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn machines_import_reads_a_sinumerik_swivel_data_record_and_points_at_its_errors() {
    let record = fiveaxis_machine::SINUMERIK_BUILTIN_TC_CARR;
    let bad = "$TC_CARR7[1]=1\n$TC_CARR23[1]=\"X\"\n";
    let dir = scratch(&[("dmu.spf", record), ("bad.spf", bad)]);
    let imported = fiveaxis_in(dir.path(), &["machines", "import", "dmu.spf"], "");
    assert_eq!(imported.status.code(), Some(0), "{}", stderr(&imported));
    let text = stdout(&imported);
    let machine = fiveaxis_machine::Machine::from_toml(&text).expect("a machine file");
    assert_eq!(machine.control, fiveaxis_machine::Control::Sinumerik);
    assert!(text.contains("# kinematic type M"), "{text}");
    // The linear axes of another machine.
    let on_base = fiveaxis_in(
        dir.path(),
        &[
            "machines",
            "import",
            "dmu.spf",
            "--machine",
            "haas-umc750",
            "--record",
            "DMU_BC",
        ],
        "",
    );
    assert_eq!(on_base.status.code(), Some(0), "{}", stderr(&on_base));
    assert!(
        stdout(&on_base).contains("min = -762.0"),
        "{}",
        stdout(&on_base)
    );
    let refused = fiveaxis_in(dir.path(), &["machines", "import", "bad.spf"], "");
    assert_input_refused(&refused, &["bad.spf:2:15:", "14153"]);
    let refused = fiveaxis_in(
        dir.path(),
        &["machines", "import", "dmu.spf", "--record", "NOPE"],
        "",
    );
    assert_input_refused(&refused, &["dmu.spf", "`NOPE`", "DMU_BC"]);
}

// ----- alarm diagnostics -------------------------------------------------------

/// Checks that an alarmed run renders `text`, the failing line, under the
/// gutter of line `line`.
fn assert_alarm_renders(program: &str, code: &str, line: usize, text: &str) {
    let output = fiveaxis_in(Path::new("."), &["run", "-"], program);
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!("ALARM {code} line {line}: ")),
        "{err}"
    );
    let gutter = format!("{line} | {text}");
    assert!(
        err.lines().any(|l| l.trim_start() == gutter),
        "`{gutter}` is not rendered:\n{err}"
    );
}

#[test]
fn alarm_renders_the_failing_line_under_its_number() {
    assert_alarm_renders("G0 X1.\nG1 X2.\n", "PS0011", 2, "G1 X2.");
}

#[test]
fn an_alarm_is_said_once_then_located_with_a_caret() {
    let output = fiveaxis_in(Path::new("."), &["run", "-"], "G0 X1.\nG1 X600. F100.\n");
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(
        lines[0],
        "ALARM OT0500 line 2: X+ over-travel: X would reach 600 beyond the soft limit 500",
        "{err}"
    );
    assert_eq!(lines[1], " --> <stdin>:2:4", "{err}");
    assert_eq!(err.matches("over-travel").count(), 1, "{err}");
    assert!(!err.contains("error:"), "{err}");
    let source = lines
        .iter()
        .position(|l| l.trim_start() == "2 | G1 X600. F100.")
        .unwrap_or_else(|| panic!("no source line in\n{err}"));
    assert_eq!(lines[source + 1].trim_end(), "  |    ^^^^^ here", "{err}");
}

#[test]
fn a_letter_o_for_a_zero_is_pointed_out() {
    let output = fiveaxis_in(Path::new("."), &["run", "-"], "G0 X1.\nG1O X10.\n");
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(
            "ALARM PS0009 line 2: unknown word `OX10`: `O` after `G1` is the letter O; did you mean the digit 0 (`G10`)?\n"
        ),
        "{err}"
    );
}

// ----- --digits ----------------------------------------------------------------

#[test]
fn digits_rounds_every_number_and_the_default_stays_exact() {
    // A quarter turn of A on the A/C trunnion: the tool direction has
    // -0.49999999999999994 in it, and its k is exactly 0 (the quarter turn
    // is exact in degrees).
    let program = "G0 X10. Y-25. Z30.\nG1 A-90. C30. F1000.\nM30\n";
    let exact = fiveaxis_in(Path::new("."), &["run", "-"], program);
    assert_eq!(exact.status.code(), Some(0), "{}", stderr(&exact));
    assert!(
        stdout(&exact).contains(",-0.49999999999999994,0.8660254037844387,0,1000"),
        "{}",
        stdout(&exact)
    );
    for format in ["csv", "jsonl"] {
        let output = fiveaxis_in(
            Path::new("."),
            &["run", "-", "--digits", "3", "--format", format],
            program,
        );
        assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
        let text = stdout(&output);
        for number in text
            .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
            .filter(|t| t.contains(|c: char| c.is_ascii_digit()))
        {
            let decimals = number.split_once('.').map_or(0, |(_, f)| f.len());
            assert!(decimals <= 3, "{number} in\n{text}");
            assert!(!number.ends_with('0') || !number.contains('.'), "{number}");
            assert_ne!(number, "-0", "{text}");
        }
        // Each rounded number is the exact one rounded.
        if format == "csv" {
            let exact_rows: Vec<Vec<f64>> = numbers(&stdout(&exact));
            let rounded_rows: Vec<Vec<f64>> = numbers(&text);
            assert_eq!(exact_rows.len(), rounded_rows.len());
            for (e, r) in exact_rows.iter().zip(&rounded_rows) {
                for (a, b) in e.iter().zip(r) {
                    assert!((a - b).abs() <= 0.0005 + 1e-12, "{a} vs {b}");
                }
            }
            assert!(
                text.contains(
                    "\n2,1,linear,10,-25,30,-90,30,-56.34,117.583,-75,-0.5,0.866,0,1000\n"
                ),
                "{text}"
            );
        }
    }
    let output = fiveaxis_in(Path::new("."), &["run", "-", "--digits", "16"], program);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
}

/// The numeric cells of CSV rows (the motion column left out).
fn numbers(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').filter_map(|c| c.parse().ok()).collect())
        .collect()
}

#[test]
fn alarm_for_a_missing_subprogram_renders_the_calling_line() {
    // The runner searches the rest of the file for O4242 and then renders
    // the last line it read there instead of the M98 block.
    assert_alarm_renders("G0 X5.\nM98 P4242\nG0 X0\nM30\n", "PS0078", 2, "M98 P4242");
}

#[test]
fn alarm_for_a_missing_return_sequence_renders_the_m99_line() {
    // Same for M99 P55: the search for N55 leaves another line behind.
    assert_alarm_renders("M98 P7\nM30\nO7\nM99 P55\n", "PS0078", 4, "M99 P55");
}
