//! Every command example of README.md and docs/*.md, run with this
//! binary and compared with what the page shows.
//!
//! How a page writes an example that this test runs:
//!
//! * A command is a line of a fenced code block that starts with `$ `;
//!   a line ending in `\` continues it on the next. A block is run when
//!   one of its commands calls `fiveaxis` (`$ fiveaxis …`, `$ printf … |
//!   fiveaxis …`, or `$ cargo run --release -p fiveaxis-cli -- …`, which
//!   is run as `fiveaxis …`); its other commands (`sed`, `printf`) run
//!   too, in order, through `sh`. Blocks without a `$ ` line (install
//!   steps, syntax summaries) are left alone.
//! * The lines after a command, up to the next command or the end of the
//!   block, are its output as a terminal shows it (standard output and
//!   standard error together); `...` alone on a line stands for any number
//!   of lines. A command with no line after it is checked for its exit
//!   status only.
//! * Exit status: 0, or 1 when the output shown has a line starting with
//!   `ALARM `. An HTML comment `<!-- exit N -->` on the line before the
//!   block's opening fence sets it for the block's last command; the
//!   other commands of the block must exit 0.
//! * Commands run from a scratch folder whose entries are links to the
//!   repository root's (so `examples/…` reads as on a clone, and files a
//!   command writes stay out of the work tree), one folder per page, in
//!   page order: a file one command writes is there for the next. A
//!   command naming `../shared` runs only when the corpus is beside the
//!   repository; without it, it and the rest of its block are skipped,
//!   and the test says so.
//!
//! A failure names the page and line, and prints the block as it would
//! read with the output of this build, ready to paste.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// What `cargo run` is written as in the quick start; run as `fiveaxis`.
const CARGO_RUN: &str = "cargo run --release -p fiveaxis-cli -- ";

/// The line that stands for any number of output lines.
const ELLIPSIS: &str = "...";

/// Most lines of a command's real output printed in a failure.
const SHOWN: usize = 60;

/// One command of a page, with the output the page shows for it.
#[derive(Debug)]
struct Example {
    /// 1-based line of the `$ ` in the page.
    line: usize,
    /// The command as the page writes it (continuation lines included).
    command: String,
    /// The lines after it, up to the next command or the end of the block.
    output: Vec<String>,
    /// The exit status it must end with.
    status: i32,
}

/// A fenced block holding at least one command, in page order.
#[derive(Debug)]
struct Block {
    examples: Vec<Example>,
}

/// The command blocks of `text` that call `fiveaxis`.
fn blocks(text: &str) -> Vec<Block> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if !lines[i].starts_with("```") {
            i += 1;
            continue;
        }
        let open = i;
        let mut close = open + 1;
        while close < lines.len() && !lines[close].starts_with("```") {
            close += 1;
        }
        let exit = lines[..open]
            .iter()
            .rev()
            .find(|l| !l.trim().is_empty())
            .and_then(|l| exit_comment(l));
        if let Some(block) = block(&lines, open + 1, close, exit) {
            found.push(block);
        }
        i = close + 1;
    }
    found
}

/// N of a line `<!-- exit N -->`.
fn exit_comment(line: &str) -> Option<i32> {
    line.trim()
        .strip_prefix("<!--")?
        .strip_suffix("-->")?
        .trim()
        .strip_prefix("exit ")?
        .trim()
        .parse()
        .ok()
}

/// The commands of the block between lines `start` and `end` (0-based,
/// `end` excluded), when one of them calls `fiveaxis`.
fn block(lines: &[&str], start: usize, end: usize, exit: Option<i32>) -> Option<Block> {
    let mut examples: Vec<Example> = Vec::new();
    let mut i = start;
    while i < end {
        let Some(first) = lines[i].strip_prefix("$ ") else {
            if let Some(last) = examples.last_mut() {
                last.output.push(lines[i].trim_end().to_owned());
            }
            i += 1;
            continue;
        };
        let line = i + 1;
        let mut command = first.to_owned();
        while command.ends_with('\\') && i + 1 < end {
            i += 1;
            command.push('\n');
            command.push_str(lines[i]);
        }
        examples.push(Example {
            line,
            command,
            output: Vec::new(),
            status: 0,
        });
        i += 1;
    }
    if !examples.iter().any(|e| calls_fiveaxis(&e.command)) {
        return None;
    }
    for example in &mut examples {
        while example.output.last().is_some_and(|l| l.is_empty()) {
            example.output.pop();
        }
        if example.output.iter().any(|l| l.starts_with("ALARM ")) {
            example.status = 1;
        }
    }
    if let (Some(status), Some(last)) = (exit, examples.last_mut()) {
        last.status = status;
    }
    Some(Block { examples })
}

