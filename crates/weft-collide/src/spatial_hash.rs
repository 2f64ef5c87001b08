//! Grids of points for neighbour searches.
//!
//! [`SpatialHash`]: dense spatial hashing, after Müller's "Ten Minute Physics" #11
//! (self-collision): cells of a fixed spacing hashed into a power-of-two table of at least 2N
//! buckets, stored as counting-sorted `cell_start` / `cell_entries` arrays: no allocation per
//! cell, and no `HashMap` whose iteration order could leak into results.
//!
//! [`CellGrid`]: points sorted by cell, for finding every close pair in one sequential sweep
//! (the sorted cell list of Green, "Particle Simulation using CUDA", NVIDIA 2010, walked on
//! the CPU with one forward-only cursor per neighbour column instead of hashed look-ups).

use std::ops::Range;

use glam::DVec3;
use multiversion::multiversion;
use rayon::prelude::*;

/// Points bucketed by hashed grid cell.
#[derive(Clone, Debug, Default)]
pub struct SpatialHash {
    spacing: f64,
    /// Table size − 1 (the table size is a power of two).
    mask: usize,
    cell_start: Vec<u32>,
    cell_entries: Vec<u32>,
}

impl SpatialHash {
    /// An empty hash with cell size `spacing` (m).
    pub fn new(spacing: f64) -> Self {
        Self {
            spacing,
            ..Self::default()
        }
    }

    /// Empties the hash and sets its cell size to `spacing` (m), keeping its storage.
    pub fn reset(&mut self, spacing: f64) {
        self.spacing = spacing;
        self.cell_start.clear();
        self.cell_entries.clear();
    }

    /// Cell size (m).
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    fn cell(&self, p: DVec3) -> [i32; 3] {
        (p / self.spacing).floor().as_ivec3().to_array()
    }

    fn bucket(&self, [x, y, z]: [i32; 3]) -> usize {
        // The large primes of Teschner et al. 2003, "Optimized Spatial Hashing for Collision
        // Detection of Deformable Objects", as used by Müller.
        let h =
            x.wrapping_mul(92_837_111) ^ y.wrapping_mul(689_287_499) ^ z.wrapping_mul(283_923_481);
        h as u32 as usize & self.mask
    }

    /// Rebuilds the table over `items` (indices into `positions`), keeping their order per bucket.
    pub fn build(&mut self, positions: &[DVec3], items: &[u32]) {
        let table = (2 * items.len()).max(2).next_power_of_two();
        self.mask = table - 1;
        self.cell_start.clear();
        self.cell_start.resize(table + 1, 0);
        self.cell_entries.clear();
        self.cell_entries.resize(items.len(), 0);
        for &i in items {
            let b = self.bucket(self.cell(positions[i as usize]));
            self.cell_start[b] += 1;
        }
        // Exclusive prefix sums give each bucket's end; filling backwards then leaves the start.
        let mut sum = 0;
        for s in &mut self.cell_start {
            sum += *s;
            *s = sum;
        }
        for &i in items.iter().rev() {
            let b = self.bucket(self.cell(positions[i as usize]));
            self.cell_start[b] -= 1;
            self.cell_entries[self.cell_start[b] as usize] = i;
        }
    }

    /// Writes to `out` every item whose cell overlaps the cube of half-size `radius` around
    /// `p` (a superset of the items within `radius`), each once, in a fixed order.
    pub fn query(&self, p: DVec3, radius: f64, out: &mut Vec<u32>) {
        out.clear();
        if self.cell_entries.is_empty() {
            return;
        }
        let lo = self.cell(p - DVec3::splat(radius));
        let hi = self.cell(p + DVec3::splat(radius));
        // Two cells in range may hash to one bucket: visit each bucket once.
        let mut seen = [usize::MAX; 64];
        let mut count = 0;
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let b = self.bucket([x, y, z]);
                    if seen[..count.min(64)].contains(&b) {
                        continue;
                    }
                    if count < 64 {
                        seen[count] = b;
                    } else {
                        // A huge radius against the spacing: fall back to sorting below.
                        count = usize::MAX;
                    }
                    count = count.saturating_add(1);
                    let (s, e) = (self.cell_start[b], self.cell_start[b + 1]);
                    out.extend_from_slice(&self.cell_entries[s as usize..e as usize]);
                }
            }
        }
        if count == usize::MAX {
            out.sort_unstable();
            out.dedup();
        }
    }
}

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

