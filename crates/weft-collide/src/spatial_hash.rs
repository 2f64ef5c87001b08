//! Dense spatial hashing of points, after Müller's "Ten Minute Physics" #11 (self-collision):
//! cells of a fixed spacing hashed into a table of ~2N buckets, stored as counting-sorted
//! `cell_start` / `cell_entries` arrays: no allocation per cell, and no `HashMap` whose
//! iteration order could leak into results.

use glam::DVec3;

/// Points bucketed by hashed grid cell.
#[derive(Clone, Debug, Default)]
pub struct SpatialHash {
    spacing: f64,
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
        h.unsigned_abs() as usize % (self.cell_start.len() - 1)
    }

    /// Rebuilds the table over `items` (indices into `positions`), keeping their order per bucket.
    pub fn build(&mut self, positions: &[DVec3], items: &[u32]) {
        let table = 2 * items.len().max(1) + 1;
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
}
