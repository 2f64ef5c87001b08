//! A uniform grid over a still triangle mesh for contact queries. Every cell lists the
//! triangles within the contact reach of any point in it, so a particle finds every triangle
//! it can touch by one lookup and keeps no list of its own (nothing to rebuild as it slides).
//! Cells that meet no triangle lie wholly on one side of the surface: a flood fill from the
//! grid's border labels them outside or inside a closed mesh.

use glam::DVec3;
use rayon::prelude::*;

use super::MeshGeometry;
use super::closest::closest_on_triangle;
use super::face_cert::FaceCert;

/// Cells of a grid at most (a 16 MB offset table); coarser cells beyond.
const MAX_CELLS: usize = 1 << 22;

/// Cell entries at most (triangle indices, 4 bytes each): a mesh that would need more keeps
/// the per-particle lists.
pub(crate) const MAX_ENTRIES: usize = 1 << 24;

/// What a cell that lists no triangle within reach knows of its side, and whether any
/// triangle's box meets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    /// Wholly outside the mesh (or the mesh is open).
    Outside,
    /// Wholly inside a closed mesh.
    Inside,
    /// A triangle's box meets the cell: either side.
    Surface,
}

/// The grid: cells of edge `h` from `origin`, each listing the triangles within `reach` of it.
#[derive(Clone, Debug)]
pub(crate) struct ContactGrid {
    origin: DVec3,
    h: f64,
    inv_h: f64,
    /// The reach the grid was built for.
    reach: f64,
    /// The mesh's box.
    bounds: (DVec3, DVec3),
    dims: [usize; 3],
    /// Cell c lists `tris[starts[c] .. starts[c + 1]]`.
    starts: Vec<u32>,
    tris: Vec<u32>,
    side: Vec<Side>,
    /// Per cell, how many cells away (Chebyshev, at most 255) the nearest cell listing a
    /// triangle is: 0 for those.
    gap: Vec<u8>,
    /// Per triangle, a lower bound (sought up to twice the reach of a cell's farthest
    /// point) on its distance to any triangle that reaches in front of its plane.
    clearance: Vec<f64>,
    /// Per triangle, what the first test of `grid_run` reads, then a record that settles
    /// nothing.
    certs: Vec<FaceCert>,
}

impl ContactGrid {
    /// The grid of `mesh` (still: its end vertices are the surface) for contacts within
    /// `reach`, or `None` if it would hold more than [`MAX_ENTRIES`] entries.
    pub fn new(mesh: &MeshGeometry, reach: f64) -> Option<Self> {
        let (lo, hi) = mesh.bounds();
        let corners = |t: usize| mesh.triangles[t].map(|i| mesh.end[i as usize]);
        let n = mesh.triangles.len();
        // Cells about as large as the triangles, and no smaller than twice the reach.
        let edges: f64 = (0..n)
            .map(|t| {
                let [a, b, c] = corners(t);
                (b - a).length() + (c - b).length() + (a - c).length()
            })
            .sum();
        let mean_edge = if n > 0 { edges / (3 * n) as f64 } else { 0.0 };
        let mut h = mean_edge.max(2.0 * reach).max(1e-6);
        let dims_for = |h: f64| {
            let pad = reach + h;
            let size = hi - lo + DVec3::splat(2.0 * pad);
            (
                lo - DVec3::splat(pad),
                size.to_array().map(|s| (s / h).ceil() as usize + 1),
            )
        };
        let (mut origin, mut dims) = dims_for(h);
        let cells = |d: [usize; 3]| d[0] as f64 * d[1] as f64 * d[2] as f64;
        while cells(dims) > MAX_CELLS as f64 {
            h *= (cells(dims) / MAX_CELLS as f64).cbrt() * 1.01;
            (origin, dims) = dims_for(h);
        }
        let inv_h = 1.0 / h;
        let cell_range = |lo: DVec3, hi: DVec3| {
            let a = ((lo - origin) * inv_h).floor().max(DVec3::ZERO);
            let b = ((hi - origin) * inv_h).floor();
            let a = a.to_array().map(|v| v as usize);
            let b = b.to_array().map(|v| v.max(0.0) as usize);
            std::array::from_fn::<_, 3, _>(|k| (a[k], b[k].min(dims[k] - 1)))
        };
        // Entries before taking memory for them: every cell of each triangle's grown box.
        let estimate: f64 = (0..n)
            .map(|t| {
                let [a, b, c] = corners(t);
                let r = cell_range(a.min(b).min(c) - reach, a.max(b).max(c) + reach);
                r.iter().map(|&(s, e)| (e + 1 - s) as f64).product::<f64>()
            })
            .sum();
        if estimate > MAX_ENTRIES as f64 {
            return None;
        }
        // A point of the cell is within half its diagonal of the centre; the slack covers the
        // rounding of the cell a point is found in.
        let half_diagonal = 0.5 * h * 3f64.sqrt() * (1.0 + 1e-9) + 1e-9 * (1.0 + h);
        let within = reach + half_diagonal;
        let index = |[i, j, k]: [usize; 3]| (k * dims[1] + j) * dims[0] + i;
        // (cell, triangle, the triangle's own box meets the cell), sorted: a fixed order.
        let mut pairs: Vec<(u32, u32, bool)> = (0..n)
            .into_par_iter()
            .with_min_len(256)
            .flat_map_iter(|t| {
                let [a, b, c] = corners(t);
                let (tlo, thi) = (a.min(b).min(c), a.max(b).max(c));
                let r = cell_range(tlo - reach, thi + reach);
                let mut out = Vec::new();
                for k in r[2].0..=r[2].1 {
                    for j in r[1].0..=r[1].1 {
                        for i in r[0].0..=r[0].1 {
                            let cell_lo = origin + DVec3::new(i as f64, j as f64, k as f64) * h;
                            let centre = cell_lo + DVec3::splat(0.5 * h);
                            let q = closest_on_triangle(centre, a, b, c).point;
                            if (q - centre).length_squared() > within * within {
                                continue;
                            }
                            let eps = 1e-9 * (1.0 + h);
                            let meets = (tlo - eps).cmple(cell_lo + h).all()
                                && (thi + eps).cmpge(cell_lo).all();
                            out.push((index([i, j, k]) as u32, t as u32, meets));
                        }
                    }
                }
                out
            })
            .collect();
        pairs.par_sort_unstable();
        let total = dims[0] * dims[1] * dims[2];
        let mut starts = vec![0u32; total + 1];
        let mut side = vec![Side::Outside; total];
        for &(c, _, meets) in &pairs {
            starts[c as usize + 1] += 1;
            if meets {
                side[c as usize] = Side::Surface;
            }
        }
        for c in 0..total {
            starts[c + 1] += starts[c];
        }
        let tris = pairs.iter().map(|p| p.1).collect();
        drop(pairs);
        if mesh.closed() {
            label_inside(&mut side, dims);
        }
        let gap = gaps(&starts, dims);
        // Sought as far as a particle with triangles in its cell may be from them.
        let clearance = clearances(mesh, 2.0 * (within + half_diagonal));
        // One more record, settling nothing, for the particles that touched no triangle.
        let certs = (clearance.iter().enumerate())
            .map(|(t, &clear)| {
                let f = mesh.face(t);
                FaceCert::new(f.corners, f.normal, clear)
            })
            .chain([FaceCert::NONE])
            .collect();
        Some(Self {
            origin,
            h,
            inv_h,
            reach,
            bounds: (lo, hi),
            gap,
            dims,
            starts,
            tris,
            side,
            clearance,
            certs,
        })
    }

