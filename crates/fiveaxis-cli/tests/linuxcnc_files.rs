//! LinuxCNC's files around a run (`control = "linuxcnc"`): subroutine
//! files found through the machine file's `subroutine_path` and the
//! program's folder, and tool tables (`.tbl`) given with `--offsets` or
//! named by the machine file's `tool_table`.

mod common;

use std::path::Path;

use fiveaxis_machine::builtin_source;

/// The built-in three-axis mill as a LinuxCNC machine file, with
/// `extra` lines added to its `[parameters]`.
fn machine_file(extra: &str) -> String {
    let text = builtin_source("mill-3axis").expect("built-in machine");
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("control") {
            out.push_str("control = \"linuxcnc\"\n");
        } else {
            out.push_str(line);
            out.push('\n');
            if line.trim() == "[parameters]" {
                out.push_str(extra);
            }
        }
    }
    if !out.contains("[parameters]") {
        out.push_str("[parameters]\n");
        out.push_str(extra);
    }
    out
}

fn write(dir: &Path, name: &str, text: &str) {
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).expect("folder");
    }
    std::fs::write(path, text).expect("file written");
}

/// The machine X, Y, Z of each row.
fn xyz(stdout: &[u8]) -> Vec<[f64; 3]> {
    String::from_utf8_lossy(stdout)
        .lines()
        .skip(1)
        .map(|row| {
            let v: Vec<f64> = row
                .split(',')
                .skip(3)
                .take(3)
                .map(|x| x.parse().expect("number"))
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn subroutines_and_tool_table_named_by_the_machine_file() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let d = dir.path();
    write(
        d,
        "machine/mill.toml",
        &machine_file("subroutine_path = [\"subs\"]\ntool_table = \"tools.tbl\"\n"),
    );
    write(
        d,
        "machine/tools.tbl",
        "T1 P1 Z10 D6 ;end mill\nT2 P2 Z20.5 D10\n",
    );
    write(
        d,
        "machine/subs/peck.ngc",
        "o<peck> sub\n  G1 Z[-#1] F100\n  G0 Z5\no<peck> endsub\nM2\n",
    );
    write(d, "prog/here.ngc", "o<here> sub\nG0 X#1\no<here> endsub\n");
    write(
        d,
        "prog/main.ngc",
        "G90 G21\nT2 M6 G43\nG0 X0 Y0 Z50\no<peck> call [3]\no<here> call [7]\nM2\n",
    );
    let out = common::run_in(
        d,
        &["run", "--machine", "machine/mill.toml", "prog/main.ngc"],
        b"",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Tool 2's length 20.5 from the table; peck.ngc from the subroutine
    // path, here.ngc from the program's folder.
    assert_eq!(
        xyz(&out.stdout),
        vec![
            [0.0, 0.0, 70.5],
            [0.0, 0.0, 17.5],
            [0.0, 0.0, 25.5],
            [7.0, 0.0, 25.5]
        ]
    );
}

#[test]
fn offsets_option_reads_a_tool_table_and_reports_its_errors() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let d = dir.path();
    write(d, "mill.toml", &machine_file(""));
    write(d, "t.tbl", "T1 P1 Z10 D6\n");
    write(d, "bad.tbl", "T1 P1\nT2 P2 K3\n");
    write(d, "p.ngc", "T1 M6 G43\nG0 Z5\nM2\n");
    let out = common::run_in(
        d,
        &[
            "run",
            "--machine",
            "mill.toml",
            "--offsets",
            "t.tbl",
            "p.ngc",
        ],
        b"",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(xyz(&out.stdout), vec![[0.0, 0.0, 15.0]]);
    let out = common::run_in(
        d,
        &[
            "run",
            "--machine",
            "mill.toml",
            "--offsets",
            "bad.tbl",
            "p.ngc",
        ],
        b"",
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.tbl") && err.contains('2') && err.contains("K3"),
        "{err}"
    );
}

#[test]
fn a_missing_subroutine_file_names_the_file() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let d = dir.path();
    write(d, "mill.toml", &machine_file(""));
    write(d, "p.ngc", "o<nothere> call\nM2\n");
    let out = common::run_in(d, &["run", "--machine", "mill.toml", "p.ngc"], b"");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("FX0125") && err.contains("nothere.ngc"),
        "{err}"
    );
}

/// A program reaches the program memory it was given and nothing else:
/// a subroutine name with a path in it (`..`, a folder, an absolute
/// path) is refused with the alarm naming the word, even where the file
/// it names exists.
#[test]
fn subroutine_names_cannot_leave_the_subroutine_path() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let d = dir.path();
    write(
        d,
        "machine/mill.toml",
        &machine_file("subroutine_path = [\"subs\"]\n"),
    );
    let evil = "o<evil> sub\nG0 X99\no<evil> endsub\n";
    write(d, "outside/evil.ngc", evil);
    write(d, "machine/subs/inner/evil.ngc", evil);
    let absolute = d.join("outside/evil");
    let absolute = absolute.to_str().expect("a UTF-8 path");
    for name in [
        "../outside/evil",
        "inner/evil",
        absolute,
        "..\\outside\\evil",
    ] {
        write(d, "prog/main.ngc", &format!("G0 X1\no<{name}> call\nM2\n"));
        let out = common::run_in(
            d,
            &["run", "--machine", "machine/mill.toml", "prog/main.ngc"],
            b"",
        );
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains("FX0125"), "{name}: {err}");
        assert!(err.contains("line 2"), "{name}: {err}");
        assert!(
            err.contains(&format!("o<{}> call", name.to_lowercase())),
            "{name}: {err}"
        );
        assert!(
            !String::from_utf8_lossy(&out.stdout).contains("99"),
            "{name}"
        );
    }
}
