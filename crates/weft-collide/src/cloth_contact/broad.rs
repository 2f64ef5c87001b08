//! The broad phase of cloth contact: a Verlet list of vertex–triangle and edge–edge pairs
//! whose swept boxes lie within the contact reach plus a skin, found through a uniform grid of
//! the elements' boxes (sorted `(cell, element)` entries, one binary search per cell).
//!
//! Invariant (the list's guarantee): at a build, each member's box Bᵥ is that of its substep
//! path `x_prev → x`, and every pair of elements that share no vertex whose boxes (the union
//! of their vertices' Bᵥ) lie within D = reach + skin of each other on every axis is listed.
//! The list is kept while every member's `x_prev` and `x` stay inside Bᵥ grown by skin / 2
//! ([`Candidates::holds`]): then any two elements' current path boxes lie inside their build
//! boxes grown by skin / 2, so two elements whose current boxes come within the reach on every
//! axis were within D at the build, and are listed. Both the contacts (distance below the
//! reach) and the continuous check (paths whose boxes meet) need no pair beyond those.
//!
//! The list is built in parallel and comes out sorted (by vertex, then triangle; by edge, then
//! edge), so it does not depend on the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::topology::Elements;

/// An axis-aligned box `(lo, hi)`.
type Aabb = (DVec3, DVec3);

/// The listed pairs and what they were listed for.
#[derive(Clone, Debug, Default)]
pub(crate) struct Candidates {
    /// Vertex–triangle pairs: (particle, triangle index), with the distance each keeps.
    pub vf: Vec<(u32, u32, f64)>,
    /// Edge–edge pairs: (edge index, edge index), the first lower, with the distance kept.
    pub ee: Vec<(u32, u32, f64)>,
    /// Per particle, its path's box at the build (members only).
    anchors: Vec<Aabb>,
    /// The skin of the current list (m); `None`: no list.
    skin: Option<f64>,
    /// Lists built so far.
    pub builds: u64,
}

impl Candidates {
    /// Whether the list holds for the paths `prev → x` (see the module's invariant).
    pub(crate) fn holds(&self, el: &Elements, prev: &[DVec3], x: &[DVec3]) -> bool {
        let Some(skin) = self.skin else {
            return false;
        };
        let half = DVec3::splat(0.5 * skin);
        el.vertices.par_iter().all(|&v| {
            let i = v as usize;
            let (lo, hi) = self.anchors[i];
            let (lo, hi) = (lo - half, hi + half);
            let inside = |p: DVec3| p.cmpge(lo).all() && p.cmple(hi).all();
            inside(prev[i]) && inside(x[i])
        })
    }

    /// Drops the list: the next check rebuilds it.
    pub(crate) fn invalidate(&mut self) {
        self.skin = None;
    }

