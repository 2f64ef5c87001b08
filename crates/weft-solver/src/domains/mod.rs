//! Domain decomposition of the distance constraints for parallel, SIMD Gauss–Seidel.
//!
//! Particles are cut into contiguous index ranges of `size` particles (domains). A distance
//! constraint whose two particles lie in one domain is *interior*: each domain keeps its own
//! struct-of-arrays copy of its particles and projects its interior constraints colour by colour,
//! eight at a time, without touching any other domain — so domains run on any threads, in any
//! order, with no synchronisation. Constraints across domains (*links*, a few per cent on
//! meshes with local particle order) are projected in a fork–join tree over the domains, each
//! link once both its domains are done (see [`fork`]). The split
//! depends on `size` and the mesh only, never on the thread count: results are bit-identical
//! for 1, 2 or 64 threads.
//!
//! Inside a domain, constraints fall into conflict-free sets (see `Domain::order`), sorted by
//! particle index, so that on structured meshes eight consecutive constraints usually touch
//! eight consecutive particles (`Layout::Contiguous`, e.g. a row of vertical grid edges) or a
//! window of 15–31 consecutive ones (`Layout::Paired`, `Quad`, `Spaced`, `Strided`): those
//! chunks load and store with unit stride, and anything else is gathered lane by lane.
//!
//! The module's parts: [`domain`] (a domain's particles, integration and velocity update),
//! [`order`] (colouring and chunking of a domain's constraints), [`layout`] (how a chunk's
//! lanes reach their particles), [`sweep`] (the Gauss–Seidel sweep over a domain's chunks),
//! [`tree`] (the fork–join tree and the links between domains) and [`team`] (the threads that
//! stay together for a fused frame); `tests` (test builds only) holds their unit tests.

mod domain;
mod layout;
mod order;
mod sweep;
mod team;
#[cfg(test)]
mod tests;
mod tree;

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use crate::constraints::lanes::{Coef, LANES};
use crate::constraints::{Block, Distance, Rule};
use crate::params::FamilyParams;
use weft_simd::SimdPath;

pub(crate) use domain::{AosChunk, Domain, Finish, Integration, Mode, Start};
use layout::Layout;
use order::Interior;
use tree::{Job, LinkSet, fork, tree_node};

/// How a solver's distance constraints are laid out for the parallel SIMD solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DomainStats {
    /// Number of domains.
    pub domains: usize,
    /// Particles per domain.
    pub domain_size: usize,
    /// Constraints across domains, solved serially after them.
    pub links: usize,
    /// Interior constraints in chunks of 8 with unit-stride ends.
    pub contiguous: usize,
    /// Interior constraints in chunks of 8 loaded from 16-particle windows and permuted.
    pub strided: usize,
    /// Interior constraints in chunks of 8 loaded lane by lane.
    pub gathered: usize,
    /// Interior constraints solved one at a time (the tail of each colour).
    pub remainder: usize,
    /// The kernel path the domains run on.
    pub simd: SimdPath,
}

/// Ranges covering the local indices `ends`, in order; indices less than a vector apart share
/// a range (adding a particle's displacement early gives the same bits).
fn cover(mut ends: Vec<usize>) -> Vec<Range<usize>> {
    ends.sort_unstable();
    let mut ranges: Vec<Range<usize>> = Vec::new();
    for i in ends {
        match ranges.last_mut() {
            Some(r) if i < r.end + LANES => r.end = r.end.max(i + 1),
            _ => ranges.push(i..i + 1),
        }
    }
    ranges
}

/// Particles from which a cloth is cut into two domains at least: two halves of 2,048 still
/// give each of two threads work enough (a 90² cloth on two threads: 0.41 → 0.23 ms per frame,
/// forced AVX2; on one thread 4 % slower).
pub(crate) const SPLIT_FROM: usize = 4096;

