//! Progress bars of long runs, on stderr and only when stderr is a terminal (indicatif hides
//! them otherwise), so logs, tables on stdout and CSV files are the same with or without.
//!
//! The bar in use is kept here so that code printing while it runs can clear it first
//! ([`suspend`]) instead of writing through it.

use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;
use std::time::Duration;

/// The bar shown now, if any.
static ACTIVE: Mutex<Option<ProgressBar>> = Mutex::new(None);

/// A bar of `steps` steps (`what` names them), shown until dropped.
pub struct Steps {
    bar: ProgressBar,
}

impl Steps {
    /// Starts a bar counting `steps` steps of `what` (e.g. "bandwidths"); elapsed time ticks
    /// on while a step runs.
    pub fn new(steps: u64, what: &str) -> Steps {
        let bar = ProgressBar::new(steps);
        let template = format!("[{{elapsed_precise}}] {{bar:30}} {{pos}}/{{len}} {what} {{msg}}");
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.enable_steady_tick(Duration::from_millis(250));
        *ACTIVE.lock().unwrap_or_else(|e| e.into_inner()) = Some(bar.clone());
        Steps { bar }
    }

    /// Shows what runs now.
    pub fn message(&self, text: impl Into<String>) {
        self.bar.set_message(text.into());
    }

    /// One step done.
    pub fn step(&self) {
        self.bar.inc(1);
    }
}

impl Drop for Steps {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
        *ACTIVE.lock().unwrap_or_else(|e| e.into_inner()) = None;
    }
}

/// Runs `f` (which prints) with the active bar cleared, redrawing it after.
pub fn suspend<R>(f: impl FnOnce() -> R) -> R {
    let bar = ACTIVE.lock().unwrap_or_else(|e| e.into_inner()).clone();
    match bar {
        Some(bar) => bar.suspend(f),
        None => f(),
    }
}

/// Shows `text` as the active bar's message (nothing without a bar).
pub fn message(text: impl Into<String>) {
    if let Some(bar) = ACTIVE.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
        bar.set_message(text.into());
    }
}

/// `println!` with the active progress bar cleared first (the line is not drawn over it).
#[macro_export]
macro_rules! bar_println {
    ($($arg:tt)*) => {
        $crate::progress::suspend(|| println!($($arg)*))
    };
}

/// `eprintln!` with the active progress bar cleared first.
#[macro_export]
macro_rules! bar_eprintln {
    ($($arg:tt)*) => {
        $crate::progress::suspend(|| eprintln!($($arg)*))
    };
}
