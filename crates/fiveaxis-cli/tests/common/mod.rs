//! Running the `fiveaxis` binary for the command-line tests.

#![allow(dead_code)]

pub mod corpus;

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Output, Stdio};

/// A scratch directory holding `files` (name, contents).
pub fn scratch(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).expect("scratch file written");
    }
    dir
}

/// The binary under test.
pub fn binary() -> Command {
    Command::new(env!("CARGO_BIN_EXE_fiveaxis"))
}

/// Runs the binary with `args` in `dir`, feeding `stdin` to it.
pub fn run_in(dir: &Path, args: &[&str], stdin: &[u8]) -> Output {
    let mut child = binary()
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the fiveaxis binary starts");
    // Small inputs fit the pipe; a run that does not read its standard
    // input (a program file) may close it first, which is not a failure.
    let mut input = child.stdin.take().expect("piped stdin");
    let _ = input.write_all(stdin);
    drop(input);
    child.wait_with_output().expect("fiveaxis runs to its end")
}

/// Standard error as text.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Standard output as text.
pub fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The repository root.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .and_then(Path::parent)
        .expect("crates/fiveaxis-cli sits two levels down")
}

/// Standard base64 read back.
fn from_base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => u32::from(c - b'A'),
        b'a'..=b'z' => u32::from(c - b'a') + 26,
        b'0'..=b'9' => u32::from(c - b'0') + 52,
        b'+' => 62,
        _ => 63,
    };
    let mut out = Vec::new();
    for quad in text.as_bytes().chunks(4) {
        let pad = quad.iter().filter(|c| **c == b'=').count();
        let v = quad
            .iter()
            .fold(0, |v, c| (v << 6) | if *c == b'=' { 0 } else { value(*c) });
        out.extend(&v.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// The bytes of a packed element of a `fiveaxis view` page, read as the
/// viewer reads them (`viewer/src/data.js`): base64, inflated (zlib) when
/// `data-encoding` says `deflate`, the bytes regrouped from byte position order into elements of `data-width`.
pub fn page_element(page: &str, id: &str) -> Vec<u8> {
    let start = page
        .find(&format!("id=\"{id}\""))
        .unwrap_or_else(|| panic!("no element {id} in the page"));
    let rest = &page[start..];
    let width: usize = rest
        .split("data-width=\"")
        .nth(1)
        .and_then(|w| w.split('"').next())
        .and_then(|w| w.parse().ok())
        .expect("data-width");
    let deflated = rest
        .split('>')
        .next()
        .expect("tag")
        .contains("data-encoding=\"deflate\"");
    let text = &rest[rest.find('>').expect("tag end") + 1..rest.find("</script>").expect("end")];
    let mut bytes = from_base64(text);
    if deflated {
        let packed = std::mem::take(&mut bytes);
        std::io::Read::read_to_end(&mut flate2::read::ZlibDecoder::new(&packed[..]), &mut bytes)
            .expect("inflates");
    }
    let n = bytes.len() / width;
    (0..bytes.len())
        .map(|k| bytes[(k % width) * n + k / width])
        .collect()
}

/// `o<name> call [..]` with the NGCGUI defaults of `text`: the values of
/// `(=value …)` comments on `#<…> = #n` lines, by n (0 where none).
pub fn ngcgui_call(name: &str, text: &str) -> String {
    let mut defaults: Vec<(usize, String)> = Vec::new();
    for line in text.lines() {
        let Some((_, rest)) = line.split_once('=') else {
            continue;
        };
        let rest = rest.trim_start();
        let Some(number) = rest.strip_prefix('#') else {
            continue;
        };
        let digits: String = number.chars().take_while(char::is_ascii_digit).collect();
        let Ok(n) = digits.parse::<usize>() else {
            continue;
        };
        let Some((_, comment)) = rest.split_once("(=") else {
            continue;
        };
        let value: String = comment
            .trim_start()
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == '-')
            .collect();
        if !value.is_empty() {
            defaults.push((n, value));
        }
    }
    let count = defaults.iter().map(|(n, _)| *n).max().unwrap_or(0);
    let mut call = format!("o<{name}> call");
    for n in 1..=count {
        let value = defaults
            .iter()
            .find(|(k, _)| *k == n)
            .map_or("0", |(_, v)| v.as_str());
        call.push_str(&format!(" [{value}]"));
    }
    call
}

/// The shared corpus of real programs beside the workspace
/// (`../shared/corpus`, read in place, never copied), canonical when it
/// exists; [`corpus::corpus_path`] skips a test that needs it when it is
/// not there.
pub fn corpus_dir() -> std::path::PathBuf {
    corpus::corpus_root()
}