/// The distance constraints cut into domains, plus the links between them.
#[derive(Clone, Debug, Default)]
pub(crate) struct Domains {
    /// Particles per domain (the last may hold fewer).
    size: usize,
    /// The domains, in particle order.
    list: Vec<Domain>,
    /// Links of each internal node of the fork–join tree over the domains, in preorder (a
    /// node, then its left subtree, then its right one, so every subtree is one sub-slice).
    links: Vec<LinkSet>,
    /// Multiplier-step coefficients per parameter group, refreshed every frame.
    coef: Vec<Coef>,
    /// Which optional terms the coefficients need.
    mode: Mode,
    /// Whether each parameter group has a constraint here.
    used: Vec<bool>,
    /// The next pass visits the domains in reverse order (see `Job::reverse`).
    reverse: bool,
}

impl Domains {
    /// Cuts `block` (coloured distance constraints over `n` particles) into domains of at
    /// most `size` particles, solved on kernel path `path`: a power-of-two count of equal
    /// domains (the last may be a few particles short), since the fork–join tree halves the
    /// domains at every node — 10,172 particles in three domains of 4,096, 4,096 and 1,980
    /// left one thread two thirds of the work, in four of 2,544 each half.
    ///
    /// A cloth of [`SPLIT_FROM`] particles or more is cut in two at least, whatever `size`
    /// says, so that two threads share its sweep.
    pub fn new(block: &Block<2, Distance>, n: usize, size: usize, path: SimdPath) -> Self {
        let most = size.clamp(LANES, n.max(LANES)).next_multiple_of(LANES);
        let least = if n >= SPLIT_FROM { 2 } else { 1 };
        let count = n.div_ceil(most).max(least).next_power_of_two();
        let size = n.div_ceil(count).next_multiple_of(LANES).max(LANES);
        let count = n.div_ceil(size).max(1);
        let mut list: Vec<Domain> = (0..count)
            .map(|d| {
                let mut dom = Domain {
                    start: d * size,
                    path,
                    ..Domain::default()
                };
                dom.resize(size.min(n - (d * size).min(n)));
                dom
            })
            .collect();
        let mut links = vec![LinkSet::default(); count - 1];
        let locate = |i: u32| ((i as usize / size) as u32, (i as usize % size) as u32);
        let mut interior: Vec<Vec<Interior>> = vec![Vec::new(); count];
        for k in block.colors.iter().flat_map(|c| c.clone()) {
            let [p, q] = block.particles[k];
            let (dp, dq) = (locate(p), locate(q));
            let (rest, group) = (block.shapes[k].rest, block.group[k]);
            if dp.0 == dq.0 {
                // C and its corrections are symmetric in the two ends: store p < q.
                let (p, q) = (dp.1.min(dq.1), dp.1.max(dq.1));
                interior[dp.0 as usize].push(Interior { p, q, rest, group });
            } else {
                let set = &mut links[tree_node(dp.0 as usize, dq.0 as usize, count)];
                set.ends.push([dp, dq]);
                set.rest.push(rest);
                set.group.push(group);
                set.lambda.push(0.0);
            }
        }
        for (dom, cons) in list.iter_mut().zip(interior) {
            dom.order(cons);
        }
        let mut ends: Vec<Vec<usize>> = vec![Vec::new(); count];
        for &[(dp, ip), (dq, iq)] in links.iter().flat_map(|set| &set.ends) {
            ends[dp as usize].push(ip as usize);
            ends[dq as usize].push(iq as usize);
        }
        for (dom, ends) in list.iter_mut().zip(ends) {
            dom.linked = cover(ends);
        }
        let mut used = Vec::new();
        for &g in &block.group {
            let g = g as usize;
            if used.len() <= g {
                used.resize(g + 1, false);
            }
            used[g] = true;
        }
        Self {
            size,
            list,
            links,
            coef: Vec::new(),
            mode: Mode::default(),
            used,
            reverse: false,
        }
    }