    /// The cell holding `x`, or `None` outside the grid (where no triangle is within reach).
    #[inline]
    pub fn cell(&self, x: DVec3) -> Option<usize> {
        let f = (x - self.origin) * self.inv_h;
        // Written so that NaN fails too.
        if !(f.cmpge(DVec3::ZERO).all()) {
            return None;
        }
        let [i, j, k] = f.to_array().map(|v| v as usize);
        (i < self.dims[0] && j < self.dims[1] && k < self.dims[2])
            .then(|| (k * self.dims[1] + j) * self.dims[0] + i)
    }

    /// The triangles within reach of every point of `cell`.
    #[inline]
    pub fn list(&self, cell: usize) -> &[u32] {
        &self.tris[self.starts[cell] as usize..self.starts[cell + 1] as usize]
    }

    /// The side of `cell` (outside the grid: outside).
    #[inline]
    pub fn side(&self, cell: Option<usize>) -> Side {
        cell.map_or(Side::Outside, |c| self.side[c])
    }

    /// A lower bound on triangle `t`'s distance to any triangle that reaches in front of its
    /// plane. Every triangle within it of `t` lies behind `t`'s plane, so for a point x in
    /// front of the plane whose closest point on `t` is inside the face, at distance d with
    /// d + r no more than it, `t` is a nearest triangle of all within r of x (those behind
    /// the plane are at least d away, the others at least the bound less d).
    #[inline]
    pub fn clearance(&self, t: usize) -> f64 {
        self.clearance.get(t).copied().unwrap_or(0.0)
    }

    /// A lower bound on the distance from `x`, in `cell` (as [`Self::cell`] finds it), to
    /// every triangle. Every point of a cell listing none is farther than the reach from
    /// them, and a point of a cell k cells (Chebyshev) from the nearest listing one is at
    /// least the reach plus k − 1 cells away; `x` is as far again as it is from its cell's
    /// faces (a path from it to a triangle leaves the cell first). Outside the grid, the
    /// distance to the mesh's box. Zero in a listing cell.
    pub fn clear_distance(&self, cell: Option<usize>, x: DVec3) -> f64 {
        match cell {
            Some(c) => match self.gap[c] {
                0 => 0.0,
                k => {
                    let f = (x - self.origin) * self.inv_h;
                    let frac = f - f.floor();
                    let inner = frac.min(DVec3::ONE - frac).min_element().max(0.0) * self.h;
                    let d = inner + self.reach + f64::from(k - 1) * self.h;
                    d * (1.0 - 1e-9) - 1e-9 * (1.0 + self.h)
                }
            },
            None => {
                let (lo, hi) = self.bounds;
                let outside = (lo - x).max(x - hi).max(DVec3::ZERO);
                outside.length() * (1.0 - 1e-9)
            }
        }
    }

