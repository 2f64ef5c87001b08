//! The check before each sweep: in one parallel pass, clamp each member's displacement this
//! substep, measure how far the members strayed from their anchors, and collect the movers;
//! then keep the list, re-anchor the movers, or rebuild (see [`SelfCollision::refresh`]).

use glam::DVec3;
use rayon::prelude::*;

use super::SelfCollision;
use super::skin::Change;

/// A list is rebuilt rather than updated when more than 1/MOVERS_CAP of the members stray at
/// once, or more than 1/REANCHORED_CAP (`reanchor.rs`) have strayed since the last build: a
/// partial update costs about eight times a rebuild per member (measured at 128², 2 threads).
const MOVERS_CAP: usize = 16;

/// Members per rayon task in the per-member loops.
const MEMBER_CHUNK: usize = 1024;

/// What limits a substep's displacements (see [`SelfCollision::refresh`]).
#[derive(Clone, Copy)]
pub(crate) struct Clamp<'a> {
    /// Positions at the start of the substep.
    pub prev: &'a [DVec3],
    /// Inverse masses (pinned particles are left alone).
    pub w: &'a [f64],
}

impl Clamp<'_> {
    /// Moves particle `i` back towards its start of substep until it is at most `limit` away.
    #[inline(always)]
    pub(super) fn apply(&self, i: usize, x: &mut DVec3, limit: f64) {
        if self.w[i] == 0.0 {
            return;
        }
        let d = *x - self.prev[i];
        // Most particles move less than the limit: compare squares, and take the root only
        // for those that do not.
        let len2 = d.length_squared();
        if len2 > limit * limit {
            *x = self.prev[i] + d * (limit / len2.sqrt());
        }
    }
}

/// One chunk's part of a list check: the box and sum of its members' displacements, and its
/// movers (slots).
#[derive(Clone, Debug)]
pub(super) struct Scan {
    lo: DVec3,
    hi: DVec3,
    sum: DVec3,
    movers: Vec<u32>,
}

impl Default for Scan {
    fn default() -> Self {
        Self {
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
            sum: DVec3::ZERO,
            movers: Vec::new(),
        }
    }
}

impl Scan {
    /// Empties the findings, keeping the movers' storage.
    fn reset(&mut self) {
        let empty = Scan::default();
        (self.lo, self.hi, self.sum) = (empty.lo, empty.hi, empty.sum);
        self.movers.clear();
    }
}

impl SelfCollision {
    /// [`SelfCollision::refresh`] without its clock.
    pub(super) fn check(
        &mut self,
        positions: &mut [DVec3],
        thickness: &[f64],
        clamp: Option<Clamp<'_>>,
    ) {
        match self.skin.record(self.pair_count(), self.members.len()) {
            Change::Keep => {}
            Change::Grow => self.list.built_for = None,
            Change::Shrink => self.shrink(),
        }
        let max = self.params.max_displacement;
        // The list's thickness, half-skin² and predicted common displacement, unless there is
        // no list to check (none built yet, or no thickness or members: no pairs).
        let check = self
            .list
            .built_for
            .filter(|&t| t > 0.0 && !self.members.is_empty())
            .map(|t| {
                let limit = self.limit(t);
                (
                    t,
                    limit * limit,
                    2.0 * self.list.drift[0] - self.list.drift[1],
                )
            });
        // Per fixed chunk of particles (so the sum is the same on any thread count): clamp,
        // then the box and the sum of the members' displacements, and the movers.
        self.scans
            .resize_with(positions.len().div_ceil(MEMBER_CHUNK), Scan::default);
        let (slot_of, built_at) = (&self.slot_of, &self.list.built_at);
        positions
            .par_chunks_mut(MEMBER_CHUNK)
            .zip(self.scans.par_iter_mut())
            .enumerate()
            .for_each(|(k, (xs, scan))| {
                scan.reset();
                // In locals, not through `scan`: the movers' pushes would otherwise make the
                // compiler store and reload the three sums at every particle.
                let (mut lo, mut hi, mut sum) = (scan.lo, scan.hi, scan.sum);
                let movers = &mut scan.movers;
                for (j, x) in xs.iter_mut().enumerate() {
                    let i = k * MEMBER_CHUNK + j;
                    let slot = slot_of[i];
                    if slot == u32::MAX {
                        continue;
                    }
                    if let Some(clamp) = clamp {
                        clamp.apply(i, x, max * thickness[i]);
                    }
                    if let Some((_, limit2, guess)) = check {
                        let d = *x - built_at[slot as usize];
                        (lo, hi, sum) = (lo.min(d), hi.max(d), sum + d);
                        if (d - guess).length_squared() > limit2 {
                            movers.push(slot);
                        }
                    }
                }
                (scan.lo, scan.hi, scan.sum) = (lo, hi, sum);
            });
        let Some((t, limit2, guess)) = check else {
            if self.list.built_for.is_none() {
                self.rebuild(positions, thickness);
            }
            return;
        };
        let empty = Scan::default();
        let (lo, hi, sum) = self
            .scans
            .iter()
            .fold((empty.lo, empty.hi, empty.sum), |(lo, hi, sum), s| {
                (lo.min(s.lo), hi.max(s.hi), sum + s.sum)
            });
        self.list.drift = [sum / self.members.len() as f64, self.list.drift[0]];
        // Every |Δᵢ − box centre| is at most the box's half-diagonal: often that settles it.
        if (0.5 * (hi - lo)).length_squared() <= limit2 {
            return;
        }
        self.moved.movers.clear();
        for scan in &self.scans {
            self.moved.movers.extend_from_slice(&scan.movers);
        }
        if self.moved.movers.len() > (self.members.len() / MOVERS_CAP).max(64) {
            return self.rebuild(positions, thickness);
        }
        if !self.moved.movers.is_empty() {
            self.reanchor(positions, thickness, guess, t);
        }
    }
}
