//! Helpers of the integration tests.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};

/// The shared corpus of real programs beside the repository
/// (`../shared/corpus`), read in place and never copied into it.
pub fn corpus_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
}

/// `name` in the corpus, or `None` when the corpus is not there: the test
/// then skips, saying so on the terminal (past the harness's capture).
/// With `FIVEAXIS_REQUIRE_CORPUS` set, a missing corpus fails instead.
pub fn corpus_file(name: &str) -> Option<PathBuf> {
    let path = corpus_root().join(name);
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
        "skipped: this test needs ../shared/corpus/{name} (the shared corpus beside the repository, not part of it)"
    );
    None
}

/// The stack of the threads the depth tests run on.
pub const SMALL_STACK: usize = 256 * 1024;

/// Runs `f` on a thread with a 256 KiB stack.
pub fn on_small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(SMALL_STACK)
        .spawn(f)
        .expect("thread")
        .join()
        .expect("the test ends on a 256 KiB stack");
}
