//! A uniform grid of element boxes for cloth contact's broad phase: a hash table of
//! `(cell, element)` entries, counting-sorted by bucket (each bucket in element order), with
//! the boxes that span too many cells kept apart and tried against every query.
//!
//! A query finds each overlapping pair once: a pair is taken in one cell alone, the one
//! holding the low corner of the two boxes' overlap.

use glam::{DVec3, I64Vec3};

/// An axis-aligned box `(lo, hi)`.
pub(crate) type Aabb = (DVec3, DVec3);

/// A box spanning more cells than this is not binned: every query tries it.
const BIN_LIMIT: f64 = 64.0;

/// A query spanning more cells than this tries every element instead.
const QUERY_LIMIT: f64 = 128.0;

/// A kind's boxes are not changed apart (the caller builds afresh) once the loose ones (boxes
/// changed since the last [`Binned::bin`]) would reach 1 / this of them.
const MOST_LOOSE: usize = 2;

/// One kind of cloth contact's elements (vertices, triangles or edges): each one's box (grown
/// by half the reach) and radius, the grid of the boxes as they were when last binned, and the
/// elements whose box changed since (loose), in a small grid of their own.
#[derive(Clone, Debug, Default)]
pub(crate) struct Binned {
    /// Per element, its box and radius.
    pub boxes: Vec<(Aabb, f64)>,
    /// The grid of the boxes at the last [`Self::bin`].
    pub grid: Grid,
    /// Per element, whether its box changed since the grid was built.
    loose: Vec<bool>,
    /// The loose elements, ascending.
    loose_ids: Vec<u32>,
    /// The grid of the loose elements' boxes (element k is `loose_ids[k]`).
    loose_grid: Grid,
}

impl Binned {
    /// Bins every box afresh in cells of edge `cell` (none loose).
    pub(crate) fn bin(&mut self, cell: f64) {
        self.grid = Grid::new(self.boxes.iter().map(|b| b.0), cell);
        self.loose.clear();
        self.loose.resize(self.boxes.len(), false);
        self.loose_ids.clear();
        self.loose_grid = Grid::default();
    }

    /// Gives the elements `changed` (ascending) the boxes `grown`, binned apart in the loose
    /// grid; false (nothing changed) when the loose ones would reach 1 / [`MOST_LOOSE`] of the
    /// kind: the loose grid is made again at each change, and a build from scratch also gives
    /// every particle a fresh box.
    pub(crate) fn rebox(&mut self, changed: &[u32], grown: Vec<(Aabb, f64)>) -> bool {
        let fresh = changed.iter().filter(|&&e| !self.loose[e as usize]).count();
        if (self.loose_ids.len() + fresh) * MOST_LOOSE >= self.boxes.len().max(1) {
            return false;
        }
        for (&e, b) in changed.iter().zip(grown) {
            self.boxes[e as usize] = b;
            if !self.loose[e as usize] {
                self.loose[e as usize] = true;
                self.loose_ids.push(e);
            }
        }
        self.loose_ids.sort_unstable();
        let boxes = &self.boxes;
        self.loose_grid = Grid::new(
            self.loose_ids.iter().map(|&e| boxes[e as usize].0),
            self.grid.cell,
        );
        true
    }

    /// Calls `f(element)` once with every element from `from` on whose box overlaps `b`:
    /// unchanged ones through the main grid, loose ones through their own.
    #[inline]
    pub(crate) fn query(&self, b: &Aabb, from: u32, mut f: impl FnMut(u32)) {
        let (boxes, loose) = (&self.boxes, &self.loose);
        let at = |g: u32| boxes[g as usize].0;
        self.grid.query(b, from, at, |g| {
            if !loose[g as usize] {
                f(g);
            }
        });
        let ids = &self.loose_ids;
        let first = ids.partition_point(|&g| g < from) as u32;
        (self.loose_grid).query(b, first, |k| at(ids[k as usize]), |k| f(ids[k as usize]));
    }
}

/// Element boxes binned by the cells they touch.
#[derive(Clone, Debug, Default)]
pub(crate) struct Grid {
    /// The cell's edge (m).
    pub cell: f64,
    /// How many elements were binned (or kept apart).
    count: u32,
    /// Bits of the bucket index.
    bits: u32,
    /// Where each bucket's entries start (one more for the end).
    starts: Vec<u32>,
    entries: Vec<(u64, u32)>,
    /// Elements tried against every query, ascending.
    big: Vec<u32>,
    /// Per element, the cell of its box's low corner (binned elements only).
    low: Vec<I64Vec3>,
}

impl Grid {
    /// Bins `boxes` (element k's box is `boxes[k]`) in cells of edge `cell`.
    pub(crate) fn new(boxes: impl ExactSizeIterator<Item = Aabb>, cell: f64) -> Self {
        let mut grid = Self {
            cell: cell.max(1e-6),
            count: boxes.len() as u32,
            ..Self::default()
        };
        let mut raw = Vec::with_capacity(boxes.len() * 8);
        grid.low = vec![I64Vec3::ZERO; boxes.len()];
        for (k, b) in boxes.enumerate() {
            match grid.span(&b, BIN_LIMIT) {
                Span::Cells(lo, hi) => {
                    grid.low[k] = lo;
                    raw.extend(cells(lo, hi).map(|c| (key(c), k as u32)));
                }
                Span::Many => grid.big.push(k as u32),
                Span::None => {}
            }
        }
        grid.bits = raw.len().max(16).next_power_of_two().trailing_zeros();
        let mut starts = vec![0u32; (1 << grid.bits) + 1];
        for &(k, _) in &raw {
            starts[grid.bucket(k) + 1] += 1;
        }
        for b in 1..starts.len() {
            starts[b] += starts[b - 1];
        }
        let mut fill = starts.clone();
        grid.entries = vec![(0, 0); raw.len()];
        for &(k, e) in &raw {
            let b = grid.bucket(k);
            grid.entries[fill[b] as usize] = (k, e);
            fill[b] += 1;
        }
        grid.starts = starts;
        grid
    }

