//! The body's broad phase: a uniform grid over the parts, listing in each cell the parts that
//! a particle anywhere in the cell could touch (or be crossed by) over the span of substeps it
//! is built for.
//!
//! A part is listed in a cell when the cell's centre lies within R + (half the cell's
//! diagonal) of its axis segment, R being its larger radius plus the contact reach plus a bound
//! on how far it travels over that span; that covers every point of the cell. Rebuilt from
//! scratch for each span (tens of µs for a 20-part body; the collider picks spans of up to ten
//! substeps over which no part travels more than a cell), it has no stale state, so a limb of
//! any speed is found; a particle outside the grid's box has no candidate at all.

use glam::DVec3;

use super::motion::MovingPart;

/// Cells per axis at most; a larger box gets larger cells.
const MAX_CELLS: usize = 1 << 18;

/// Candidate parts per cell, as a compressed sparse row table.
#[derive(Clone, Debug, Default)]
pub(crate) struct PartGrid {
    origin: DVec3,
    inv_cell: f64,
    dims: [usize; 3],
    /// Start of each cell's run in `parts` (one more entry than cells).
    offsets: Vec<u32>,
    parts: Vec<u16>,
    /// (cell, part) pairs (scratch).
    pairs: Vec<(u32, u16)>,
}

impl PartGrid {
    /// Rebuilds the table for `parts` with contact reach `reach` (m) and preferred cell edge
    /// `cell` (m).
    pub fn build(&mut self, parts: &[MovingPart], reach: f64, cell: f64) {
        self.pairs.clear();
        let influence: Vec<(usize, DVec3, DVec3, f64)> = parts
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let (a, ra, b, rb) = p.cone.ends();
                (k, a, b, ra.max(rb) + reach + p.travel)
            })
            .collect();
        let Some((lo, hi)) = influence
            .iter()
            .map(|&(_, a, b, r)| (a.min(b) - DVec3::splat(r), a.max(b) + DVec3::splat(r)))
            .reduce(|(l0, h0), (l1, h1)| (l0.min(l1), h0.max(h1)))
        else {
            self.dims = [0; 3];
            return;
        };
        let size = (hi - lo).max(DVec3::splat(1e-9));
        let mut edge = cell.max(1e-3);
        while (size / edge).ceil().to_array().iter().product::<f64>() > MAX_CELLS as f64 {
            edge *= 1.5;
        }
        self.origin = lo;
        self.inv_cell = 1.0 / edge;
        let dims = (size / edge).ceil().max(DVec3::ONE);
        self.dims = [dims.x as usize, dims.y as usize, dims.z as usize];
        let half_diag = 0.5 * edge * 3f64.sqrt();
        for &(k, a, b, r) in &influence {
            let (cl, ch) = (
                self.cell_of(a.min(b) - DVec3::splat(r)),
                self.cell_of(a.max(b) + DVec3::splat(r)),
            );
            let ab = b - a;
            let l2 = ab.length_squared();
            // One division per part rather than per cell; the radius grown by a relative 1e-12
            // so that rounding never drops a cell at the boundary.
            let inv_l2 = if l2 > 0.0 { 1.0 / l2 } else { 0.0 };
            let keep = (r + half_diag) * (1.0 + 1e-12);
            let keep2 = keep * keep;
            for z in cl[2]..=ch[2] {
                for y in cl[1]..=ch[1] {
                    let row = (z * self.dims[1] + y) * self.dims[0];
                    let cy = lo.y + (y as f64 + 0.5) * edge;
                    let cz = lo.z + (z as f64 + 0.5) * edge;
                    for x in cl[0]..=ch[0] {
                        let c = DVec3::new(lo.x + (x as f64 + 0.5) * edge, cy, cz);
                        let t = ((c - a).dot(ab) * inv_l2).clamp(0.0, 1.0);
                        if (c - (a + ab * t)).length_squared() <= keep2 {
                            self.pairs.push(((row + x) as u32, k as u16));
                        }
                    }
                }
            }
        }
        // Counting sort by cell, stable: each cell lists its parts in body order.
        let cells = self.dims.iter().product::<usize>();
        self.offsets.clear();
        self.offsets.resize(cells + 1, 0);
        for &(c, _) in &self.pairs {
            self.offsets[c as usize + 1] += 1;
        }
        for i in 0..cells {
            self.offsets[i + 1] += self.offsets[i];
        }
        self.parts.clear();
        self.parts.resize(self.pairs.len(), 0);
        // Each pair goes to its cell's next free slot, counted in `offsets[c]` (the cell's
        // start, advanced as it fills); each start then sits where the next cell's was, so the
        // starts are restored by shifting them one cell up.
        for &(c, k) in &self.pairs {
            let slot = &mut self.offsets[c as usize];
            self.parts[*slot as usize] = k;
            *slot += 1;
        }
        self.offsets.copy_within(0..cells, 1);
        self.offsets[0] = 0;
    }

    /// The cell holding `p`, clamped into the grid.
    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let q = ((p - self.origin) * self.inv_cell).floor();
        std::array::from_fn(|a| (q[a].max(0.0) as usize).min(self.dims[a] - 1))
    }

    /// The parts listed in the cell holding `p` (none outside the grid).
    #[inline(always)]
    pub fn candidates(&self, p: DVec3) -> &[u16] {
        if self.dims[0] == 0 {
            return &[];
        }
        let q = (p - self.origin) * self.inv_cell;
        if !(q.cmpge(DVec3::ZERO).all()) {
            return &[];
        }
        let (x, y, z) = (q.x as usize, q.y as usize, q.z as usize);
        if x >= self.dims[0] || y >= self.dims[1] || z >= self.dims[2] {
            return &[];
        }
        let id = (z * self.dims[1] + y) * self.dims[0] + x;
        &self.parts[self.offsets[id] as usize..self.offsets[id + 1] as usize]
    }
}
