//! Searches of a [`CellGrid`]: every close pair of its points, run by run of cells, and
//! every point near each of a batch of queries, both walking the cells in key order with one
//! forward-only cursor per neighbour column.

use std::ops::{ControlFlow, Range};

use glam::DVec3;
use multiversion::multiversion;

use super::keys::{COLUMNS, NEAR_COLUMNS, X, Y};
use super::{CellGrid, Queries};

impl CellGrid {
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
            ControlFlow::Continue(())
        });
    }

    /// [`CellGrid::for_each_pair_in`] one point at a time: calls `f(i, near)` for each point
    /// `i` of `run`, `near` being its partners that come after it in key order (so that each
    /// pair comes once; often none), until `f` breaks. Only partners whose tags are
    /// more than `apart` from i's count (the grid must be tagged). `row` is scratch.
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
        mut f: impl FnMut(u32, &[u32]) -> ControlFlow<()>,
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
                if f(cells[x].1, row).is_break() {
                    return;
                }
            }
            s = e;
        }
    }
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
