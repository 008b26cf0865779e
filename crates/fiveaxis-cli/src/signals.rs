//! Interrupted runs leave nothing behind: while an `-o` file is being
//! written to its hidden temporary file, SIGINT (Ctrl-C), SIGTERM and
//! SIGHUP remove that file before the process dies of the signal.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once, PoisonError};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// The temporary file to remove on a signal, if one is being written.
static PENDING: Mutex<Option<PathBuf>> = Mutex::new(None);
static HANDLER: Once = Once::new();

fn pending() -> MutexGuard<'static, Option<PathBuf>> {
    PENDING.lock().unwrap_or_else(PoisonError::into_inner)
}

/// While the returned guard lives, a terminating signal removes `path`.
pub fn remove_on_signal(path: &Path) -> Cleanup {
    *pending() = Some(path.to_path_buf());
    HANDLER.call_once(|| {
        // Without the handler (signals unavailable) an interrupted run may
        // leave its temporary file, as before; the run itself goes on.
        if let Ok(mut signals) = Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            std::thread::spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    if let Some(path) = pending().take() {
                        let _ = std::fs::remove_file(path);
                    }
                    let _ = signal_hook::low_level::emulate_default_handler(signal);
                    std::process::exit(128 + signal);
                }
            });
        }
    });
    Cleanup(())
}

/// The temporary file registered by [`remove_on_signal`].
#[derive(Debug)]
pub struct Cleanup(());

impl Cleanup {
    /// Runs `finish` (which renames or removes the file) with signals held
    /// off the file, then forgets it: a signal during the rename cannot
    /// remove the finished output.
    pub fn finish<T>(self, finish: impl FnOnce() -> T) -> T {
        let mut guard = pending();
        let out = finish();
        *guard = None;
        out
    }
}
