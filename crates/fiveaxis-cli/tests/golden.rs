//! Golden tests of `fiveaxis run`: every `tests/fixtures/*.nc` program is
//! run through the real binary and the whole exchange (command line, exit
//! status, standard output, standard error) is compared with its snapshot
//! in `tests/snapshots/`.
//!
//! A fixture says how it is run in comments on its first lines:
//!
//! ```text
//! (args: --machine head-head-ca --step 2 --format jsonl)
//! (offsets: offsets.toml)
//! ```
//!
//! `args` are added to the command line as written (split at blanks);
//! `offsets` names an offsets file next to the fixture. Comments in
//! fixtures hold no `;`: it ends the block, comment or not.
//!
//! Numbers with a fraction in standard output are rounded to 1e-9 in the
//! snapshot, so that a change in the last bits of the kinematics does not
//! churn every snapshot; `cli.rs` checks that the full numbers read back
//! exactly. The binary runs in
//! the fixtures directory with the program named by its file name, so that
//! paths in diagnostics are the same on every machine.

use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Output};

/// How a fixture asks to be run: the options after the program name.
fn options_of(program: &str) -> Vec<String> {
    let mut options = Vec::new();
    for line in program.lines().map(str::trim) {
        if line == "%" || line.is_empty() {
            continue;
        }
        let Some(comment) = line.strip_prefix('(').and_then(|c| c.strip_suffix(')')) else {
            break;
        };
        let Some((key, value)) = comment.split_once(':') else {
            continue;
        };
        match key.trim() {
            "args" => options.extend(value.split_whitespace().map(String::from)),
            "offsets" => options.extend(["--offsets".to_owned(), value.trim().to_owned()]),
            _ => {}
        }
    }
    options
}

/// The exit status as the snapshot shows it: a number, or the signal that
/// ended the process.
fn status_of(output: &Output) -> String {
    match output.status.code() {
        Some(code) => code.to_string(),
        None => format!("killed ({})", output.status),
    }
}

/// Decimal places kept in the snapshot.
const DECIMALS: i32 = 9;

/// `text` with every number that has a fraction or an exponent rounded to
/// [`DECIMALS`] places. A number is a run of digits (with sign, point and
/// exponent) that does not continue a word: `G5.1` and `tip_x` stay.
fn rounded(text: &str) -> String {
    let scale = 10f64.powi(DECIMALS);
    let bytes = text.as_bytes();
    let continues_word =
        |i: usize| i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || b"_.".contains(&bytes[i - 1]));
    let starts_number = |i: usize| {
        let digit_at = |j: usize| bytes.get(j).is_some_and(u8::is_ascii_digit);
        (digit_at(i) || (bytes[i] == b'-' && digit_at(i + 1))) && !continues_word(i)
    };
    let mut out = String::with_capacity(text.len());
    let (mut copied, mut i) = (0, 0);
    while i < bytes.len() {
        if !starts_number(i) {
            i += 1;
            continue;
        }
        let len = bytes[i + 1..]
            .iter()
            .take_while(|b| b.is_ascii_digit() || b"+-.eE".contains(b))
            .count();
        let token = &text[i..=i + len];
        if let (true, Ok(x)) = (token.contains(['.', 'e', 'E']), token.parse::<f64>()) {
            out.push_str(&text[copied..i]);
            out.push_str(&format!("{}", (x * scale).round() / scale + 0.0));
            copied = i + len + 1;
        }
        i += len + 1;
    }
    out.push_str(&text[copied..]);
    out
}

/// Runs one fixture and renders everything it did as the snapshot text.
fn transcript(fixture: &Path) -> String {
    let program = std::fs::read_to_string(fixture).expect("fixture is readable text");
    let dir = fixture.parent().expect("fixture has a directory");
    let name = fixture
        .file_name()
        .and_then(|n| n.to_str())
        .expect("fixture name is UTF-8");
    let mut args = vec!["run".to_owned(), name.to_owned()];
    args.extend(options_of(&program));

    let output = Command::new(env!("CARGO_BIN_EXE_fiveaxis"))
        .args(&args)
        .current_dir(dir)
        .output()
        .expect("the fiveaxis binary starts");

    let mut text = String::new();
    let _ = writeln!(text, "$ fiveaxis {}", args.join(" "));
    let _ = writeln!(text, "exit status: {}", status_of(&output));
    let _ = writeln!(
        text,
        "--- stdout (numbers rounded to 1e-{DECIMALS}) ---\n{}",
        rounded(&String::from_utf8_lossy(&output.stdout))
    );
    let _ = write!(
        text,
        "--- stderr ---\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    text
}

#[test]
fn every_fixture_runs_as_its_snapshot_records() {
    insta::glob!("fixtures/*.nc", |path| {
        insta::assert_snapshot!("run", transcript(path));
    });
}

#[test]
fn snapshots_round_numbers_with_a_fraction_and_leave_words_alone() {
    let row = "6,0.14285714285714285,cw,-124.99999999999997,0.000000000000014210854715202004,G5.1,tip_x,1e-20,12,-0.5";
    assert_eq!(rounded(row), "6,0.142857143,cw,-125,0,G5.1,tip_x,0,12,-0.5");
    let json =
        r#"{"line":7,"s":0.5,"X":-99.60000000000001,"message":"X would reach -501.819660112501"}"#;
    assert_eq!(
        rounded(json),
        r#"{"line":7,"s":0.5,"X":-99.6,"message":"X would reach -501.819660113"}"#
    );
}