    /// How the distance constraints were laid out.
    pub fn stats(&self) -> DomainStats {
        let mut s = DomainStats {
            domains: self.list.len(),
            domain_size: self.size,
            links: self.links.iter().map(|l| l.rest.len()).sum(),
            simd: self.path(),
            ..DomainStats::default()
        };
        for d in &self.list {
            for c in &d.chunks {
                let live = c.live.count_ones() as usize;
                match c.layout {
                    Layout::Contiguous => s.contiguous += live,
                    Layout::Paired | Layout::Quad | Layout::Spaced | Layout::Strided => {
                        s.strided += live
                    }
                    Layout::Gathered => s.gathered += live,
                }
            }
            for ((_, tail), colour) in d.plan.iter().zip(&d.colours) {
                s.remainder += colour.end - tail;
            }
        }
        s
    }

    /// The kernel path the domains run on.
    pub fn path(&self) -> SimdPath {
        self.list.first().map_or_else(SimdPath::default, |d| d.path)
    }

    /// Runs every domain on kernel path `path` from now on.
    pub fn set_path(&mut self, path: SimdPath) {
        for d in &mut self.list {
            d.path = path;
        }
    }

    /// Which optional terms the current coefficients need.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Sets the per-group coefficients for `rule` (with every group's parameters).
    pub fn prepare(&mut self, params: &[FamilyParams], rule: Rule) {
        self.coef.clear();
        self.mode = Mode::default();
        for p in params {
            let c = Coef::of(p, rule);
            if p.enabled {
                self.mode.damped |= c.gamma > 0.0;
                self.mode.lambda |= c.alpha > 0.0;
            }
            self.coef.push(c);
        }
        let used = |g: usize| self.used.get(g).copied().unwrap_or(false);
        self.mode.unit_k = (self.coef.iter().enumerate()).all(|(g, c)| c.k == 1.0 || !used(g));
    }

    fn project_with<F>(&mut self, before: F)
    where
        F: Fn(&mut Domain, usize) + Sync,
    {
        let Self {
            list,
            links,
            coef,
            mode,
            reverse,
            ..
        } = self;
        let job = Job {
            before: &before,
            coef,
            mode: *mode,
            reverse: std::mem::replace(reverse, !*reverse),
            serial: false,
        };
        fork(list, 0, links, &job);
    }

    /// Clears the link multipliers (the domains clear theirs when integrating).
    pub fn reset_link_multipliers(&mut self) {
        for set in &mut self.links {
            set.lambda.fill(0.0);
        }
    }

    /// One sweep on global arrays: copy in, project domains and links, copy positions out.
    /// `prev` is needed only for XPBD damping. Clears every multiplier first when `fresh`.
    pub fn project_global(&mut self, x: &mut [DVec3], prev: &[DVec3], w: &[f64], fresh: bool) {
        let size = self.size;
        let damped = self.mode.damped;
        if fresh {
            self.reset_link_multipliers();
        }
        // Each domain copies its particles in at its leaf of the fork–join tree, just before
        // its sweep: one parallel pass fewer.
        let (xs, n) = (&*x, x.len());
        self.project_with(|d, index| {
            let r = index * size..((index + 1) * size).min(n);
            if fresh {
                d.pairs.lambda.fill(0.0);
                // The substep's first sweep rebases where the fused integration does.
                d.work.next_origin = prev.get(r.start).map(|p| p.to_array());
            }
            d.load_positions(&xs[r.clone()], damped.then_some(&prev[r.clone()]), &w[r]);
        });
        self.list
            .par_iter_mut()
            .zip(x.par_chunks_mut(size))
            .for_each(|(d, x)| {
                d.settle();
                d.store_positions(x);
            });
    }

    /// Ends a fused frame: velocity update and damping, written out with the positions;
    /// returns whether every position is finite and within `bound` (see [`Domain::finish`]).
    pub fn finish(
        &mut self,
        finish: Finish,
        bound: f64,
        x: &mut [DVec3],
        prev: &mut [DVec3],
        v: &mut [DVec3],
    ) -> bool {
        let size = self.size;
        self.list
            .par_iter_mut()
            .zip(x.par_chunks_mut(size))
            .zip(prev.par_chunks_mut(size))
            .zip(v.par_chunks_mut(size))
            .map(|(((d, x), prev), v)| d.finish(finish, x, prev, v, bound))
            // Not `all`: it would stop finishing the other domains at the first `false`.
            .reduce(|| true, |a, b| a & b)
    }
}
