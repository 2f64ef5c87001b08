//! SIGINT and SIGTERM. While a loop that polls the stop flag is running (a run writing its log,
//! an experiments queue, the viewer) a signal only raises the flag, and the loop closes its
//! outputs (the solver polls the same flag once per substep). At any other time (loading and
//! validating a scene, building its solvers, `weft check`) there is nothing to finish: the
//! handler removes any partial output and ends the process at once.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Exit code of a command stopped by SIGINT or SIGTERM (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: i32 = 130;

/// How many flag-polling loops are running.
static POLLING: AtomicUsize = AtomicUsize::new(0);

/// Installs the handler; returns the stop flag.
pub fn install() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let handler = move || {
        flag.store(true, Ordering::SeqCst);
        if POLLING.load(Ordering::SeqCst) == 0 {
            crate::output::remove_partials();
            eprintln!("weft: stopped");
            std::process::exit(EXIT_INTERRUPTED);
        }
    };
    if let Err(e) = ctrlc::set_handler(handler) {
        eprintln!("weft: warning: cannot catch SIGINT/SIGTERM: {e}");
    }
    stop
}

/// While alive, a signal raises the flag instead of ending the process: the holder polls it.
pub struct Polling(());

impl Polling {
    /// Marks a flag-polling loop as running until the guard drops. If `stop` was raised before
    /// (a signal arrived while nothing polled), the process was already ending.
    pub fn start() -> Self {
        POLLING.fetch_add(1, Ordering::SeqCst);
        Self(())
    }
}

impl Drop for Polling {
    fn drop(&mut self) {
        POLLING.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Work abandoned because the stop flag was raised (an export, an image being written).
#[derive(Debug)]
pub struct Stopped;

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("stopped")
    }
}

impl std::error::Error for Stopped {}
