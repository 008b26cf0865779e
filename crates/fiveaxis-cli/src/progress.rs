//! Progress bars on standard error (indicatif), for `check` and `view`:
//! hidden for the first second, so that a quick run prints nothing, and
//! altogether when standard error is not a terminal (indicatif's rule for
//! its standard-error target).

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A run that has taken this long shows its progress bar.
pub const PROGRESS_DELAY: Duration = Duration::from_secs(1);

/// A progress bar that shows once its run has taken [`PROGRESS_DELAY`].
/// Shared between threads (`check` runs programs in parallel).
pub struct DelayedBar {
    bar: ProgressBar,
    start: Instant,
    shown: AtomicBool,
    /// Serialises showing the bar.
    show: Mutex<()>,
}

impl DelayedBar {
    /// A bar of `len` steps drawn with indicatif's `template`.
    pub fn new(len: u64, template: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Self {
            bar,
            start: Instant::now(),
            shown: AtomicBool::new(false),
            show: Mutex::new(()),
        }
    }

    /// The bar, shown from now on once the delay has passed; `None` while
    /// it is hidden (nothing to update).
    pub fn visible(&self) -> Option<&ProgressBar> {
        if !self.shown.load(Ordering::Relaxed) && self.start.elapsed() >= PROGRESS_DELAY {
            let _guard = self.show.lock();
            if !self.shown.swap(true, Ordering::Relaxed) {
                self.bar.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
        self.shown.load(Ordering::Relaxed).then_some(&self.bar)
    }

    /// The bar, shown or not (for its position).
    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for DelayedBar {
    /// A run that ends early (an error) leaves no bar on the terminal.
    fn drop(&mut self) {
        if !self.bar.is_finished() {
            self.bar.finish_and_clear();
        }
    }
}
