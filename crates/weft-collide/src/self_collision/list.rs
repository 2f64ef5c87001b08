//! The candidate list: the pairs of the last full build, in runs of grid cells, and those
//! added for re-anchored members since, with the anchors they were listed at; built from a
//! [`CellGrid`] and filtered down when the skin thins.

use std::ops::ControlFlow;
use std::sync::atomic::Ordering;

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;

use super::SelfCollision;
use crate::grid::CellGrid;

/// Candidate pairs as struct-of-arrays, a < b.
#[derive(Clone, Debug, Default)]
pub(super) struct PairList {
    pub(super) a: Vec<u32>,
    pub(super) b: Vec<u32>,
    pub(super) target: Vec<f64>,
}

impl PairList {
    pub(super) fn clear(&mut self) {
        self.a.clear();
        self.b.clear();
        self.target.clear();
    }

    pub(super) fn push(&mut self, a: u32, b: u32, target: f64) {
        self.a.push(a);
        self.b.push(b);
        self.target.push(target);
    }

    pub(super) fn len(&self) -> usize {
        self.a.len()
    }

    /// Keeps the pairs for which `keep(a, b, target)` holds, in order.
    pub(super) fn retain(&mut self, mut keep: impl FnMut(u32, u32, f64) -> bool) {
        let mut n = 0;
        for k in 0..self.a.len() {
            let (a, b, target) = (self.a[k], self.b[k], self.target[k]);
            self.a[n] = a;
            self.b[n] = b;
            self.target[n] = target;
            n += usize::from(keep(a, b, target));
        }
        self.a.truncate(n);
        self.b.truncate(n);
        self.target.truncate(n);
    }
}

/// A pair (a < b) as one key.
#[inline(always)]
pub(super) fn pair_key(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

/// The Verlet list of candidate pairs and the anchors it holds for.
#[derive(Clone, Debug, Default)]
pub(super) struct List {
    /// The members at the last full build, sorted by cell.
    pub(super) grid: CellGrid,
    /// The pairs of the last full build, one list per run of grid cells.
    pub(super) pairs: Vec<PairList>,
    /// Each member's position at the last full build (member order): a pair is in `pairs`
    /// exactly when it is not exempt and these two are at most R apart by the grid's own test.
    pub(super) built_pos: Vec<DVec3>,
    /// Each member's anchor x⁰ (member order): its position at the last full build, or, for
    /// a member re-anchored since, its position then less the common displacement.
    pub(super) built_at: Vec<DVec3>,
    /// Members (slots) re-anchored since the last full build, and a flag per slot: their
    /// positions in `grid` are stale.
    pub(super) reanchored: Vec<u32>,
    pub(super) is_reanchored: Vec<bool>,
    /// Pairs added for re-anchored members since the last full build (not in `pairs`), in the
    /// order they were added, and the same pairs as keys ([`pair_key`]) to look them up.
    pub(super) extra: PairList,
    pub(super) in_extra: FxHashSet<u64>,
    /// Largest member thickness the list was built for; `None` when there is no list.
    pub(super) built_for: Option<f64>,
    /// The members' mean displacement from their anchors at the last two checks.
    pub(super) drift: [DVec3; 2],
}

impl List {
    /// Candidate pairs in the list.
    pub(super) fn len(&self) -> usize {
        self.pairs.iter().map(PairList::len).sum::<usize>() + self.extra.len()
    }
}

impl SelfCollision {
    /// Builds the list at `positions`: pairs from the grid, run by run on rayon's threads,
    /// with their targets.
    pub(super) fn rebuild(&mut self, positions: &[DVec3], thickness: &[f64]) {
        self.timed(|t| &mut t.rebuild, |s| s.build(positions, thickness));
    }

    /// [`SelfCollision::rebuild`] without its clock.
    fn build(&mut self, positions: &[DVec3], thickness: &[f64]) {
        self.tally.rebuilds += 1;
        for &r in &self.list.reanchored {
            self.list.is_reanchored[r as usize] = false;
        }
        self.list.reanchored.clear();
        self.list.is_reanchored.resize(self.members.len(), false);
        self.list.extra.clear();
        self.list.in_extra.clear();
        self.list.built_at.clear();
        self.list
            .built_at
            .extend(self.members.iter().map(|&i| positions[i as usize]));
        self.list.built_pos.clone_from(&self.list.built_at);
        self.list.drift = [DVec3::ZERO; 2];
        let max_t = self.max_thickness(thickness);
        self.list.built_for = Some(max_t);
        self.list.pairs.iter_mut().for_each(PairList::clear);
        if max_t <= 0.0 {
            return;
        }
        let apart = self.exempt.apart(max_t);
        let radius = self.radius(max_t);
        self.list.grid.build(positions, &self.members, radius);
        self.list.grid.tag(self.exempt.tags(apart));
        // A few runs per thread balance the load; the runs change nothing but the cost.
        let runs = self.list.grid.cell_runs(4 * rayon::current_num_threads());
        self.list.pairs.resize_with(runs.len(), PairList::default);
        let grid = &self.list.grid;
        let stop = self.stop.as_deref();
        let stopping = || stop.is_some_and(|f| f.load(Ordering::Relaxed));
        self.list
            .pairs
            .par_iter_mut()
            .zip(runs)
            .for_each(|(list, run)| {
                list.clear();
                let mut row = Vec::new();
                // Exempt pairs are left out by the search itself.
                grid.for_each_row_in(run, radius, apart, &mut row, |i, near| {
                    let ti = thickness[i as usize];
                    for &j in near {
                        list.push(i.min(j), i.max(j), 0.5 * (ti + thickness[j as usize]));
                    }
                    // A list of a huge thickness takes seconds: a stop cuts it short.
                    if stopping() {
                        ControlFlow::Break(())
                    } else {
                        ControlFlow::Continue(())
                    }
                });
            });
        if stopping() {
            // The frame is being abandoned: no list, so the next check builds one anew.
            self.list.pairs.iter_mut().for_each(PairList::clear);
            self.list.built_for = None;
            return;
        }
        self.skin.built(self.members.len(), self.pair_count());
    }

    /// Lists for the (thinner) skin's radius R: keeps in `pairs` those whose positions at the
    /// build are within R, the grid's test replayed (what a build at R would list), moves to
    /// `extra` the others whose anchors are within R (a member re-anchored since the build is
    /// nearer its partner now), and keeps in `extra` those whose anchors are within R. Every
    /// non-exempt pair whose anchors are within R stays listed, and none twice. Rare (at most
    /// once per epoch): serial.
    pub(super) fn shrink(&mut self) {
        let Some(t) = self.list.built_for else { return };
        let radius = self.radius(t);
        let r2 = radius * radius;
        let slot_of = &self.slot_of;
        let near = |anchors: &[DVec3], a: u32, b: u32| {
            let (sa, sb) = (slot_of[a as usize], slot_of[b as usize]);
            anchors[sa as usize].distance_squared(anchors[sb as usize]) <= r2
        };
        // Pairs of the build's lists are not in `extra`: the moved ones can join it as they
        // are.
        let extra = &mut self.list.extra;
        extra.retain(|a, b, _| near(&self.list.built_at, a, b));
        for list in &mut self.list.pairs {
            list.retain(|a, b, target| {
                let built = near(&self.list.built_pos, a, b);
                if !built && near(&self.list.built_at, a, b) {
                    extra.push(a, b, target);
                }
                built
            });
        }
        self.list.in_extra.clear();
        self.list
            .in_extra
            .extend(extra.a.iter().zip(&extra.b).map(|(&a, &b)| pair_key(a, b)));
    }
}
