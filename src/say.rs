//! Standard output. A closed pipe (`weft run … | head -1`) ends the output quietly and the
//! command finishes with its own exit code, as ripgrep and cargo do; any other failure (a full
//! device) is an error naming standard output, never a panic.

use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once the reader of standard output has gone.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `args` to standard output and flushes it.
pub fn say(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_fmt(args).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(anyhow::anyhow!("cannot write to standard output: {e}")),
    }
}

/// `println!` through [`say`]: evaluates to `anyhow::Result<()>`.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::say::say(format_args!("{}\n", format_args!($($arg)*)))
    };
}
