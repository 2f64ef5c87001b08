//! Points sorted by grid cell, for finding every close pair in one sequential sweep (the
//! sorted cell list of Green, "Particle Simulation using CUDA", NVIDIA 2010, walked on the CPU
//! with one forward-only cursor per neighbour column instead of hashed look-ups).
//!
//! [`keys`] packs a cell into a key that sorts in cell order; this file builds and updates a
//! [`CellGrid`]; [`search`] walks it for close pairs and for the neighbours of query points.

mod keys;
mod search;
#[cfg(test)]
mod tests;

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use keys::{Compact, cell_key, radix_sort};

/// Points sorted by grid cell (x, then y, then z) for [`CellGrid::for_each_pair`].
#[derive(Clone, Debug, Default)]
pub(crate) struct CellGrid {
    spacing: f64,
    /// (cell key, item) in key order.
    sorted: Vec<(u64, u32)>,
    /// Positions in key order.
    positions: Vec<DVec3>,
    /// Each item's tag in key order (see [`CellGrid::tag`]); empty until tagged after a build.
    tags: Vec<DVec3>,
    /// Scratch of [`CellGrid::update`]: the moved items' keys, the old order and positions,
    /// and a flag per item leaving its place (all false between calls).
    fresh: Vec<(u64, u32)>,
    old: Vec<(u64, u32)>,
    old_positions: Vec<DVec3>,
    leaving: Vec<bool>,
    /// Scratch of [`CellGrid::build`]'s radix sort: (compact key, index) and its copy.
    radix: Vec<u64>,
    radix_copy: Vec<u64>,
}

/// Fewest items per rayon task in the grid's parallel loops (smaller ones cost more to hand
/// to another thread than to do).
const PAR_MIN: usize = 2048;

/// Query points in cell order for [`CellGrid::for_each_near_all`], for every grid of one cell
/// size: sorted once, they serve several grids.
#[derive(Clone, Debug, Default)]
pub(crate) struct Queries {
    spacing: f64,
    /// (cell key, index of the point) in key order.
    order: Vec<(u64, u32)>,
}

impl Queries {
    /// Sorts `points` by their cell of size `spacing` (m).
    pub(crate) fn sort(&mut self, points: &[DVec3], spacing: f64) {
        self.spacing = spacing;
        let inv = 1.0 / spacing;
        self.order.clear();
        self.order.extend(
            points
                .iter()
                .enumerate()
                .map(|(k, &p)| (cell_key(p, inv), k as u32)),
        );
        self.order.sort_unstable();
    }
}

impl CellGrid {
    /// Sorts `items` (indices into `positions`) by their cell of size `spacing` (m), then by
    /// index; the order is a function of the positions alone.
    ///
    /// Keys are computed in the items' order. When the items ascend and the cells in use fit a
    /// 32-bit compact key ([`Compact`]), a stable radix sort on it ([`radix_sort`]: equal cells
    /// keep the items' order) replaces a comparison sort of the (key, item) entries, which
    /// took longer.
    pub(crate) fn build(&mut self, positions: &[DVec3], items: &[u32], spacing: f64) {
        self.spacing = spacing;
        self.tags.clear();
        let inv = 1.0 / spacing;
        let mut fresh = std::mem::take(&mut self.fresh);
        // Keys and positions on rayon's threads: besides the time, each thread then has the
        // positions it will search in its own cache.
        fresh.resize(items.len(), (0, 0));
        fresh
            .par_iter_mut()
            .zip(items.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(out, &i)| *out = (cell_key(positions[i as usize], inv), i));
        let ascending = items.windows(2).all(|w| w[0] < w[1]);
        let compact = if ascending && items.len() <= u32::MAX as usize {
            Compact::of(fresh.iter().map(|&(key, _)| key))
        } else {
            None
        };
        self.sorted.clear();
        match compact {
            Some(compact) => {
                let (mut src, mut dst) = (
                    std::mem::take(&mut self.radix),
                    std::mem::take(&mut self.radix_copy),
                );
                src.clear();
                src.extend(
                    fresh
                        .iter()
                        .enumerate()
                        .map(|(k, &(key, _))| (compact.apply(key) << 32) | k as u64),
                );
                radix_sort(&mut src, &mut dst, compact.bits);
                self.sorted.resize(src.len(), (0, 0));
                self.sorted
                    .par_iter_mut()
                    .zip(src.par_iter())
                    .with_min_len(PAR_MIN)
                    .for_each(|(out, &v)| *out = fresh[(v & 0xffff_ffff) as usize]);
                (self.radix, self.radix_copy) = (src, dst);
            }
            None => {
                // Keys are unique with their item, so an unstable sort gives the one order.
                fresh.sort_unstable();
                self.sorted.extend_from_slice(&fresh);
            }
        }
        self.fresh = fresh;
        in_key_order(&mut self.positions, &self.sorted, positions);
    }