/// Bits of a digit of [`CellGrid::build`]'s radix sort.
const DIGIT: u32 = 11;

/// Sorts `v` stably by its high 32 bits, of which only the low `bits` may be set: a
/// least-significant-digit radix sort, one counting pass and one scatter per [`DIGIT`] bits
/// (Knuth, TAOCP vol. 3, §5.2.5). `copy` is scratch.
fn radix_sort(v: &mut Vec<u64>, copy: &mut Vec<u64>, bits: u32) {
    copy.resize(v.len(), 0);
    let mut shift = 32;
    while shift < 32 + bits {
        let digit = |x: u64| ((x >> shift) & ((1 << DIGIT) - 1)) as usize;
        let mut start = [0usize; 1 << DIGIT];
        for &x in v.iter() {
            start[digit(x)] += 1;
        }
        let mut sum = 0;
        for s in &mut start {
            (*s, sum) = (sum, sum + *s);
        }
        for &x in v.iter() {
            let d = digit(x);
            copy[start[d]] = x;
            start[d] += 1;
        }
        std::mem::swap(v, copy);
        shift += DIGIT;
    }
}

/// Keys made compact to the box of the cells in use: a cell's offsets from the box's lowest
/// cell, packed x, y, z with just the bits each needs, so that they sort as the keys do.
#[derive(Clone, Copy, Debug)]
struct Compact {
    lo: [u64; 3],
    /// Shifts of x and y in the compact key (z is not shifted).
    shift: [u32; 2],
    /// Bits of the compact key.
    bits: u32,
}

impl Compact {
    /// The packing for `keys`, or `None` when it needs more than 32 bits.
    fn of(keys: impl Iterator<Item = u64>) -> Option<Self> {
        let (mut lo, mut hi) = ([u64::MAX; 3], [0u64; 3]);
        for key in keys {
            for (axis, v) in Self::fields(key).into_iter().enumerate() {
                lo[axis] = lo[axis].min(v);
                hi[axis] = hi[axis].max(v);
            }
        }
        let width = |a: usize| {
            (hi[a].saturating_sub(lo[a]))
                .checked_ilog2()
                .map_or(0, |b| b + 1)
        };
        let (wx, wy, wz) = (width(0), width(1), width(2));
        let bits = wx + wy + wz;
        (bits <= 32).then_some(Self {
            lo,
            shift: [wy + wz, wz],
            bits,
        })
    }

    /// A key's x, y and z cell coordinates.
    fn fields(key: u64) -> [u64; 3] {
        let mask = (1 << BITS) - 1;
        [key >> (2 * BITS), (key >> BITS) & mask, key & mask]
    }

    /// The compact form of `key` (a key of the cells the packing was made for).
    fn apply(&self, key: u64) -> u64 {
        let [x, y, z] = Self::fields(key);
        ((x - self.lo[0]) << self.shift[0]) | ((y - self.lo[1]) << self.shift[1]) | (z - self.lo[2])
    }
}

/// Bits per cell coordinate in a cell key.
const BITS: u32 = 21;
/// Key steps of one cell along y and along x (z is 1).
const Y: u64 = 1 << BITS;
const X: u64 = 1 << (2 * BITS);

