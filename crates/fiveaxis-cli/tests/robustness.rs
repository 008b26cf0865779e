//! The command line on hostile input (issue: robustness before breadth):
//! bytes that are not text, full and closed output streams, endless
//! inputs, endless programs, interrupted runs and the `-o` file's
//! permissions and links. Each test is a class, with the reproducer that
//! found it.

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Output, Stdio};

mod common;

use common::{binary, run_in, stderr};

fn run(args: &[&str], stdin: &[u8]) -> Output {
    let dir = tempfile::tempdir().expect("a temporary directory");
    run_in(dir.path(), args, stdin)
}

/// A program with bytes that are not UTF-8 alarms with the byte shown
/// escaped and the caret under it, never a panic.
#[test]
fn invalid_utf8_in_a_program_alarms_with_the_byte_escaped() {
    for (program, shown, caret_under) in [
        (&b"\xff\n"[..], "\\xff", "\\xff"),
        (&b"(\xe9\xe9) Q\n"[..], "(\\xe9\\xe9) Q", "Q"),
        (&b"G1 X1. \xc3\x28\n"[..], "\\xc3(", "\\xc3"),
        (&b"G0 X1.\x1b\n"[..], "G0 X1.\\x1b", "\\x1b"),
        (&b"G0 \xef\xbb\xbfX1.\n"[..], "G0 \\u{feff}X1.", "\\u{feff}"),
    ] {
        let out = run(&["run", "-"], program);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            !err.contains('\u{1b}'),
            "control characters printed raw: {err:?}"
        );
        let lines: Vec<&str> = err.lines().collect();
        let source = lines
            .iter()
            .position(|l| l.contains(shown))
            .unwrap_or_else(|| panic!("the line is not shown as `{shown}`: {err}"));
        let column = lines[source].find(caret_under).expect("marked text shown");
        assert_eq!(
            lines[source + 1].find('^'),
            Some(column),
            "caret not under `{caret_under}`:\n{err}"
        );
    }
}

/// Output that cannot be written ends with a message and exit status 2.
#[test]
fn a_full_output_device_exits_2_with_a_message() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full")
    };
    let show = binary()
        .args(["machines", "show", "trunnion-ac"])
        .stdout(full())
        .stderr(Stdio::piped())
        .output()
        .expect("runs");
    assert_eq!(show.status.code(), Some(2), "{}", stderr(&show));
    assert!(
        stderr(&show).contains("standard output"),
        "{}",
        stderr(&show)
    );
    let mut child = binary()
        .args(["run", "-"])
        .stdin(Stdio::piped())
        .stdout(full())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    let _ = child
        .stdin
        .take()
        .expect("stdin")
        .write_all(b"G0 X1.\nM30\n");
    let out = child.wait_with_output().expect("ends");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"));
}

/// An alarm with standard error on a full device or closed still exits 1.
#[test]
fn an_alarm_with_standard_error_full_or_closed_exits_1() {
    let mut sinks = vec![Stdio::null()];
    if let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") {
        sinks.push(Stdio::from(full));
    }
    for sink in sinks {
        let mut child = binary()
            .args(["run", "-"])
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(sink)
            .spawn()
            .expect("runs");
        let _ = child.stdin.take().expect("stdin").write_all(b"G1 X1. F0\n");
        let status = child.wait().expect("ends");
        assert_eq!(status.code(), Some(1));
    }
}