/// The command as the shell runs it: `cargo run … --` becomes `fiveaxis`.
fn shell_text(command: &str) -> String {
    match command.strip_prefix(CARGO_RUN) {
        Some(rest) => format!("fiveaxis {rest}"),
        None => command.to_owned(),
    }
}

/// Whether the command runs the `fiveaxis` binary.
fn calls_fiveaxis(command: &str) -> bool {
    shell_text(command)
        .split(|c: char| c.is_whitespace() || c == '|' || c == ';' || c == '(')
        .any(|word| word == "fiveaxis")
}

/// Whether the lines `actual` read as `expected`, where a line `...` of
/// `expected` stands for any number of lines.
fn matches(expected: &[String], actual: &[String]) -> bool {
    match expected.split_first() {
        None => actual.is_empty(),
        Some((first, rest)) if first == ELLIPSIS => {
            (0..=actual.len()).any(|skip| matches(rest, &actual[skip..]))
        }
        Some((first, rest)) => actual
            .split_first()
            .is_some_and(|(line, tail)| line == first && matches(rest, tail)),
    }
}

/// The first line, before any `...`, where the page and the output differ:
/// its 1-based number, the page's line and the printed one.
fn first_difference(expected: &[String], actual: &[String]) -> Option<(usize, String, String)> {
    let gone = || "(no more lines)".to_owned();
    expected
        .iter()
        .take_while(|l| *l != ELLIPSIS)
        .enumerate()
        .find(|(i, l)| actual.get(*i) != Some(*l))
        .map(|(i, l)| {
            (
                i + 1,
                l.clone(),
                actual.get(i).cloned().unwrap_or_else(gone),
            )
        })
}

/// The output lines a page would show for `actual`, in the shape of
/// `expected`: as many lines kept before its first `...` and after its
/// last as it shows there; all of `actual` (up to `SHOWN` lines) when it
/// has no `...`.
fn proposal(expected: &[String], actual: &[String]) -> Vec<String> {
    let first = expected.iter().position(|l| l == ELLIPSIS);
    let last = expected.iter().rposition(|l| l == ELLIPSIS);
    let (head, tail) = match (first, last) {
        (Some(first), Some(last)) => (first, expected.len() - last - 1),
        _ => (SHOWN, 0),
    };
    if head + tail >= actual.len() {
        return actual.to_vec();
    }
    let mut lines = actual[..head].to_vec();
    lines.push(ELLIPSIS.to_owned());
    lines.extend_from_slice(&actual[actual.len() - tail..]);
    lines
}

/// A scratch folder with a link to every entry of the repository root,
/// and `../shared` linked when it is beside the repository.
fn scratch(root: &Path, dir: &Path) -> PathBuf {
    let clone = dir.join("clone");
    std::fs::create_dir(&clone).expect("a scratch folder");
    for entry in std::fs::read_dir(root).expect("the repository root reads") {
        let entry = entry.expect("an entry of the root");
        std::os::unix::fs::symlink(entry.path(), clone.join(entry.file_name()))
            .expect("a link in the scratch folder");
    }
    let shared = root.join("../shared");
    if shared.is_dir() {
        std::os::unix::fs::symlink(&shared, dir.join("shared")).expect("a link to ../shared");
    }
    clone
}

/// Standard output and standard error of `command` run by `sh` in `dir`
/// (merged as a terminal shows them), and its exit status.
fn run(command: &str, dir: &Path, bin: &Path) -> (Vec<String>, Option<i32>) {
    let path = std::env::var_os("PATH").unwrap_or_default();
    let mut paths = vec![bin.to_path_buf()];
    paths.extend(std::env::split_paths(&path));
    let output = Command::new("sh")
        .arg("-c")
        .arg(format!("exec 2>&1\n{}", shell_text(command)))
        .current_dir(dir)
        .env("PATH", std::env::join_paths(paths).expect("a PATH"))
        .env_remove("FORCE_COLOR")
        .env_remove("CLICOLOR_FORCE")
        .output()
        .expect("sh runs");
    let text = String::from_utf8_lossy(&output.stdout);
    let mut lines: Vec<String> = text.lines().map(|l| l.trim_end().to_owned()).collect();
    while lines.last().is_some_and(|l| l.is_empty()) {
        lines.pop();
    }
    (lines, output.status.code())
}

/// What is wrong with one example's run, if anything.
fn judge(page: &str, example: &Example, output: &[String], status: Option<i32>) -> Option<String> {
    let status_ok = status == Some(example.status);
    let output_ok = example.output.is_empty() || matches(&example.output, output);
    if status_ok && output_ok {
        return None;
    }
    let mut message = format!("{page}:{}: `$ {}`\n", example.line, example.command);
    if !status_ok {
        let _ = writeln!(
            message,
            "  exit status {status:?}, the page expects {} (set it with `<!-- exit N -->` before the block)",
            example.status
        );
    }
    if !output_ok {
        message.push_str("  the page shows:\n");
        for line in &example.output {
            let _ = writeln!(message, "    {line}");
        }
        if let Some((n, shown, printed)) = first_difference(&example.output, output) {
            let _ = writeln!(
                message,
                "  first difference, output line {n}:\n    page:    {shown}\n    printed: {printed}"
            );
        }
    }
    let _ = writeln!(
        message,
        "  the command printed {} lines; the example would read:\n",
        output.len()
    );
    let _ = writeln!(message, "$ {}", example.command);
    let shown = if example.output.is_empty() {
        proposal(&[], output)
    } else {
        proposal(&example.output, output)
    };
    for line in shown {
        let _ = writeln!(message, "{line}");
    }
    Some(message)
}

