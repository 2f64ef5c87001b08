//! Seams that did not close, in words: the warning `run`, `view` and `render` print once per
//! garment whose seam pairs are still open after they were due to close
//! ([`weft_sim::SeamWatch`]).

use weft_sim::{SeamWatch, Simulation};

/// Prints a warning for each cloth of `sim` whose seams came due since `watch` last looked and
/// are still open; returns how many there were. The run goes on.
pub fn warn_open(watch: &mut SeamWatch, sim: &Simulation) -> usize {
    let open = watch.look(sim);
    for s in &open {
        eprintln!("weft: warning: {s}");
    }
    open.len()
}
