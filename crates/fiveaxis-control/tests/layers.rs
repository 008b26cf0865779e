//! The layering of ARCHITECTURE.md ("Front ends and the command layer"),
//! checked on the source: no G number steers the controller
//! (`src/controller.rs` and `src/controller/`); `src/fanuc/gcodes.rs`
//! turns a block's G codes into typed functions. (That the controller
//! reads no address letter the compiler holds: the words' letter-level
//! methods are private to `src/fanuc/`.) M numbers stay: the machine
//! model's M-function table is keyed by them.

use std::fs;
use std::path::{Path, PathBuf};

/// The controller's source files.
fn controller_files() -> Vec<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = vec![src.join("controller.rs")];
    let mut dirs = vec![src.join("controller")];
    while let Some(dir) = dirs.pop() {
        for entry in fs::read_dir(&dir).expect("read src/controller") {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The lines of `path` that are code (not comments), with their numbers.
fn code_lines(path: &Path) -> Vec<(usize, String)> {
    let text = fs::read_to_string(path).expect("read source");
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with("//"))
        .map(|(i, l)| (i + 1, l.to_string()))
        .collect()
}

#[test]
fn no_g_number_steers_the_controller() {
    let files = controller_files();
    assert!(files.len() > 10, "the controller's files: {files:?}");
    let mut found = Vec::new();
    for path in files {
        // M numbers are the machine model's (its [m_codes] table).
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name == "m_codes.rs" || name == "haas.rs" {
            continue;
        }
        for (n, line) in code_lines(&path) {
            if line.contains(".major") || line.contains(".minor") {
                found.push(format!("{}:{n}: {}", path.display(), line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "the controller decodes a G code (fanuc/gcodes.rs turns them into typed functions):\n{}",
        found.join("\n")
    );
}