#[test]
fn every_command_of_the_readme_and_docs_prints_what_the_page_shows() {
    let root = common::root();
    let mut pages = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("docs/ reads")
        .map(|e| e.expect("an entry of docs/").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);

    let bin_dir = tempfile::tempdir().expect("a temporary folder");
    std::os::unix::fs::symlink(
        env!("CARGO_BIN_EXE_fiveaxis"),
        bin_dir.path().join("fiveaxis"),
    )
    .expect("a link to the binary");
    let corpus = root.join("../shared/corpus").is_dir();

    let mut failures = Vec::new();
    let mut ran = 0;
    let mut readme_commands = 0;
    for page in &pages {
        let name = page
            .strip_prefix(root)
            .unwrap_or(page)
            .display()
            .to_string();
        let text = std::fs::read_to_string(page).expect("the page reads");
        let found = blocks(&text);
        if name == "README.md" {
            readme_commands = found.iter().map(|b| b.examples.len()).sum();
        }
        let dir = tempfile::tempdir().expect("a temporary folder");
        let clone = scratch(root, dir.path());
        for block in &found {
            for example in &block.examples {
                if !corpus && example.command.contains("../shared") {
                    println!(
                        "{name}:{}: skipped with the rest of its block: \
                         no corpus at ../shared/corpus beside the repository",
                        example.line
                    );
                    break;
                }
                let (output, status) = run(&example.command, &clone, bin_dir.path());
                ran += 1;
                if let Some(failure) = judge(&name, example, &output, status) {
                    failures.push(failure);
                }
            }
        }
    }
    println!("{ran} commands run");
    assert!(
        readme_commands >= 8,
        "the README's command examples were not found ({readme_commands}): \
         is the `$ ` convention of tests/readme.rs still the README's?"
    );
    assert!(
        failures.is_empty(),
        "{} of {ran} commands differ from their page:\n\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn ellipsis_stands_for_any_lines_and_nothing_else_does() {
    let lines = |s: &str| -> Vec<String> { s.lines().map(str::to_owned).collect() };
    assert!(matches(&lines("a\n...\nd"), &lines("a\nb\nc\nd")));
    assert!(matches(&lines("a\n...\nd"), &lines("a\nd")));
    assert!(matches(&lines("a\n..."), &lines("a")));
    assert!(!matches(&lines("a\n...\nd"), &lines("a\nb\nc")));
    assert!(!matches(&lines("a\nb"), &lines("a\nb\nc")));
    assert!(!matches(&lines("a\nc"), &lines("a\nb")));
    assert_eq!(
        proposal(&lines("a\nb\n...\nz"), &lines("1\n2\n3\n4\n5")),
        lines("1\n2\n...\n5")
    );
    assert_eq!(
        first_difference(&lines("a\nb\n...\nz"), &lines("a\nc")),
        Some((2, "b".to_owned(), "c".to_owned()))
    );
    assert_eq!(first_difference(&lines("a\n...\nz"), &lines("a\nc")), None);
}

#[test]
fn blocks_commands_outputs_and_exit_statuses_are_read_as_documented() {
    let page = "text\n\n```\nfiveaxis run PROGRAM\n```\n\n<!-- exit 2 -->\n```\n\
                $ printf 'x' > a.nc\n$ fiveaxis run a.nc \\\n    --step 1\nerror: x\n\n```\n\
                ```\n$ cargo run --release -p fiveaxis-cli -- run b.nc\nALARM PS0010 line 1: x\n```\n\
                ```sh\n$ cargo install --path crates/fiveaxis-cli --locked\n```\n";
    let found = blocks(page);
    assert_eq!(found.len(), 2, "{found:?}");
    let first = &found[0].examples;
    assert_eq!(first.len(), 2);
    assert_eq!((first[0].line, first[0].status), (9, 0));
    assert_eq!(first[1].command, "fiveaxis run a.nc \\\n    --step 1");
    assert_eq!(first[1].output, vec!["error: x".to_owned()]);
    assert_eq!(first[1].status, 2);
    let second = &found[1].examples[0];
    assert_eq!(second.status, 1);
    assert_eq!(shell_text(&second.command), "fiveaxis run b.nc");
}