/// Endless or huge inputs are refused early with a message naming the
/// limit, not read until memory or disk run out.
#[test]
fn endless_inputs_are_refused_naming_the_limit() {
    if !Path::new("/dev/zero").exists() {
        return;
    }
    let started = std::time::Instant::now();
    let as_file = run(&["run", "/dev/zero"], b"");
    assert_eq!(as_file.status.code(), Some(2));
    assert!(
        stderr(&as_file).contains("longer than 65536 bytes"),
        "{}",
        stderr(&as_file)
    );
    let zero = std::fs::File::open("/dev/zero").expect("/dev/zero");
    let piped = binary()
        .args(["run", "-"])
        .stdin(zero)
        .output()
        .expect("runs");
    assert_eq!(piped.status.code(), Some(2));
    assert!(
        stderr(&piped).contains("standard input: line 1 is longer"),
        "{}",
        stderr(&piped)
    );
    let machine = run(&["run", "-", "--machine", "/dev/zero"], b"G0 X1.\n");
    assert_eq!(machine.status.code(), Some(2));
    assert!(
        stderr(&machine).contains("larger than 1048576 bytes"),
        "{}",
        stderr(&machine)
    );
    let offsets = run(&["run", "-", "--offsets", "/dev/zero"], b"G0 X1.\n");
    assert_eq!(offsets.status.code(), Some(2));
    assert!(
        started.elapsed().as_secs() < 30,
        "refusing took {:?}",
        started.elapsed()
    );
}

/// A program that never ends is stopped by the block budget, with the
/// lines it was repeating.
#[test]
fn endless_programs_stop_at_the_block_budget() {
    for program in [
        &b"O1\nN5 G0 X1.\nG0 X2.\nM99 P5\n"[..],
        &b"O1\nM98 P2 L9999\nM30\nO2\nM98 P3 L9999\nM99\nO3\nG0 X1.\nG0 X0\nM99\n"[..],
    ] {
        let out = run(&["run", "-", "--max-blocks", "20000"], program);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("ALARM FX0102"), "{err}");
        assert!(err.contains("repeating lines"), "{err}");
    }
    let out = run(&["run", "-", "--max-blocks", "0"], b"G0 X1.\n");
    assert_eq!(out.status.code(), Some(2), "a zero budget is not a budget");
}

#[cfg(unix)]
mod output_file {
    use std::os::unix::fs::{PermissionsExt, symlink};

    use super::*;

    const PROGRAM: &[u8] = b"G0 X10.\nG1 X20. F100.\nM30\n";

    fn mode(path: &Path) -> u32 {
        std::fs::metadata(path)
            .expect("exists")
            .permissions()
            .mode()
            & 0o777
    }

    #[test]
    fn a_new_file_gets_the_usual_permissions_and_a_replaced_one_keeps_its_mode() {
        let dir = tempfile::tempdir().expect("dir");
        let out = run_in(dir.path(), &["run", "-", "-o", "rows.csv"], PROGRAM);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let path = dir.path().join("rows.csv");
        // 0666 less the umask: readable by others unless the umask says no.
        assert_ne!(mode(&path), 0o600, "the temporary file's 0600 leaked");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).expect("chmod");
        let out = run_in(dir.path(), &["run", "-", "-o", "rows.csv"], PROGRAM);
        assert_eq!(out.status.code(), Some(0));
        assert_eq!(mode(&path), 0o640);
    }

    #[test]
    fn output_onto_a_symbolic_link_writes_its_target_and_keeps_the_link() {
        let dir = tempfile::tempdir().expect("dir");
        std::fs::create_dir(dir.path().join("real")).expect("mkdir");
        std::fs::write(dir.path().join("real/rows.csv"), "old").expect("write");
        symlink("real/rows.csv", dir.path().join("link.csv")).expect("symlink");
        let out = run_in(dir.path(), &["run", "-", "-o", "link.csv"], PROGRAM);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let link = std::fs::symlink_metadata(dir.path().join("link.csv")).expect("link");
        assert!(
            link.file_type().is_symlink(),
            "the link was replaced by a file"
        );
        let target = std::fs::read_to_string(dir.path().join("real/rows.csv")).expect("target");
        assert!(target.starts_with("line,s,motion"), "{target}");
        // A dangling link is refused, and nothing is created.
        symlink("missing/rows.csv", dir.path().join("dangling.csv")).expect("symlink");
        let out = run_in(dir.path(), &["run", "-", "-o", "dangling.csv"], PROGRAM);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains("symbolic link"), "{}", stderr(&out));
    }

    #[test]
    fn an_interrupted_run_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().expect("dir");
        // An endless program that writes rows all the time.
        let program = dir.path().join("loop.nc");
        std::fs::write(&program, "O1\nN5 G0 X1.\nG0 X2.\nM99 P5\n").expect("program");
        for signal in ["TERM", "INT", "HUP"] {
            let mut child = binary()
                .args([
                    "run",
                    "loop.nc",
                    "-o",
                    "rows.csv",
                    "--max-blocks",
                    "4000000000",
                ])
                .current_dir(dir.path())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("runs");
            // Wait until the temporary file is there.
            let started = std::time::Instant::now();
            while std::fs::read_dir(dir.path()).expect("dir").count() < 2
                && started.elapsed().as_secs() < 20
            {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            std::thread::sleep(std::time::Duration::from_millis(200));
            let killed = Command::new("kill")
                .args([&format!("-{signal}"), &child.id().to_string()])
                .status()
                .expect("kill runs");
            assert!(killed.success());
            let status = child.wait().expect("ends");
            assert!(!status.success());
            let names: Vec<String> = std::fs::read_dir(dir.path())
                .expect("dir")
                .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .collect();
            assert_eq!(names, vec!["loop.nc".to_owned()], "after SIG{signal}");
        }
    }
}