    /// Lists every pair within `reach + skin` for the paths `prev → x`; `target(a, b)` gives
    /// the distance a pair keeps from the two elements' first particles (`a` the vertex's or
    /// first edge's).
    pub(crate) fn build(
        &mut self,
        el: &Elements,
        prev: &[DVec3],
        x: &[DVec3],
        reach: f64,
        skin: f64,
        target: impl Fn(Pair) -> f64 + Sync,
    ) {
        self.builds += 1;
        self.anchors.resize(prev.len(), (DVec3::ZERO, DVec3::ZERO));
        for &v in &el.vertices {
            let i = v as usize;
            self.anchors[i] = (prev[i].min(x[i]), prev[i].max(x[i]));
        }
        let anchors = &self.anchors;
        let union = |ids: &[u32]| {
            ids.iter().fold(
                (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), &i| (lo.min(anchors[i as usize].0), hi.max(anchors[i as usize].1)),
            )
        };
        let reach_d = reach + skin;
        let tri_boxes: Vec<Aabb> = el.triangles.par_iter().map(|t| union(t)).collect();
        let edge_boxes: Vec<Aabb> = el.edges.par_iter().map(|e| union(e)).collect();
        // Cells about as large as a triangle's grown box: each box spans a few cells.
        let mean = tri_boxes
            .iter()
            .map(|(lo, hi)| (*hi - *lo).max_element())
            .sum::<f64>()
            / tri_boxes.len().max(1) as f64;
        let cell = (mean + 2.0 * reach_d).max(1e-6);
        let grow = DVec3::splat(reach_d);
        let tri_grid = Grid::new(cell, &tri_boxes, grow);
        let edge_grid = Grid::new(cell, &edge_boxes, grow);
        let near =
            |a: &Aabb, b: &Aabb| (a.0 - grow).cmple(b.1).all() && (b.0 - grow).cmple(a.1).all();
        self.vf = el
            .vertices
            .par_iter()
            .map_init(Vec::new, |found, &v| {
                let b = anchors[v as usize];
                tri_grid.near(b, found);
                (found.iter().copied())
                    .filter(|&f| {
                        let t = el.triangles[f as usize];
                        !t.contains(&v) && near(&b, &tri_boxes[f as usize])
                    })
                    .map(|f| (v, f, target(Pair::VertexFace(v, f))))
                    .collect::<Vec<_>>()
            })
            .flatten_iter()
            .collect();
        self.ee = (0..el.edges.len() as u32)
            .into_par_iter()
            .map_init(Vec::new, |found, e| {
                let b = edge_boxes[e as usize];
                let [a0, a1] = el.edges[e as usize];
                edge_grid.near(b, found);
                (found.iter().copied())
                    .filter(|&g| {
                        let [b0, b1] = el.edges[g as usize];
                        g > e
                            && a0 != b0
                            && a0 != b1
                            && a1 != b0
                            && a1 != b1
                            && near(&b, &edge_boxes[g as usize])
                    })
                    .map(|g| (e, g, target(Pair::EdgeEdge(e, g))))
                    .collect::<Vec<_>>()
            })
            .flatten_iter()
            .collect();
        self.skin = Some(skin);
    }
}

/// A pair of elements, by index.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Pair {
    /// A particle and a triangle index.
    VertexFace(u32, u32),
    /// Two edge indices.
    EdgeEdge(u32, u32),
}

/// Element boxes (grown) binned by the grid cells they touch: `(cell key, element)` sorted.
struct Grid {
    cell: f64,
    entries: Vec<(u64, u32)>,
}

impl Grid {
    /// Bins `boxes`, each grown by `grow`, in cells of side `cell`.
    fn new(cell: f64, boxes: &[Aabb], grow: DVec3) -> Self {
        let mut grid = Self {
            cell,
            entries: Vec::with_capacity(boxes.len() * 4),
        };
        let mut entries = std::mem::take(&mut grid.entries);
        for (k, (lo, hi)) in boxes.iter().enumerate() {
            grid.for_cells(*lo - grow, *hi + grow, |key| entries.push((key, k as u32)));
        }
        entries.par_sort_unstable();
        grid.entries = entries;
        grid
    }

    /// Calls `f` with the key of every cell box `lo..hi` touches (none for a box that is not a
    /// number).
    fn for_cells(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(u64)) {
        let (a, b) = ((lo / self.cell).floor(), (hi / self.cell).floor());
        if !(a.is_finite() && b.is_finite()) {
            return;
        }
        let (a, b) = (a.as_i64vec3(), b.as_i64vec3());
        for x in a.x..=b.x {
            for y in a.y..=b.y {
                for z in a.z..=b.z {
                    f(key(x, y, z));
                }
            }
        }
    }

    /// The elements binned in the cells box `b` touches, each once, ascending, into `found`.
    fn near(&self, b: Aabb, found: &mut Vec<u32>) {
        found.clear();
        self.for_cells(b.0, b.1, |k| {
            let start = self.entries.partition_point(|&(c, _)| c < k);
            found.extend(
                self.entries[start..]
                    .iter()
                    .take_while(|&&(c, _)| c == k)
                    .map(|&(_, t)| t),
            );
        });
        found.sort_unstable();
        found.dedup();
    }
}

/// A cell's key: 21 bits of each coordinate (cells that share a key share a bin, which costs
/// a box test, never a pair).
fn key(x: i64, y: i64, z: i64) -> u64 {
    let m = (1u64 << 21) - 1;
    ((x as u64) & m) | (((y as u64) & m) << 21) | (((z as u64) & m) << 42)
}