/// The key of the cell holding `p`: its coordinates, offset to be positive and clamped to
/// 1..2²¹ − 2, packed x, y, z from the high bits, so that key order is lexicographic cell
/// order and a neighbour's key is the key ± 1, ± Y, ± X. Clamping is 1-Lipschitz: cells that
/// are neighbours stay neighbours (or merge), so no close pair is lost; only points more than
/// 2²⁰ cells from the origin share border cells.
///
/// The floor is taken without `f64::floor`, a call into libm on the baseline x86-64 target,
/// and without converting an integer back to a float (whose false dependency on the target
/// register chained every key): the coordinate is clamped to ±2²¹ cells (beyond which every
/// key component is clamped anyway), rounded to an integer by adding and subtracting
/// 1.5 · 2⁵² (exact there: the unit in the last place is 1; Rust never reassociates the two),
/// and stepped down where that rounded up. A NaN coordinate converts to 0: such points
/// gather in one cell.
#[inline]
fn cell_key(p: DVec3, inv_spacing: f64) -> u64 {
    const LIMIT: f64 = (1u64 << (BITS)) as f64;
    const ROUND: f64 = 1.5 * (1u64 << 52) as f64;
    let half = 1i64 << (BITS - 1);
    let max = (1i64 << BITS) - 2;
    let k = |v: f64| {
        let v = (v * inv_spacing).clamp(-LIMIT, LIMIT);
        let r = (v + ROUND) - ROUND;
        let floor = if r > v { r - 1.0 } else { r };
        (floor as i64 + half).clamp(1, max) as u64
    };
    (k(p.x) << (2 * BITS)) | (k(p.y) << BITS) | k(p.z)
}

/// Neighbour columns (dx, dy) after a cell's own in key order, each visited over
/// dz ∈ −1..=1: with the cell itself and the cell above it (0, 0, +1) they are the 13
/// lexicographically positive neighbours, so each pair of neighbouring cells is visited once.
/// As key offsets from (x, y, z) to (x + dx, y + dy, z − 1).
const COLUMNS: [u64; 4] = [Y - 1, X - Y - 1, X - 1, X + Y - 1];

