//! The shared corpus of real programs and LinuxCNC configurations
//! (`../shared/corpus` beside the repository, read in place, never copied
//! into it). A fresh clone does not have it: a test that needs it skips
//! and says so on the terminal. `.ci/run`, which has it, sets
//! `FIVEAXIS_REQUIRE_CORPUS=1`, and a missing corpus then fails the test.
//! Included by the test commons of several crates (`#[path]`).

#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};

/// The corpus folder beside the workspace, canonical when it exists.
pub fn corpus_root() -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus");
    if let Ok(found) = std::fs::canonicalize(&path) {
        return found;
    }
    // Not there: name it plainly, beside the repository's own folder.
    let repository = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    match std::fs::canonicalize(&repository) {
        Ok(root) => root
            .parent()
            .map_or(path, |beside| beside.join("shared/corpus")),
        Err(_) => path,
    }
}

/// `relative` inside the corpus, or `None` when it is not there: the
/// test then skips, after saying so. The message goes to the terminal
/// itself, past the test harness's capture, so that a skipped test is
/// seen as one.
pub fn corpus_path(relative: &str) -> Option<PathBuf> {
    let path = corpus_root().join(relative);
    if path.exists() {
        return Some(path);
    }
    if std::env::var_os("FIVEAXIS_REQUIRE_CORPUS").is_some_and(|v| v != "0") {
        panic!(
            "{} is missing, and FIVEAXIS_REQUIRE_CORPUS is set",
            path.display()
        );
    }
    let _ = writeln!(
        std::io::stderr(),
        "skipped: this test needs {} (the shared corpus beside the repository, not part of it)",
        path.display()
    );
    None
}
