//! Wall-clock time spent in each part of self-collision, for profiling (the counters of
//! rapier's `Counters`, for one stage). Reading the clock changes no result.

use std::time::Duration;

/// Time spent in each part of self-collision since it was turned on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelfCollisionTimes {
    /// The check before each sweep: the displacement clamp, each member's displacement from
    /// its anchor, the movers, and the skin's bookkeeping (a thinner skin's filtering).
    pub check: Duration,
    /// Full builds of the candidate list (grid and pair search).
    pub rebuild: Duration,
    /// Partial updates: movers re-anchored and their pairs added.
    pub reanchor: Duration,
    /// Finding the touching pairs among the listed ones and computing their corrections.
    pub find: Duration,
    /// Moving each touched particle by the mean of its corrections.
    pub apply: Duration,
}

impl SelfCollisionTimes {
    /// Keeping the list up to date: check, builds and partial updates.
    pub fn upkeep(&self) -> Duration {
        self.check + self.rebuild + self.reanchor
    }

    /// The sweeps themselves: finding and applying contacts.
    pub fn sweep(&self) -> Duration {
        self.find + self.apply
    }

    /// Everything.
    pub fn total(&self) -> Duration {
        self.upkeep() + self.sweep()
    }
}