/// All nine neighbour columns (dx, dy ∈ −1..=1) in key order, as key offsets from
/// (x − 1, y − 1, z − 1) to (x + dx, y + dy, z − 1).
const NEAR_COLUMNS: [u64; 9] = [
    0,
    Y,
    2 * Y,
    X,
    X + Y,
    X + 2 * Y,
    2 * X,
    2 * X + Y,
    2 * X + 2 * Y,
];

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
    /// An empty grid.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// Sorts `items` (indices into `positions`) by their cell of size `spacing` (m), then by
    /// index; the order is a function of the positions alone.
    ///
    /// Keys are computed in the items' order. When the items ascend and the cells in use fit a
    /// 32-bit compact key ([`Compact`]), a stable radix sort on it ([`radix_sort`]: equal cells
    /// keep the items' order) replaces a comparison sort of the (key, item) entries: for a
    /// 128² curtain or drape mid-fall the grid took 347–434 µs on one thread and 172–216 µs
    /// on two, now 204–240 µs and 146–191 µs.
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

    /// Calls `f(k, i)` for every query point `points[k]` and every built item `i` at most
    /// `radius` (≤ spacing) from it; `queries` are the points sorted for this grid's cell size.
    /// `row` is scratch.
    ///
    /// The queries are taken in key order, so that the start of each of the nine neighbour
    /// columns (x + dx, y + dy, z − 1..=z + 1) only moves forward from one query to the next:
    /// one cursor per column gallops on from where it stopped (Bentley and Yao 1976). A batch
    /// of queries then costs a few steps each, where a search per query from scratch would
    /// cross the grid nine times.
    pub(crate) fn for_each_near_all(
        &self,
        points: &[DVec3],
        queries: &Queries,
        radius: f64,
        row: &mut Vec<u32>,
        mut f: impl FnMut(usize, u32),
    ) {
        assert!(
            radius <= self.spacing,
            "query radius {radius} exceeds the cell size {}",
            self.spacing
        );
        assert_eq!(
            queries.spacing, self.spacing,
            "queries sorted for another cell size"
        );
        let r2 = radius * radius;
        let (cells, pos) = (&self.sorted, &self.positions);
        let mut cursors = [0usize; NEAR_COLUMNS.len()];
        for &(key, k) in &queries.order {
            let p = points[k as usize];
            // Cell coordinates are at least 1, so the lowest column start does not wrap.
            let base = key - X - Y - 1;
            row.clear();
            for (cursor, offset) in cursors.iter_mut().zip(NEAR_COLUMNS) {
                let lo = base + offset;
                *cursor = gallop(cells, *cursor, lo);
                let end = column_end(cells, *cursor, lo + 2);
                let items = cells[*cursor..end].iter().map(|&(_, i)| i);
                near_into(row, p, r2, items, &pos[*cursor..end]);
            }
            for &i in row.iter() {
                f(k as usize, i);
            }
        }
    }

    /// Calls `f(i, j)` once for every unordered pair {i, j} of built items at most `radius`
    /// apart (`radius` must not exceed the spacing) whose tags are more than `apart` apart;
    /// which comes first, and the order of the calls, depend on the positions alone.
    #[cfg(test)]
    pub(crate) fn for_each_pair(&self, radius: f64, apart: f64, f: impl FnMut(u32, u32)) {
        self.for_each_pair_in(0..self.sorted.len(), radius, apart, f);
    }

    /// [`CellGrid::for_each_pair`] for the pairs whose first point (in key order) lies in
    /// `run`, a run of whole cells from [`CellGrid::cell_runs`]: the runs of a split together
    /// give every pair once.
    #[cfg(test)]
    pub(crate) fn for_each_pair_in(
        &self,
        run: Range<usize>,
        radius: f64,
        apart: f64,
        mut f: impl FnMut(u32, u32),
    ) {
        let mut row = Vec::new();
        self.for_each_row_in(run, radius, apart, &mut row, |i, near| {
            for &j in near {
                f(i, j);
            }
        });
    }

    /// [`CellGrid::for_each_pair_in`] one point at a time: calls `f(i, near)` for each point
    /// `i` of `run` with a partner, `near` being its partners that come after it in key
    /// order (so that each pair comes once). Only partners whose tags are more than `apart`
    /// from i's count (the grid must be tagged). `row` is scratch.
    ///
    /// With `radius` ≤ spacing two such points lie in the same or neighbouring cells. Walking
    /// the cells in key order, the cells of a neighbour column (x + dx, y + dy, z − 1..=z + 1)
    /// form one contiguous run whose start only moves forward, so one cursor per column finds
    /// it without any search after the first cell. Each cell's candidates are copied together
    /// once, so that a point tests them in one pass rather than one per column: a sheet lying
    /// across the cells obliquely has a few candidates in each column, and a pass per column
    /// cost more than its tests. The distance tests do not branch: about one candidate in four
    /// is a partner, a branch there was mispredicted on every fourth test and took most of a
    /// rebuild's time.
    pub(crate) fn for_each_row_in(
        &self,
        run: Range<usize>,
        radius: f64,
        apart: f64,
        row: &mut Vec<u32>,
        mut f: impl FnMut(u32, &[u32]),
    ) {
        assert!(
            radius <= self.spacing,
            "pair radius {radius} exceeds the cell size {}",
            self.spacing
        );
        assert_eq!(self.tags.len(), self.sorted.len(), "the grid is not tagged");
        let (r2, apart2) = (radius * radius, apart * apart);
        let (cells, pos, tags) = (&self.sorted, &self.positions, &self.tags);
        let n = cells.len();
        let mut cursors = [0usize; COLUMNS.len()];
        if let Some(&(first, _)) = cells.get(run.start) {
            for (cursor, offset) in cursors.iter_mut().zip(COLUMNS) {
                *cursor = cells.partition_point(|&(k, _)| k < first + offset);
            }
        }
        let mut near = Candidates::default();
        let mut s = run.start;
        while s < run.end {
            let c = cells[s].0;
            let mut e = s + 1;
            while e < n && cells[e].0 == c {
                e += 1;
            }
            // The cell itself, the cell above (the next run, if occupied), then the columns.
            let mut y = e;
            while y < n && cells[y].0 == c + 1 {
                y += 1;
            }
            // The cell's candidates gathered once, in key order (the cell and the cell above
            // are contiguous), so that each point tests those after it in one pass.
            near.clear();
            near.extend(&cells[s..y], &pos[s..y], &tags[s..y]);
            for (cursor, offset) in cursors.iter_mut().zip(COLUMNS) {
                let lo = c + offset;
                while *cursor < n && cells[*cursor].0 < lo {
                    *cursor += 1;
                }
                let end = column_end(cells, *cursor, lo + 2);
                let range = *cursor..end;
                near.extend(&cells[range.clone()], &pos[range.clone()], &tags[range]);
            }
            for x in s..e {
                row.clear();
                near.within(x - s + 1, (pos[x], tags[x]), (r2, apart2), row);
                if !row.is_empty() {
                    f(cells[x].1, row);
                }
            }
            s = e;
        }
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

/// The first index at or after `from` whose key exceeds `last` (a column's cells run to
/// `last`; they are few, so a linear scan).
fn column_end(cells: &[(u64, u32)], from: usize, last: u64) -> usize {
    let mut end = from;
    while end < cells.len() && cells[end].0 <= last {
        end += 1;
    }
    end
}

/// The first index at or after `from` whose key is at least `key` (`cells` sorted by key):
/// exponential steps forward, then a binary search in the last step (which also covers a
/// `from` already at or past `key`).
fn gallop(cells: &[(u64, u32)], from: usize, key: u64) -> usize {
    let mut step = 1;
    let mut lo = from;
    while lo + step < cells.len() && cells[lo + step].0 < key {
        lo += step;
        step *= 2;
    }
    let hi = (lo + step + 1).min(cells.len());
    lo + cells[lo..hi].partition_point(|&(k, _)| k < key)
}

/// Appends to `row` the `items` whose position (in `pos`, one each) is at most √`r2` from
/// `p`, without a branch per item.
#[inline(always)]
fn near_into(
    row: &mut Vec<u32>,
    p: DVec3,
    r2: f64,
    items: impl ExactSizeIterator<Item = u32>,
    pos: &[DVec3],
) {
    let start = row.len();
    row.resize(start + items.len(), 0);
    let out = &mut row[start..];
    let mut n = 0;
    for (item, q) in items.zip(pos) {
        out[n] = item;
        n += usize::from(p.distance_squared(*q) <= r2);
    }
    row.truncate(start + n);
}

/// A cell's candidates for [`CellGrid::for_each_row_in`]: items, positions and tags as
/// struct-of-arrays, so that the distance tests run as vector operations.
#[derive(Default)]
struct Candidates {
    ids: Vec<u32>,
    pos: [Vec<f64>; 3],
    tags: [Vec<f64>; 3],
    /// Scratch: whether each candidate passed.
    keep: Vec<u8>,
}

impl Candidates {
    fn clear(&mut self) {
        self.ids.clear();
        self.pos
            .iter_mut()
            .chain(&mut self.tags)
            .for_each(Vec::clear);
    }

    /// Appends the items of `cells` at `pos` with their `tags`.
    fn extend(&mut self, cells: &[(u64, u32)], pos: &[DVec3], tags: &[DVec3]) {
        self.ids.extend(cells.iter().map(|&(_, i)| i));
        for (soa, points) in [(&mut self.pos, pos), (&mut self.tags, tags)] {
            for (c, out) in soa.iter_mut().enumerate() {
                out.extend(points.iter().map(|p| p[c]));
            }
        }
    }

    /// Appends to `row` the candidates from index `from` on that lie at most √r2 from `p` and
    /// whose tag lies more than √apart2 from `tag`.
    fn within(
        &mut self,
        from: usize,
        (p, tag): (DVec3, DVec3),
        (r2, apart2): (f64, f64),
        row: &mut Vec<u32>,
    ) {
        let len = self.ids.len().saturating_sub(from);
        self.keep.resize(len, 0);
        fn at(v: &[Vec<f64>; 3], from: usize) -> [&[f64]; 3] {
            [&v[0][from..], &v[1][from..], &v[2][from..]]
        }
        mark_near_apart(
            &mut self.keep,
            (at(&self.pos, from), at(&self.tags, from)),
            (p.to_array(), tag.to_array()),
            (r2, apart2),
        );
        // Compaction without a branch per candidate (about one in four passes).
        let start = row.len();
        row.resize(start + len, 0);
        let out = &mut row[start..];
        let mut n = 0;
        for (&id, &k) in self.ids[from..].iter().zip(&self.keep) {
            out[n] = id;
            n += usize::from(k);
        }
        row.truncate(start + n);
    }
}

/// `keep[k]` = whether point k of `pos` lies at most √`r2` from `p` and its tag (in `tags`)
/// more than √`apart2` from `q` (both struct-of-arrays).
#[multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512dq+avx2+fma",
    "x86_64+avx2+fma",
    "aarch64+neon"
))]
fn mark_near_apart(
    keep: &mut [u8],
    (pos, tags): ([&[f64]; 3], [&[f64]; 3]),
    (p, q): ([f64; 3], [f64; 3]),
    (r2, apart2): (f64, f64),
) {
    let n = keep.len();
    let (xs, ys, zs) = (&pos[0][..n], &pos[1][..n], &pos[2][..n]);
    let (ts, us, vs) = (&tags[0][..n], &tags[1][..n], &tags[2][..n]);
    for k in 0..n {
        let (dx, dy, dz) = (xs[k] - p[0], ys[k] - p[1], zs[k] - p[2]);
        let (ex, ey, ez) = (ts[k] - q[0], us[k] - q[1], vs[k] - q[2]);
        let near = dx * dx + dy * dy + dz * dz <= r2;
        let apart = ex * ex + ey * ey + ez * ez > apart2;
        keep[k] = u8::from(near & apart);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rand;

    #[test]
    fn query_finds_every_point_within_radius() {
        let positions: Vec<DVec3> = (0..500)
            .map(|i| {
                let f = i as f64;
                DVec3::new((f * 0.37).sin(), (f * 0.71).cos(), (f * 0.13).sin()) * 0.5
            })
            .collect();
        let items: Vec<u32> = (0..500).collect();
        let mut hash = SpatialHash::new(0.05);
        hash.build(&positions, &items);
        let mut out = Vec::new();
        for (i, p) in positions.iter().enumerate() {
            hash.query(*p, 0.05, &mut out);
            let mut sorted = out.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), out.len(), "repeats for {i}");
            for (j, q) in positions.iter().enumerate() {
                if p.distance(*q) <= 0.05 {
                    assert!(sorted.binary_search(&(j as u32)).is_ok(), "{i} misses {j}");
                }
            }
        }
    }

    /// A folded, clustered cloud of 800 points (many per cell, in negative and positive cells)
    /// and the two thirds of them that are built into grids.
    #[test]
    fn tagged_pairs_are_the_close_pairs_whose_tags_are_apart() {
        let (positions, items) = folded_cloud();
        // Tags: the positions stretched along x, so that some close pairs have close tags
        // and others do not.
        let tags: Vec<DVec3> = positions
            .iter()
            .enumerate()
            .map(|(k, p)| *p * DVec3::new(3.0, 1.0, 1.0) + DVec3::X * 0.01 * (k % 5) as f64)
            .collect();
        let (radius, apart) = (0.04, 0.05);
        let mut grid = CellGrid::new();
        grid.build(&positions, &items, radius);
        grid.tag(&tags);
        let mut found = Vec::new();
        for run in grid.cell_runs(5) {
            let mut row = Vec::new();
            grid.for_each_row_in(run, radius, apart, &mut row, |i, near| {
                found.extend(near.iter().map(|&j| (i.min(j), i.max(j))));
            });
        }
        found.sort_unstable();
        let (mut brute, mut left_out) = (Vec::new(), 0);
        for (k, &i) in items.iter().enumerate() {
            for &j in &items[k + 1..] {
                let (i, j) = (i as usize, j as usize);
                if positions[i].distance_squared(positions[j]) <= radius * radius {
                    if tags[i].distance_squared(tags[j]) > apart * apart {
                        brute.push((i as u32, j as u32));
                    } else {
                        left_out += 1;
                    }
                }
            }
        }
        assert!(
            brute.len() > 500 && left_out > 500,
            "too one-sided a test: {} kept, {left_out} left out",
            brute.len()
        );
        assert_eq!(found, brute);
    }

    fn folded_cloud() -> (Vec<DVec3>, Vec<u32>) {
        let positions = (0..800)
            .map(|i| {
                let f = i as f64;
                DVec3::new((f * 0.37).sin(), 0.1 * (f * 0.71).cos(), (f * 0.13).sin()) * 0.3
            })
            .collect();
        (positions, (0..800).filter(|i| i % 3 != 1).collect())
    }

    #[test]
    fn grid_near_query_is_exactly_the_brute_force_neighbourhood() {
        let (positions, items) = folded_cloud();
        let mut grid = CellGrid::new();
        grid.build(&positions, &items, 0.04);
        // At every point (built or not) and at points between them, for two radii.
        let probes: Vec<DVec3> = positions
            .iter()
            .copied()
            .chain(positions.windows(2).map(|w| 0.5 * (w[0] + w[1])))
            .collect();
        let mut total = 0;
        let (mut queries, mut row) = (Queries::default(), Vec::new());
        queries.sort(&probes, grid.spacing());
        for radius in [0.04, 0.015] {
            let mut found = vec![Vec::new(); probes.len()];
            grid.for_each_near_all(&probes, &queries, radius, &mut row, |k, i| found[k].push(i));
            for (p, mut found) in probes.iter().zip(found) {
                let mut brute: Vec<u32> = items
                    .iter()
                    .copied()
                    .filter(|&i| positions[i as usize].distance_squared(*p) <= radius * radius)
                    .collect();
                brute.sort_unstable();
                total += found.len();
                found.sort_unstable();
                assert_eq!(found, brute, "at {p} within {radius}");
            }
        }
        assert!(total > 5000, "too sparse a test: {total}");
    }

    #[test]
    fn cell_keys_floor_like_f64_floor() {
        // The key as first written, with `f64::floor`.
        let reference = |p: DVec3, inv: f64| {
            let c = (p * inv).floor();
            let half = f64::from(1u32 << (BITS - 1));
            let max = f64::from((1u32 << BITS) - 2);
            let k = |v: f64| (v + half).clamp(1.0, max) as u64;
            (k(c.x) << (2 * BITS)) | (k(c.y) << BITS) | k(c.z)
        };
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.5,
            1.0 - f64::EPSILON,
            -1.0 + f64::EPSILON,
            -f64::MIN_POSITIVE,
            1e15 + 0.5,
            -1e15 - 0.5,
            2e6,
            -2e6,
            2_097_151.5,
            2_097_152.0,
            -2_097_152.0,
            -2_097_152.5,
            1_048_575.5,
            -1_048_576.5,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut seed = 9u64;
        values.extend((0..10_000).map(|_| rand(&mut seed) * 100.0));
        for inv in [1.0, 37.5, 1.0 / 0.0071] {
            for &v in &values {
                for p in [
                    DVec3::new(v, 0.3, -0.2),
                    DVec3::new(0.1, v, 7.0),
                    DVec3::new(-3.0, 2.0, v),
                ] {
                    assert_eq!(cell_key(p, inv), reference(p, inv), "{p} at {inv}");
                }
            }
        }
        // NaN coordinates share one cell.
        let nan = DVec3::new(f64::NAN, 0.0, 0.0);
        assert_eq!(
            cell_key(nan, 2.0),
            cell_key(DVec3::new(f64::NAN, 0.1, 0.2), 2.0)
        );
    }

    #[test]
    fn a_build_sorts_by_cell_then_item_whichever_sort_it_takes() {
        let (mut positions, items) = folded_cloud();
        let spacing = 0.01;
        let expected = |positions: &[DVec3], items: &[u32]| {
            let mut e: Vec<(u64, u32)> = items
                .iter()
                .map(|&i| (cell_key(positions[i as usize], 1.0 / spacing), i))
                .collect();
            e.sort_unstable();
            e
        };
        let mut grid = CellGrid::new();
        let check = |grid: &mut CellGrid, positions: &[DVec3], items: &[u32], radix: bool| {
            let compact = Compact::of(
                items
                    .iter()
                    .map(|&i| cell_key(positions[i as usize], 100.0)),
            );
            let ascending = items.windows(2).all(|w| w[0] < w[1]);
            assert_eq!(compact.is_some() && ascending, radix, "the case tested");
            grid.build(positions, items, spacing);
            let e = expected(positions, items);
            assert_eq!(grid.sorted, e);
            let at: Vec<DVec3> = e.iter().map(|&(_, i)| positions[i as usize]).collect();
            assert_eq!(grid.positions, at);
        };
        // Radix: ascending items in a small box (several digits' worth of cells).
        check(&mut grid, &positions, &items, true);
        assert!(
            Compact::of(grid.sorted.iter().map(|&(k, _)| k))
                .expect("a compact packing")
                .bits
                > DIGIT
        );
        // All in one cell: no pass at all, the items' order.
        let one = vec![DVec3::splat(0.001); positions.len()];
        check(&mut grid, &one, &items, true);
        // Items out of order, and cells spread wider than 32 bits: the comparison sort.
        let mut shuffled = items.clone();
        shuffled.reverse();
        check(&mut grid, &positions, &shuffled, false);
        positions[items[3] as usize] = DVec3::new(5e3, -5e3, 5e3);
        check(&mut grid, &positions, &items, false);
    }

    #[test]
    fn an_updated_grid_is_the_grid_built_anew() {
        let (mut positions, items) = folded_cloud();
        let spacing = 0.04;
        let mut grid = CellGrid::new();
        grid.build(&positions, &[], spacing);
        let mut present = vec![false; positions.len()];
        let mut seed = 3u64;
        // A pseudo-random index below m.
        let mut next = |m: usize| ((rand(&mut seed) + 1.0) * 0.5 * m as f64) as usize % m;
        for round in 0..20 {
            // Some items already in the grid and some new ones move.
            let mut moved: Vec<u32> = (0..1 + next(200))
                .map(|_| items[next(items.len())])
                .collect();
            moved.sort_unstable();
            moved.dedup();
            for &i in &moved {
                positions[i as usize].x += 0.03 * (next(100) as f64 / 50.0 - 1.0);
            }
            grid.update(&positions, &moved, |i| present[i as usize]);
            for &i in &moved {
                present[i as usize] = true;
            }
            let union: Vec<u32> = (0..positions.len() as u32)
                .filter(|&i| present[i as usize])
                .collect();
            let mut fresh = CellGrid::new();
            fresh.build(&positions, &union, spacing);
            assert_eq!(grid.sorted, fresh.sorted, "round {round}");
            assert_eq!(grid.positions, fresh.positions, "round {round}");
        }
        assert!(present.iter().filter(|&&p| p).count() > 400);
    }

    #[test]
    fn grid_pairs_are_exactly_the_brute_force_pairs_each_once() {
        let (positions, items) = folded_cloud();
        let radius = 0.04;
        // Tags 1 m apart from each other: no pair is left out by them.
        let (apart, tags): (f64, Vec<DVec3>) = (
            0.5,
            (0..positions.len()).map(|i| DVec3::X * i as f64).collect(),
        );
        let mut grid = CellGrid::new();
        let mut moved = positions.clone();
        // Twice: the second build starts from the first one's order.
        for round in 0..2 {
            grid.build(&moved, &items, radius);
            grid.tag(&tags);
            let mut found = Vec::new();
            grid.for_each_pair(radius, apart, |i, j| found.push((i.min(j), i.max(j))));
            // Split into runs of cells, the runs find the same pairs, each once.
            for parts in [2, 7, 64] {
                let mut split = Vec::new();
                let runs = grid.cell_runs(parts);
                assert!(runs.windows(2).all(|w| w[0].end == w[1].start));
                assert_eq!((runs[0].start, runs[runs.len() - 1].end), (0, items.len()));
                for run in runs {
                    grid.for_each_pair_in(run, radius, apart, |i, j| {
                        split.push((i.min(j), i.max(j)))
                    });
                }
                split.sort_unstable();
                let mut whole = found.clone();
                whole.sort_unstable();
                assert_eq!(split, whole, "round {round}: {parts} runs");
            }
            let count = found.len();
            found.sort_unstable();
            found.dedup();
            assert_eq!(
                found.len(),
                count,
                "round {round}: a pair was reported twice"
            );
            let mut brute = Vec::new();
            for (k, &i) in items.iter().enumerate() {
                for &j in &items[k + 1..] {
                    let d2 = moved[i as usize].distance_squared(moved[j as usize]);
                    if d2 <= radius * radius {
                        brute.push((i, j));
                    }
                }
            }
            assert!(
                brute.len() > 1000,
                "too sparse a test: {} pairs",
                brute.len()
            );
            assert_eq!(found, brute, "round {round}");
            for (k, x) in moved.iter_mut().enumerate() {
                x.x += 0.01 * (k as f64 * 0.9).sin();
            }
        }
    }
}
