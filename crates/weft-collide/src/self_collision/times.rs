//! Counters and wall-clock time spent in each part of self-collision, for profiling (the
//! counters of rapier's `Counters`, for one stage). Reading the clock changes no result.

use std::time::{Duration, Instant};

use super::SelfCollision;

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

/// What self-collision has done so far: full builds, partial updates, and the time of each
/// part.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Tally {
    /// Lists built so far.
    pub(super) rebuilds: u64,
    /// Partial updates (re-anchoring a few members) so far.
    pub(super) updates: u64,
    /// Time spent in each part so far.
    pub(super) times: SelfCollisionTimes,
}

impl SelfCollision {
    /// Runs `f` and adds the time it took to the part `part` picks, less the time of the parts
    /// timed inside it (a check that rebuilds counts the build as a build, not as check).
    pub(super) fn timed<T>(
        &mut self,
        part: fn(&mut SelfCollisionTimes) -> &mut Duration,
        f: impl FnOnce(&mut Self) -> T,
    ) -> T {
        let (start, before) = (Instant::now(), self.tally.times.total());
        let out = f(self);
        let inside = self.tally.times.total() - before;
        *part(&mut self.tally.times) += start.elapsed().saturating_sub(inside);
        out
    }
}