    /// The mean of the largest extent of each finite box: a cell size about as large as the
    /// boxes.
    pub(crate) fn mean_extent(boxes: impl Iterator<Item = Aabb>) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for (lo, hi) in boxes {
            let s = (hi - lo).max_element();
            n += 1;
            if s.is_finite() {
                sum += s;
            }
        }
        sum / n.max(1) as f64
    }

    /// The bucket of cell key `k`.
    #[inline]
    fn bucket(&self, k: u64) -> usize {
        (k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.bits)) as usize
    }

    /// The cells box `b` touches, if at most `limit`.
    fn span(&self, b: &Aabb, limit: f64) -> Span {
        let (lo, hi) = ((b.0 / self.cell).floor(), (b.1 / self.cell).floor());
        if !(lo.is_finite() && hi.is_finite()) {
            return Span::None;
        }
        let count = (hi - lo + DVec3::ONE).element_product();
        if count > limit {
            Span::Many
        } else {
            Span::Cells(lo.as_i64vec3(), hi.as_i64vec3())
        }
    }

    /// The elements binned in cell `c` from `from` on, ascending.
    #[inline]
    fn bin(&self, c: I64Vec3, from: u32) -> impl Iterator<Item = u32> + '_ {
        let k = key(c);
        let b = self.bucket(k);
        let bucket = &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize];
        (bucket.iter())
            .filter(move |&&(e, g)| e == k && g >= from)
            .map(|&(_, g)| g)
    }

    /// Calls `f(element)` once with every element from `from` on whose box (`boxes(element)`)
    /// overlaps `b` (touching counts).
    #[inline]
    pub(crate) fn query(
        &self,
        b: &Aabb,
        from: u32,
        boxes: impl Fn(u32) -> Aabb,
        mut f: impl FnMut(u32),
    ) {
        if self.count == 0 {
            return;
        }
        match self.span(b, QUERY_LIMIT) {
            Span::Cells(lo, hi) => {
                // A pair's home: the cell of its boxes' overlap's low corner, the larger of
                // their low corners' cells on each axis (the floor is monotonic). In a single
                // cell every overlapping pair has it as its home.
                let one = lo == hi;
                for c in cells(lo, hi) {
                    for g in self.bin(c, from) {
                        let home = one || lo.max(self.low[g as usize]) == c;
                        if home && overlap(b, &boxes(g)) {
                            f(g);
                        }
                    }
                }
                let start = self.big.partition_point(|&g| g < from);
                for &g in &self.big[start..] {
                    if overlap(b, &boxes(g)) {
                        f(g);
                    }
                }
            }
            Span::Many => (from..self.count)
                .filter(|&g| overlap(b, &boxes(g)))
                .for_each(f),
            Span::None => {}
        }
    }
}

/// Whether two boxes overlap (touching counts).
#[inline]
pub(crate) fn overlap(a: &Aabb, b: &Aabb) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

/// How many cells a box touches.
enum Span {
    /// Those from the first to the last (inclusive on every axis).
    Cells(I64Vec3, I64Vec3),
    /// Too many.
    Many,
    /// None: the box is not a number.
    None,
}

/// The cells from `a` to `b` (inclusive on every axis).
fn cells(a: I64Vec3, b: I64Vec3) -> impl Iterator<Item = I64Vec3> {
    (a.x..=b.x).flat_map(move |x| {
        (a.y..=b.y).flat_map(move |y| (a.z..=b.z).map(move |z| I64Vec3::new(x, y, z)))
    })
}

/// A cell's key: 21 bits of each coordinate (cells that share a key share a bin, which costs
/// a box test, never a pair).
fn key(c: I64Vec3) -> u64 {
    let m = (1u64 << 21) - 1;
    ((c.x as u64) & m) | (((c.y as u64) & m) << 21) | (((c.z as u64) & m) << 42)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_query_finds_each_overlapping_box_once() {
        // Boxes of mixed sizes along a diagonal, one far too big to bin.
        let mut boxes: Vec<Aabb> = (0..40)
            .map(|k| {
                let c = DVec3::splat(k as f64 * 0.013);
                let h = DVec3::splat(0.004 + 0.006 * (k % 3) as f64);
                (c - h, c + h)
            })
            .collect();
        boxes.push((DVec3::splat(-5.0), DVec3::splat(5.0)));
        let grid = Grid::new(boxes.iter().copied(), 0.01);
        for (q, qb) in boxes.iter().enumerate() {
            let mut got = Vec::new();
            grid.query(qb, 3, |g| boxes[g as usize], |g| got.push(g));
            got.sort_unstable();
            let want: Vec<u32> = (3..boxes.len() as u32)
                .filter(|&g| overlap(qb, &boxes[g as usize]))
                .collect();
            assert_eq!(got, want, "query {q}");
        }
        assert_eq!(Grid::default().count, 0);
        let mut none = 0;
        Grid::default().query(&boxes[0], 0, |g| boxes[g as usize], |_| none += 1);
        assert_eq!(none, 0);
    }
}