    /// Gives each item of the last build its tag `tags[item]`, a second point that
    /// [`CellGrid::for_each_row_in`] requires pairs to be apart in. A build drops the tags.
    pub(crate) fn tag(&mut self, tags: &[DVec3]) {
        in_key_order(&mut self.tags, &self.sorted, tags);
    }

    /// Moves `moved` (items, each given once) to their cells at `positions`: those already in
    /// the grid (for which `present` holds) leave their old cells, and every other item keeps
    /// its place. When the others have not moved since they were placed, the result is the
    /// grid [`CellGrid::build`] would give for the union at `positions`, for the cost of
    /// sorting `moved` and one merge.
    pub(crate) fn update(
        &mut self,
        positions: &[DVec3],
        moved: &[u32],
        present: impl Fn(u32) -> bool,
    ) {
        let inv = 1.0 / self.spacing;
        self.tags.clear();
        let mut fresh = std::mem::take(&mut self.fresh);
        fresh.clear();
        fresh.extend(
            moved
                .iter()
                .map(|&i| (cell_key(positions[i as usize], inv), i)),
        );
        fresh.sort_unstable();
        // The old order and positions, swapped out into the scratch buffers.
        let (mut old, mut old_pos) = (
            std::mem::take(&mut self.old),
            std::mem::take(&mut self.old_positions),
        );
        std::mem::swap(&mut old, &mut self.sorted);
        std::mem::swap(&mut old_pos, &mut self.positions);
        self.sorted.clear();
        self.positions.clear();
        // The moved items that were present leave their old places.
        let top = moved.iter().map(|&i| i as usize + 1).max().unwrap_or(0);
        if self.leaving.len() < top {
            self.leaving.resize(top, false);
        }
        for &i in moved {
            self.leaving[i as usize] = present(i);
        }
        let leaving = &self.leaving;
        let stays = |i: u32| !leaving.get(i as usize).copied().unwrap_or(false);
        let (mut a, mut b) = (0, 0);
        loop {
            while a < old.len() && !stays(old[a].1) {
                a += 1;
            }
            let take_old = match (old.get(a), fresh.get(b)) {
                (Some(o), Some(f)) => o < f,
                (Some(_), None) => true,
                (None, Some(_)) => false,
                (None, None) => break,
            };
            if take_old {
                self.sorted.push(old[a]);
                self.positions.push(old_pos[a]);
                a += 1;
            } else {
                self.sorted.push(fresh[b]);
                self.positions.push(positions[fresh[b].1 as usize]);
                b += 1;
            }
        }
        for &i in moved {
            self.leaving[i as usize] = false;
        }
        (self.fresh, self.old, self.old_positions) = (fresh, old, old_pos);
    }

    /// The (cell key, item) entries in key order and their positions.
    #[cfg(test)]
    pub(crate) fn entries(&self) -> (&[(u64, u32)], &[DVec3]) {
        (&self.sorted, &self.positions)
    }

    /// Splits the sorted items into about `parts` runs of whole cells, for
    /// [`CellGrid::for_each_pair_in`] on several threads.
    pub(crate) fn cell_runs(&self, parts: usize) -> Vec<Range<usize>> {
        let n = self.sorted.len();
        let parts = parts.clamp(1, n.max(1));
        let mut runs = Vec::with_capacity(parts);
        let mut start = 0;
        for k in 1..=parts {
            let mut end = if k == parts {
                n
            } else {
                (n * k / parts).max(start)
            };
            // Move the cut to the end of the cell it falls in.
            while end < n && end > 0 && self.sorted[end].0 == self.sorted[end - 1].0 {
                end += 1;
            }
            if end > start {
                runs.push(start..end);
                start = end;
            }
        }
        runs
    }

    /// Cell size of the last build (m).
    pub(crate) fn spacing(&self) -> f64 {
        self.spacing
    }
}

/// Fills `out` with `values[item]` for each (key, item) of `sorted`, on rayon's threads.
fn in_key_order(out: &mut Vec<DVec3>, sorted: &[(u64, u32)], values: &[DVec3]) {
    out.resize(sorted.len(), DVec3::ZERO);
    out.par_iter_mut()
        .zip(sorted.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(out, &(_, i))| *out = values[i as usize]);
}
