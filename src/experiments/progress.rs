//! Progress while `weft experiments` runs: one bar for the queue, on a terminal only.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Runs done out of the runs queued, with each finished run printed above the bar.
pub struct QueueProgress {
    bar: ProgressBar,
}

impl QueueProgress {
    /// A bar for `runs` runs, drawn on stderr when it is a terminal (hidden otherwise).
    pub fn new(runs: usize) -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(runs as u64), target);
        if let Ok(style) = ProgressStyle::with_template(
            "{elapsed_precise} [{bar:32}] {pos}/{len} runs, eta {eta} {msg}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        Self { bar }
    }

    /// Counts one finished run and shows `line` above the bar.
    pub fn done(&self, line: &str) {
        self.note(line);
        self.bar.inc(1);
    }

    /// Shows `line` above the bar (a warning before a run starts).
    pub fn note(&self, line: &str) {
        // A hidden bar prints nothing, so off a terminal the line goes to stderr directly.
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