/// A machine or offsets file that is not UTF-8 is refused naming the line
/// and column of the first bad byte.
#[test]
fn a_data_file_that_is_not_utf8_names_its_line() {
    let dir = tempfile::tempdir().expect("dir");
    std::fs::write(
        dir.path().join("m.toml"),
        b"# a machine\nname = \"caf\xe9\"\n".as_slice(),
    )
    .expect("write");
    std::fs::write(
        dir.path().join("o.toml"),
        b"[tools]\n\n1 = { length = 1\xff }\n".as_slice(),
    )
    .expect("write");
    let out = run_in(
        dir.path(),
        &["run", "-", "--machine", "m.toml"],
        b"G0 X1.\n",
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("m.toml:2:12: not UTF-8 text"),
        "{}",
        stderr(&out)
    );
    let out = run_in(
        dir.path(),
        &["run", "-", "--offsets", "o.toml"],
        b"G0 X1.\n",
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("o.toml:3:17: not UTF-8 text"),
        "{}",
        stderr(&out)
    );
}

/// Numbers beyond what a machine can have are refused when the file is
/// read, naming the key: they used to hang TCPC (a stroke of 1e18 degrees)
/// or give rows of NaN (offsets of 1e308).
#[test]
fn huge_file_values_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().expect("dir");
    let machine = binary()
        .args(["machines", "show", "trunnion-ac"])
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&machine.stdout).replacen("min = -120.0", "min = -1e18", 1);
    std::fs::write(dir.path().join("m.toml"), text).expect("write");
    std::fs::write(
        dir.path().join("o.toml"),
        "[work]\nG54 = [1.7e308, 0.0, 0.0]\n",
    )
    .expect("write");
    let out = run_in(
        dir.path(),
        &["run", "-", "--machine", "m.toml"],
        b"G0 X1.\n",
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("(key `min`)"), "{}", stderr(&out));
    let out = run_in(
        dir.path(),
        &["run", "-", "--offsets", "o.toml"],
        b"G0 Y1.\n",
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("(key `G54`)"), "{}", stderr(&out));
}

/// `--variables` sets #500-#999 and the interface signals at start;
/// `--save-variables` writes #500-#999 back (whole), keeping the signals.
#[test]
fn macro_variables_file_is_read_and_written_back() {
    let dir = tempfile::tempdir().expect("dir");
    std::fs::write(dir.path().join("vars.toml"), "500 = 2\n\"#1000\" = 1\n").expect("write");
    let program = b"IF [#1000 EQ 1] THEN #500=#500+1\nG0 X#500\n";
    for want in [3.0, 4.0] {
        let out = run_in(
            dir.path(),
            &["run", "-", "--variables", "vars.toml", "--save-variables"],
            program,
        );
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let rows = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            rows.lines()
                .nth(1)
                .is_some_and(|l| l.starts_with(&format!("2,1,rapid,{want},"))),
            "{rows}"
        );
    }
    let saved = std::fs::read_to_string(dir.path().join("vars.toml")).expect("read");
    assert!(
        saved.contains("500 = 4.0") && saved.contains("\"#1000\" = 1"),
        "{saved}"
    );
    // A number that is not a kept variable is refused, naming it.
    std::fs::write(dir.path().join("bad.toml"), "100 = 1\n").expect("write");
    let out = run_in(
        dir.path(),
        &["run", "-", "--variables", "bad.toml"],
        program,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("#100 cannot be set"),
        "{}",
        stderr(&out)
    );
}

