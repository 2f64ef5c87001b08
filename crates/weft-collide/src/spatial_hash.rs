//! Dense spatial hashing of points, after Müller's "Ten Minute Physics" #11 (self-collision):
//! cells of a fixed spacing hashed into a power-of-two table of at least 2N buckets, stored as
//! counting-sorted `cell_start` / `cell_entries` arrays: no allocation per cell (nor per
//! rebuild once the arrays have grown), and no `HashMap` whose iteration order could leak into
//! results.

use glam::DVec3;

/// Points bucketed by hashed grid cell.
#[derive(Clone, Debug, Default)]
pub struct SpatialHash {
    spacing: f64,
    /// Table size − 1 (the table size is a power of two).
    mask: usize,
    cell_start: Vec<u32>,
    cell_entries: Vec<u32>,
    /// Cell and position of each entry of `cell_entries`, in the same order.
    entry_cells: Vec<[i32; 3]>,
    entry_positions: Vec<DVec3>,
    /// Bucket of each item, in `items` order (build scratch).
    item_buckets: Vec<u32>,
}

/// The 13 neighbour-cell offsets that are lexicographically positive: with the cell itself
/// they visit every pair of neighbouring cells exactly once.
const HALF_NEIGHBOURS: [[i32; 3]; 13] = [
    [0, 0, 1],
    [0, 1, -1],
    [0, 1, 0],
    [0, 1, 1],
    [1, -1, -1],
    [1, -1, 0],
    [1, -1, 1],
    [1, 0, -1],
    [1, 0, 0],
    [1, 0, 1],
    [1, 1, -1],
    [1, 1, 0],
    [1, 1, 1],
];

impl SpatialHash {
    /// An empty hash with cell size `spacing` (m).
    pub fn new(spacing: f64) -> Self {
        Self {
            spacing,
            ..Self::default()
        }
    }

    /// Cell size (m).
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// Sets the cell size (m); takes effect at the next [`SpatialHash::build`].
    pub fn set_spacing(&mut self, spacing: f64) {
        self.spacing = spacing;
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

    /// Rebuilds the table over `items` (indices into `positions`). Within a bucket, entries are
    /// ordered by cell, then by their order in `items`.
    pub fn build(&mut self, positions: &[DVec3], items: &[u32]) {
        let table = (2 * items.len()).max(2).next_power_of_two();
        self.mask = table - 1;
        self.cell_start.clear();
        self.cell_start.resize(table + 1, 0);
        self.item_buckets.clear();
        for &i in items {
            let b = self.bucket(self.cell(positions[i as usize]));
            self.item_buckets.push(b as u32);
            self.cell_start[b] += 1;
        }
        // Inclusive prefix sums give each bucket's end; filling backwards then leaves the start.
        let mut sum = 0;
        for s in &mut self.cell_start {
            sum += *s;
            *s = sum;
        }
        self.cell_entries.clear();
        self.cell_entries.resize(items.len(), 0);
        for (&i, &b) in items.iter().zip(&self.item_buckets).rev() {
            self.cell_start[b as usize] -= 1;
            self.cell_entries[self.cell_start[b as usize] as usize] = i;
        }
        self.entry_cells.clear();
        self.entry_positions.clear();
        for &i in &self.cell_entries {
            let p = positions[i as usize];
            self.entry_cells.push(self.cell(p));
            self.entry_positions.push(p);
        }
        // Group each bucket's entries by cell (buckets hold a handful of entries: insertion
        // sort, stable, so items keep their order within a cell).
        for b in 0..table {
            let (s, e) = (self.cell_start[b] as usize, self.cell_start[b + 1] as usize);
            for k in s + 1..e {
                let mut j = k;
                while j > s && self.entry_cells[j - 1] > self.entry_cells[j] {
                    self.entry_cells.swap(j - 1, j);
                    self.entry_positions.swap(j - 1, j);
                    self.cell_entries.swap(j - 1, j);
                    j -= 1;
                }
            }
        }
    }

    /// Calls `f(i, j, distance²)` once for every unordered pair {i, j} of built items at most
    /// `radius` apart (`radius` must not exceed the spacing). Which of the two comes first,
    /// and the order of the calls, depend on the positions and the table alone.
    ///
    /// Cell by cell: a cell is paired with itself and with its 13 lexicographically positive
    /// neighbours, so each pair of neighbouring cells is visited once; with `radius` ≤ spacing
    /// any two points within `radius` lie in the same or neighbouring cells.
    pub fn for_each_pair(&self, radius: f64, mut f: impl FnMut(u32, u32, f64)) {
        assert!(
            radius <= self.spacing,
            "pair radius {radius} exceeds the cell size {}",
            self.spacing
        );
        let r2 = radius * radius;
        let (cells, pos, ids) = (&self.entry_cells, &self.entry_positions, &self.cell_entries);
        let mut s = 0;
        while s < ids.len() {
            // The run s..e of entries in one cell (one bucket holds its whole cell).
            let c = cells[s];
            let mut e = s + 1;
            while e < ids.len() && cells[e] == c {
                e += 1;
            }
            for x in s..e {
                for y in x + 1..e {
                    let d2 = pos[x].distance_squared(pos[y]);
                    if d2 <= r2 {
                        f(ids[x], ids[y], d2);
                    }
                }
            }
            for off in HALF_NEIGHBOURS {
                let nc = [c[0] + off[0], c[1] + off[1], c[2] + off[2]];
                let b = self.bucket(nc);
                let (bs, be) = (self.cell_start[b] as usize, self.cell_start[b + 1] as usize);
                // Cells are grouped within a bucket: find nc's run, if any.
                let Some(first) = (bs..be).find(|&y| cells[y] == nc) else {
                    continue;
                };
                let last = (first..be).find(|&y| cells[y] != nc).unwrap_or(be);
                for x in s..e {
                    let px = pos[x];
                    for y in first..last {
                        let d2 = px.distance_squared(pos[y]);
                        if d2 <= r2 {
                            f(ids[x], ids[y], d2);
                        }
                    }
                }
            }
            s = e;
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

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn pairs_are_exactly_the_brute_force_pairs_each_once() {
        // A folded, clustered cloud: many points per cell and many bucket collisions.
        let positions: Vec<DVec3> = (0..800)
            .map(|i| {
                let f = i as f64;
                DVec3::new((f * 0.37).sin(), 0.1 * (f * 0.71).cos(), (f * 0.13).sin()) * 0.3
            })
            .collect();
        // Every other point only, so that items are not simply 0..n.
        let items: Vec<u32> = (0..800).filter(|i| i % 3 != 1).collect();
        let radius = 0.04;
        let mut hash = SpatialHash::new(radius);
        hash.build(&positions, &items);
        let mut found = Vec::new();
        hash.for_each_pair(radius, |i, j, d2| {
            let d = positions[i as usize].distance_squared(positions[j as usize]);
            assert_eq!(d, d2, "distance² of {i}-{j}");
            found.push((i.min(j), i.max(j)));
        });
        let count = found.len();
        found.sort_unstable();
        found.dedup();
        assert_eq!(found.len(), count, "a pair was reported twice");
        let mut brute = Vec::new();
        for (k, &i) in items.iter().enumerate() {
            for &j in &items[k + 1..] {
                if positions[i as usize].distance_squared(positions[j as usize]) <= radius * radius
                {
                    brute.push((i, j));
                }
            }
        }
        assert!(
            brute.len() > 1000,
            "too sparse a test: {} pairs",
            brute.len()
        );
        assert_eq!(found, brute);
    }
}
