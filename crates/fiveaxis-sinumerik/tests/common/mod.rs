//! Helpers of the integration tests.
#![allow(dead_code)]

/// The shared corpus beside the repository: the CLI's helper, which the
/// other crates' tests include too.
#[path = "../../../fiveaxis-cli/tests/common/corpus.rs"]
pub mod corpus;

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

/// A fake control and program store for the interpreter's tests.
pub mod fake;