/// A message shows numbers as people read them: `--step 1e-300` is
/// written `1e-300`, not as a 302-character decimal.
#[test]
fn messages_write_extreme_numbers_in_scientific_notation() {
    let out = run(&["run", "-", "--step", "1e-300"], b"G0 X1.\n");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("FX0101"), "{err}");
    assert!(err.contains("at most 1e-300 mm and 1 degrees"), "{err}");
    assert!(!err.contains("0000000000"), "{err}");
}

/// RS274/NGC lines of 30,000 signs, `#` or operations (30 to 60 KB,
/// under the line limit) end in the format alarm at their line; they
/// overflowed the stack (exit 134).
#[test]
fn deep_ngc_expressions_alarm_instead_of_overflowing_the_stack() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let machine = fiveaxis_machine::builtin_source("mill-3axis")
        .expect("built-in machine")
        .lines()
        .map(|line| {
            if line.trim_start().starts_with("control") {
                "control = \"linuxcnc\"\n".to_owned()
            } else {
                format!("{line}\n")
            }
        })
        .collect::<String>();
    std::fs::write(dir.path().join("lcnc.toml"), machine).expect("machine file");
    const HOSTILE: usize = 30_000;
    let chain = format!("[{}1]", "1+".repeat(HOSTILE));
    for value in ["-".repeat(HOSTILE) + "1", "#".repeat(HOSTILE) + "1", chain] {
        let program = format!("G0 X1\n#1 = {value}\nM2\n");
        let out = run_in(
            dir.path(),
            &["run", "--machine", "lcnc.toml", "-"],
            program.as_bytes(),
        );
        let err = stderr(&out);
        let head: String = err.chars().take(400).collect();
        assert_eq!(out.status.code(), Some(1), "{head}");
        assert!(err.contains("ALARM FX0112 line 2"), "{head}");
    }
}

/// FANUC 30i-B's additional common variables (issue 24, item 3): a
/// machine file with the option (`additional_common_variables`) has the
/// shop's `#900000`…; `--variables` sets them and `--save-variables`
/// writes them back. Without the option they are refused, naming it.
#[test]
fn additional_common_variables_are_read_and_written_back() {
    let dir = tempfile::tempdir().expect("dir");
    let machine = run_in(dir.path(), &["machines", "show", "trunnion-ac"], b"");
    let mut text = String::from_utf8_lossy(&machine.stdout).into_owned();
    text = text.replace(
        "[parameters]",
        "[parameters]\nadditional_common_variables = 500000",
    );
    std::fs::write(dir.path().join("m.toml"), text).expect("write");
    std::fs::write(dir.path().join("vars.toml"), "900000 = 2\n").expect("write");
    let program = b"#900001=#900000+1\n#100000=5\nG0 X#900001 Y#100000\nM30\n";
    let args = [
        "run",
        "-",
        "--machine",
        "m.toml",
        "--variables",
        "vars.toml",
        "--save-variables",
    ];
    let out = run_in(dir.path(), &args, program);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let rows = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        rows.lines()
            .nth(1)
            .is_some_and(|l| l.starts_with("3,1,rapid,3,5,")),
        "{rows}"
    );
    let saved = std::fs::read_to_string(dir.path().join("vars.toml")).expect("read");
    assert!(
        saved.contains("900000 = 2.0") && saved.contains("900001 = 3.0"),
        "{saved}"
    );
    // #100000… are cleared at reset: not saved.
    assert!(!saved.contains("100000 ="), "{saved}");
    // The default machine has no such option.
    let out = run_in(
        dir.path(),
        &["run", "-", "--variables", "vars.toml"],
        program,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("additional_common_variables"),
        "{}",
        stderr(&out)
    );
}