    /// Per triangle (storage order), what the first test of `grid_run` reads, then
    /// [`FaceCert::NONE`].
    #[inline]
    pub fn certs(&self) -> &[FaceCert] {
        &self.certs
    }
}

/// Each triangle's [`ContactGrid::clearance`], sought up to `cap`: from the triangle's
/// centroid c, the distance to each triangle with a corner in front of the plane less the
/// triangle's radius about c (a lower bound on the distance between the two triangles).
fn clearances(mesh: &MeshGeometry, cap: f64) -> Vec<f64> {
    let eps = 1e-12 * (1.0 + mesh.extent);
    (0..mesh.face_count())
        .into_par_iter()
        .with_min_len(256)
        .map(|t| {
            let f = mesh.face(t);
            let [a, b, c] = f.corners;
            let n = f.normal;
            if n == DVec3::ZERO {
                return 0.0;
            }
            let centre = (a + b + c) / 3.0;
            let radius = [a, b, c]
                .iter()
                .map(|v| (*v - centre).length())
                .fold(0.0, f64::max);
            let mut clear = cap;
            mesh.bvh
                .branch_and_bound(centre, (cap + radius) * (cap + radius), |u| {
                    let [ua, ub, uc] = mesh.corners(u);
                    if [ua, ub, uc].iter().any(|v| n.dot(*v - a) > eps) {
                        let q = closest_on_triangle(centre, ua, ub, uc).point;
                        clear = clear.min(((q - centre).length() - radius).max(0.0));
                    }
                    (clear + radius) * (clear + radius)
                });
            clear
        })
        .collect()
}

/// Per cell of a grid of `dims` whose cell c lists `starts[c + 1] − starts[c]` triangles,
/// the Chebyshev distance in cells to the nearest cell that lists any (0 for those, 255 at
/// most; 255 everywhere if none does), by a breadth-first search over the 26 neighbours.
fn gaps(starts: &[u32], dims: [usize; 3]) -> Vec<u8> {
    let total = dims[0] * dims[1] * dims[2];
    let mut gap = vec![u8::MAX; total];
    let mut front: Vec<usize> = (0..total).filter(|&c| starts[c + 1] > starts[c]).collect();
    for &c in &front {
        gap[c] = 0;
    }
    let mut next = Vec::new();
    for k in 1..u8::MAX {
        for &c in &front {
            let (i, j, l) = (
                c % dims[0],
                (c / dims[0]) % dims[1],
                c / (dims[0] * dims[1]),
            );
            for dl in -1i64..=1 {
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (a, b, d) = (i as i64 + di, j as i64 + dj, l as i64 + dl);
                        if a < 0 || b < 0 || d < 0 {
                            continue;
                        }
                        let (a, b, d) = (a as usize, b as usize, d as usize);
                        if a >= dims[0] || b >= dims[1] || d >= dims[2] {
                            continue;
                        }
                        let n = (d * dims[1] + b) * dims[0] + a;
                        if gap[n] == u8::MAX {
                            gap[n] = k;
                            next.push(n);
                        }
                    }
                }
            }
        }
        if next.is_empty() {
            break;
        }
        std::mem::swap(&mut front, &mut next);
        next.clear();
    }
    gap
}

/// Relabels as inside every cell that no triangle's box meets and that no path of such cells
/// joins to the grid's border (the border is out of the mesh's box, hence outside).
fn label_inside(side: &mut [Side], dims: [usize; 3]) {
    let index = |i: usize, j: usize, k: usize| (k * dims[1] + j) * dims[0] + i;
    let mut reached = vec![false; side.len()];
    let mut stack = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let border = i == 0
                    || j == 0
                    || k == 0
                    || i + 1 == dims[0]
                    || j + 1 == dims[1]
                    || k + 1 == dims[2];
                let c = index(i, j, k);
                if border && side[c] != Side::Surface && !reached[c] {
                    reached[c] = true;
                    stack.push((i, j, k));
                }
            }
        }
    }
    while let Some((i, j, k)) = stack.pop() {
        let mut visit = |i: usize, j: usize, k: usize| {
            let c = index(i, j, k);
            if side[c] != Side::Surface && !reached[c] {
                reached[c] = true;
                stack.push((i, j, k));
            }
        };
        if i > 0 {
            visit(i - 1, j, k);
        }
        if i + 1 < dims[0] {
            visit(i + 1, j, k);
        }
        if j > 0 {
            visit(i, j - 1, k);
        }
        if j + 1 < dims[1] {
            visit(i, j + 1, k);
        }
        if k > 0 {
            visit(i, j, k - 1);
        }
        if k + 1 < dims[2] {
            visit(i, j, k + 1);
        }
    }
    for (s, r) in side.iter_mut().zip(reached) {
        if *s == Side::Outside && !r {
            *s = Side::Inside;
        }
    }
}

#[cfg(test)]
#[path = "contact_grid_tests.rs"]
mod tests;
