//! An independent measure of cloth interpenetration: how many mesh edges pass through a
//! triangle they share no vertex with, and how close non-adjacent elements come.
//!
//! It measures contact and shares nothing with it: its own broad phase (triangles binned in a
//! hash table of grid cells, one search a triangle for the edges and vertices it owns, each
//! search narrowed to the closest pair found so far) and exact-predicate style tests in f64
//! (signed volumes for the crossings, Ericson's closest points for the distances, "Real-Time
//! Collision Detection" §5.1.5 and §5.1.9). A crossing is an edge whose two end points lie
//! strictly on opposite sides of a triangle's plane and whose line passes strictly inside the
//! triangle; touching and coplanar configurations are not crossings. Integer counts and a
//! minimum: the answer does not depend on the thread count.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, I64Vec3};
use rayon::prelude::*;

/// What [`measure`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Crossings {
    /// Edge–triangle crossings between elements that share no vertex.
    pub crossings: usize,
    /// The closest approach between non-adjacent elements (vertex–triangle and edge–edge
    /// pairs that share no vertex) when it is below the `reach` asked for, capped at the
    /// longest edge (m).
    pub closest: Option<f64>,
}

/// Counts the crossings of `triangles` (indices into `positions`) and the closest approach
/// below `reach` (at most the longest edge) between elements that share no vertex.
pub fn measure(positions: &[DVec3], triangles: &[[u32; 3]], reach: f64) -> Crossings {
    let own: Vec<u32> = (0..positions.len() as u32).collect();
    measure_joined(positions, triangles, &own, reach)
}

/// [`measure`] where particles are joined into vertices (`vertex[i]`, e.g. the two sides of
/// a closed seam): elements are adjacent when they share a vertex so joined, while every
/// particle keeps its own position. Edges and triangles a join collapses are left out.
/// Measured at the particles' own positions, a seam that opens a little neither makes nor
/// hides a crossing, as moving the joined particles onto one would.
pub fn measure_joined(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex: &[u32],
    reach: f64,
) -> Crossings {
    let j = |i: u32| vertex[i as usize];
    let kept: Vec<[u32; 3]> = (triangles.iter().copied())
        .filter(|t| j(t[0]) != j(t[1]) && j(t[1]) != j(t[2]) && j(t[2]) != j(t[0]))
        .collect();
    let triangles = &kept[..];
    let owned = Owned::new(positions.len(), triangles);
    if !owned.any_edge {
        return Crossings::default();
    }
    let mesh = Joined {
        x: positions,
        triangles,
        vertex,
    };
    let longest = triangles
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[a, b]| positions[a as usize].distance(positions[b as usize]))
        .fold(0.0_f64, f64::max);
    // The reach is capped at the longest edge: beyond it every vertex would be near a whole
    // neighbourhood of its own cloth, and the search would grow with the square of the mesh.
    let reach = if reach.is_finite() {
        reach.clamp(0.0, longest)
    } else {
        0.0
    };
    let bins = Bins::new(positions, triangles, longest.max(reach).max(1e-9));
    // One search a triangle for the edges and vertices it owns: the crossings of its edges,
    // and, within the reach, the closest triangle to its vertices and edge to its edges. Each
    // search goes only as far as the closest pair any task has found so far (`Closest`): a
    // pair no closer cannot lower the minimum, so the answer is the same at any split and in
    // any order.
    let shared = Closest::new(reach);
    let (crossings, near) = (0..triangles.len())
        .into_par_iter()
        .map_init(Vec::new, |found, t| {
            bins.owned_by(&mesh, t, owned.mask[t], (found, &shared))
        })
        .reduce(|| (0, f64::INFINITY), |a, b| (a.0 + b.0, a.1.min(b.1)));
    let closest = if reach > 0.0 {
        // Particles in no triangle (a triangle collapsed by a join): their own searches.
        let orphans = (owned.orphans.par_iter())
            .map_init(
                || Near::new(near.min(reach)),
                |n, &v| {
                    let d = bins.vertex_closest(&mesh, v, n);
                    n.keep(d)
                },
            )
            .min_by(f64::total_cmp)
            .unwrap_or(f64::INFINITY);
        Some(near.min(orphans)).filter(|&d| d < reach)
    } else {
        None
    };
    Crossings { crossings, closest }
}

/// Which of its edges and vertices each triangle searches for: every edge and every particle
/// is owned by the first triangle that holds it.
struct Owned {
    /// Per triangle: bit k for its edge from corner k to corner k + 1, bit 3 + k for its
    /// corner k.
    mask: Vec<u8>,
    /// Particles no triangle holds.
    orphans: Vec<u32>,
    /// Whether any triangle owns an edge.
    any_edge: bool,
}

impl Owned {
    fn new(n: usize, triangles: &[[u32; 3]]) -> Self {
        let mut mask = vec![0u8; triangles.len()];
        let mut sides: Vec<(u32, u32, u32, u8)> = (triangles.iter().enumerate())
            .flat_map(|(t, tri)| {
                (0..3).map(move |k| {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    (a.min(b), a.max(b), t as u32, k as u8)
                })
            })
            .filter(|&(a, b, _, _)| a != b)
            .collect();
        sides.sort_unstable();
        let any_edge = !sides.is_empty();
        for (i, &(a, b, t, k)) in sides.iter().enumerate() {
            if i == 0 || (sides[i - 1].0, sides[i - 1].1) != (a, b) {
                mask[t as usize] |= 1 << k;
            }
        }
        let mut held = vec![false; n];
        for (t, tri) in triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                if !std::mem::replace(&mut held[v as usize], true) {
                    mask[t] |= 8 << k;
                }
            }
        }
        let orphans = (0..n as u32).filter(|&v| !held[v as usize]).collect();
        Self {
            mask,
            orphans,
            any_edge,
        }
    }
}

/// The measured mesh: positions per particle, triangles, and each particle's vertex.
struct Joined<'a> {
    x: &'a [DVec3],
    triangles: &'a [[u32; 3]],
    vertex: &'a [u32],
}

impl Joined<'_> {
    /// Whether triangle `t` holds a vertex of particle `a`.
    #[inline]
    fn holds(&self, t: &[u32; 3], a: u32) -> bool {
        let v = self.vertex[a as usize];
        t.iter().any(|&i| self.vertex[i as usize] == v)
    }

    /// Whether particles `a` and `b` are one vertex.
    #[inline]
    fn same(&self, a: u32, b: u32) -> bool {
        self.vertex[a as usize] == self.vertex[b as usize]
    }
}

/// One task's search for the closest approach: its candidate buffer and the distance it
/// searches within, the closest pair it has found so far (at most the reach).
struct Near {
    found: Vec<u32>,
    within: f64,
}

impl Near {
    fn new(reach: f64) -> Self {
        Self {
            found: Vec::new(),
            within: reach,
        }
    }

    /// Narrows the search to a pair found `d` apart; returns `d`.
    fn keep(&mut self, d: f64) -> f64 {
        self.within = self.within.min(d);
        d
    }
}

/// The closest approach any task has found so far, shared between tasks: a distance (not
/// negative, so its bits order as its value) narrowed with an atomic minimum.
struct Closest(AtomicU64);

impl Closest {
    fn new(reach: f64) -> Self {
        Self(AtomicU64::new(reach.max(0.0).to_bits()))
    }

    fn get(&self) -> f64 {
        f64::from_bits(self.0.load(Ordering::Relaxed))
    }

    /// Narrows it to a pair found `d` apart.
    fn keep(&self, d: f64) {
        if d >= 0.0 && d.is_finite() {
            self.0.fetch_min(d.to_bits(), Ordering::Relaxed);
        }
    }
}

/// The distance between the boxes `lo1..hi1` and `lo2..hi2` (0 where they overlap): no point
/// of one is closer to a point of the other.
fn box_gap(lo1: DVec3, hi1: DVec3, lo2: DVec3, hi2: DVec3) -> f64 {
    (lo2 - hi1).max(lo1 - hi2).max(DVec3::ZERO).length()
}

/// Triangles binned by the grid cells their boxes touch: `(cell key, triangle)` entries in a
/// hash table, counting-sorted by bucket (each bucket in triangle order).
struct Bins {
    cell: f64,
    /// Bits of the bucket index.
    bits: u32,
    /// Where each bucket's entries start (one more for the end).
    starts: Vec<u32>,
    entries: Vec<(u64, u32)>,
    /// Per triangle, its box.
    boxes: Vec<(DVec3, DVec3)>,
    /// Per triangle, the cell of its box's low corner.
    low: Vec<I64Vec3>,
}

impl Bins {
    fn new(positions: &[DVec3], triangles: &[[u32; 3]], cell: f64) -> Self {
        let boxes: Vec<(DVec3, DVec3)> = (triangles.par_iter())
            .map(|tri| bounds(tri.iter().map(|&i| positions[i as usize])))
            .collect();
        let mut low = vec![I64Vec3::ZERO; triangles.len()];
        let mut raw = Vec::with_capacity(triangles.len() * 2);
        for (t, &(lo, hi)) in boxes.iter().enumerate() {
            if let Some((a, b)) = cells(lo, hi, cell) {
                low[t] = a;
                for_cells(a, b, |c| raw.push((key(c), t as u32)));
            }
        }
        let bits = raw.len().max(16).next_power_of_two().trailing_zeros();
        let mut starts = vec![0u32; (1 << bits) + 1];
        for &(k, _) in &raw {
            starts[bucket(k, bits) + 1] += 1;
        }
        for b in 1..starts.len() {
            starts[b] += starts[b - 1];
        }
        let mut fill = starts.clone();
        let mut entries = vec![(0, 0); raw.len()];
        for &(k, t) in &raw {
            let b = bucket(k, bits);
            entries[fill[b] as usize] = (k, t);
            fill[b] += 1;
        }
        Bins {
            cell,
            bits,
            starts,
            entries,
            boxes,
            low,
        }
    }

    /// The triangles whose boxes overlap the box `lo..hi`, each once, into `found`: a triangle
    /// is taken only in its home cell, the larger of the two boxes' low-corner cells on each
    /// axis (the cell of the boxes' overlap's low corner, which both touch).
    fn near(&self, lo: DVec3, hi: DVec3, found: &mut Vec<u32>) {
        found.clear();
        let Some((a, b)) = cells(lo, hi, self.cell) else {
            return;
        };
        for_cells(a, b, |c| {
            let k = key(c);
            let i = bucket(k, self.bits);
            let bucket = &self.entries[self.starts[i] as usize..self.starts[i + 1] as usize];
            for &(e, t) in bucket {
                if e == k && a.max(self.low[t as usize]) == c {
                    let (tlo, thi) = self.boxes[t as usize];
                    if tlo.cmple(hi).all() && lo.cmple(thi).all() {
                        found.push(t);
                    }
                }
            }
        });
    }

    /// The closest triangle to vertex `v` that does not hold it, if closer than
    /// `near.within` (else at least that, or infinity).
    fn vertex_closest(&self, m: &Joined, v: u32, near: &mut Near) -> f64 {
        let x = m.x;
        let (p, r) = (x[v as usize], near.within);
        self.near(p - r, p + r, &mut near.found);
        let mut best = f64::INFINITY;
        for &t in &near.found {
            let tri = m.triangles[t as usize];
            if m.holds(&tri, v) {
                continue;
            }
            let (lo, hi) = self.boxes[t as usize];
            if box_gap(p, p, lo, hi) < best.min(r) {
                best = best.min(point_triangle_distance(p, tri.map(|i| x[i as usize])));
            }
        }
        best
    }

    /// Triangle `t`'s search for what it owns (`mask`, see [`Owned`]): the crossings of its
    /// edges through triangles that share no vertex with them, and the closest triangle to its
    /// vertices and edge to its edges that share none, if closer than the closest pair found
    /// so far (else at least that, or infinity), to which `shared` is narrowed.
    fn owned_by(
        &self,
        m: &Joined,
        t: usize,
        mask: u8,
        (found, shared): (&mut Vec<u32>, &Closest),
    ) -> (usize, f64) {
        if mask == 0 {
            return (0, f64::INFINITY);
        }
        let (x, tri, r) = (m.x, m.triangles[t], shared.get());
        let (lo, hi) = self.boxes[t];
        self.near(lo - r, hi + r, found);
        let (mut count, mut best) = (0, f64::INFINITY);
        for k in (0..3).filter(|k| mask & (1 << k) != 0) {
            // The edge from its lower particle, as every search of it has read it.
            let (a, b) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
            let (p, q) = (x[a as usize], x[b as usize]);
            let (elo, ehi) = (p.min(q), p.max(q));
            for &c in found.iter() {
                let other = m.triangles[c as usize];
                let (clo, chi) = self.boxes[c as usize];
                if clo.cmple(ehi).all()
                    && elo.cmple(chi).all()
                    && !m.holds(&other, a)
                    && !m.holds(&other, b)
                    && segment_crosses(p, q, other.map(|i| x[i as usize]))
                {
                    count += 1;
                }
                if r <= 0.0 || box_gap(elo, ehi, clo, chi) >= best.min(r) {
                    continue;
                }
                for j in 0..3 {
                    let (c, d) = (other[j], other[(j + 1) % 3]);
                    if m.same(c, a) || m.same(c, b) || m.same(d, a) || m.same(d, b) {
                        continue;
                    }
                    let (pc, pd) = (x[c as usize], x[d as usize]);
                    if box_gap(elo, ehi, pc.min(pd), pc.max(pd)) < best.min(r) {
                        best = best.min(segment_distance(p, q, pc, pd));
                    }
                }
            }
        }
        if r > 0.0 {
            for k in (0..3).filter(|k| mask & (8 << k) != 0) {
                let (v, p) = (tri[k], x[tri[k] as usize]);
                for &c in found.iter() {
                    let (clo, chi) = self.boxes[c as usize];
                    let other = m.triangles[c as usize];
                    if box_gap(p, p, clo, chi) < best.min(r) && !m.holds(&other, v) {
                        best = best.min(point_triangle_distance(p, other.map(|i| x[i as usize])));
                    }
                }
            }
        }
        shared.keep(best);
        (count, best)
    }
}

/// A cell's key: the three coordinates' low 21 bits interleaved into one word (distinct cells
/// may share a key far apart; they only add candidates, which the home cell turns away).
fn key(c: I64Vec3) -> u64 {
    let m = |v: i64| (v as u64) & 0x1f_ffff;
    (m(c.x) << 42) | (m(c.y) << 21) | m(c.z)
}

/// The hash bucket of key `k` in a table of 2^`bits` buckets.
fn bucket(k: u64, bits: u32) -> usize {
    (k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - bits)) as usize
}

/// The first and last cells (of edge `cell`) the box `lo..hi` touches, if it is finite.
fn cells(lo: DVec3, hi: DVec3, cell: f64) -> Option<(I64Vec3, I64Vec3)> {
    let (a, b) = ((lo / cell).floor(), (hi / cell).floor());
    (a.is_finite() && b.is_finite()).then(|| (a.as_i64vec3(), b.as_i64vec3()))
}

/// Calls `f` with every cell from `a` to `b` (inclusive on every axis).
fn for_cells(a: I64Vec3, b: I64Vec3, mut f: impl FnMut(I64Vec3)) {
    for x in a.x..=b.x {
        for y in a.y..=b.y {
            for z in a.z..=b.z {
                f(I64Vec3::new(x, y, z));
            }
        }
    }
}

fn bounds(points: impl Iterator<Item = DVec3>) -> (DVec3, DVec3) {
    points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    })
}

/// Six times the signed volume of the tetrahedron `a b c d`.
fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a)
}

/// Whether the segment `p q` passes strictly through the triangle `t`.
fn segment_crosses(p: DVec3, q: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
    if !(sp > 0.0 && sq < 0.0 || sp < 0.0 && sq > 0.0) {
        return false;
    }
    // The line p q against the three edges: all the same strict sign means inside.
    let (u, v, w) = (orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a));
    u > 0.0 && v > 0.0 && w > 0.0 || u < 0.0 && v < 0.0 && w < 0.0
}

/// The distance from `p` to the triangle `a b c` (Ericson §5.1.5).
fn point_triangle_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return p.distance(b + (c - b) * t);
    }
    let denom = 1.0 / (va + vb + vc);
    p.distance(a + ab * (vb * denom) + ac * (vc * denom))
}

/// The distance between the segments `p1 q1` and `p2 q2` (Ericson §5.1.9).
fn segment_distance(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    const EPS: f64 = 1e-30;
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > EPS {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p1 + d1 * s).distance(p2 + d2 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n × n grid of squares of side `h` in the plane z = `z`, particle indices from `base`.
    fn sheet(n: u32, h: f64, z: f64, base: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut x = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                x.push(DVec3::new(i as f64 * h, j as f64 * h, z));
            }
        }
        let id = |i: u32, j: u32| base + j * (n + 1) + i;
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (x, t)
    }

    #[test]
    fn a_flat_sheet_has_no_crossings_and_its_spacing_as_closest_approach() {
        let (x, t) = sheet(8, 0.1, 0.0, 0);
        let m = measure(&x, &t, 1.0);
        assert_eq!(m.crossings, 0);
        // A vertex's nearest triangle without it lies across one of its neighbours' far edges:
        // the diagonal triangles put it h / √2 away (the square's half diagonal).
        let d = m.closest.expect("within reach");
        assert!((d - 0.1 / 2f64.sqrt()).abs() < 1e-12, "{d}");
    }

    #[test]
    fn a_particle_in_no_triangle_is_measured_too() {
        let (mut x, t) = sheet(4, 0.1, 0.0, 0);
        // A lone particle 1 mm above the sheet's middle: nearer than any of the sheet's own.
        x.push(DVec3::new(0.2, 0.2, 0.001));
        let m = measure(&x, &t, 0.05);
        assert_eq!(m.closest, Some(0.001));
        assert_eq!(m.crossings, 0);
    }

    #[test]
    fn two_parallel_sheets_report_their_gap() {
        let (mut x, mut t) = sheet(4, 0.1, 0.0, 0);
        let (x2, t2) = sheet(4, 0.1, 0.002, x.len() as u32);
        x.extend(x2);
        t.extend(t2);
        let m = measure(&x, &t, 0.01);
        assert_eq!(m.crossings, 0);
        assert!((m.closest.expect("within reach") - 0.002).abs() < 1e-12);
        // Nothing within a reach smaller than the gap.
        assert_eq!(measure(&x, &t, 0.001).closest, None);
    }

    #[test]
    fn a_sheet_pushed_through_another_is_counted_edge_by_edge() {
        let (mut x, mut t) = sheet(4, 0.1, 0.0, 0);
        // A small vertical square (two triangles) in the plane y = 0.15, x in [0.12, 0.17],
        // z in [-0.05, 0.05], through the first sheet's cell (1, 1).
        let base = x.len() as u32;
        x.extend([
            DVec3::new(0.12, 0.15, -0.05),
            DVec3::new(0.17, 0.15, -0.05),
            DVec3::new(0.17, 0.15, 0.05),
            DVec3::new(0.12, 0.15, 0.05),
        ]);
        t.push([base, base + 1, base + 2]);
        t.push([base, base + 2, base + 3]);
        // The square's two sides and its diagonal each pierce one of the cell's triangles (at
        // x = 0.12, 0.17 and 0.145, none on the cell's diagonal y = x); the cell's diagonal
        // (0.1, 0.1)–(0.2, 0.2) pierces the square at (0.15, 0.15, 0), inside its lower
        // triangle (off the square's diagonal, which meets z = 0 at x = 0.145). No other edge
        // of the sheet spans y = 0.15 within x in [0.12, 0.17].
        let m = measure(&x, &t, 0.0);
        assert_eq!(m.crossings, 4, "{m:?}");
        // Lift the square clear: no crossings.
        for p in &mut x[base as usize..] {
            p.z += 0.2;
        }
        assert_eq!(measure(&x, &t, 0.0).crossings, 0);
    }

    /// A deterministic wave over the plane, between −1 and 1.
    fn wave(p: DVec3) -> f64 {
        (p.x * 17.0).sin() * (p.y * 13.0).cos()
    }

    /// Two 6 × 6 sheets of 0.1 m cells, the second at height `z` and off the first one's grid
    /// (so no edge meets a triangle's boundary), each particle `i` at `p` raised by
    /// `bump(p, i, s)`, s = 1 in the first sheet and −1 in the second.
    fn bumped_pair(z: f64, bump: impl Fn(DVec3, usize, f64) -> f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let (mut x, mut t) = sheet(6, 0.1, 0.0, 0);
        let (x2, t2) = sheet(6, 0.1, z, x.len() as u32);
        x.extend(x2.into_iter().map(|p| p + DVec3::new(0.037, 0.021, 0.0)));
        t.extend(t2);
        let n = x.len() / 2;
        for (i, p) in x.iter_mut().enumerate() {
            p.z += bump(*p, i, if i < n { 1.0 } else { -1.0 });
        }
        (x, t)
    }

    /// Every edge of `triangles` once, its ends in order.
    fn unique_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .filter(|[a, b]| a != b)
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    #[test]
    fn crossings_match_a_brute_force_count_on_a_crumpled_pair() {
        // Opposite bumps in two sheets in one plane, so they interpenetrate in patches.
        let (x, t) = bumped_pair(0.0, |p, i, s| s * 0.03 * wave(p) + 0.01 * (i % 3) as f64);
        let edges = unique_edges(&t);
        let brute = edges
            .iter()
            .map(|&[a, b]| {
                t.iter()
                    .filter(|tri| !tri.contains(&a) && !tri.contains(&b))
                    .filter(|tri| {
                        segment_crosses(x[a as usize], x[b as usize], tri.map(|i| x[i as usize]))
                    })
                    .count()
            })
            .sum::<usize>();
        assert!(brute > 20, "the pair must interpenetrate: {brute}");
        assert_eq!(measure(&x, &t, 0.0).crossings, brute);
        // With the closest approach searched too, each triangle's search reaches further.
        assert_eq!(measure(&x, &t, 0.05).crossings, brute);
    }

    #[test]
    fn the_closest_approach_is_the_brute_force_minimum_on_any_thread_count() {
        // Two sheets 2 cm apart, bumped towards each other where they meet.
        let (x, t) = bumped_pair(0.02, |p, _, s| s * 0.008 * wave(p).max(0.0));
        let edges = unique_edges(&t);
        let p = |i: u32| x[i as usize];
        let mut brute = f64::INFINITY;
        for v in 0..x.len() as u32 {
            for tri in t.iter().filter(|tri| !tri.contains(&v)) {
                brute = brute.min(point_triangle_distance(p(v), tri.map(p)));
            }
        }
        for &[a, b] in &edges {
            for &[c, d] in &edges {
                if c != a && c != b && d != a && d != b {
                    brute = brute.min(segment_distance(p(a), p(b), p(c), p(d)));
                }
            }
        }
        assert!(brute > 1e-3 && brute < 0.015, "{brute}");
        assert_eq!(measure(&x, &t, 0.05).crossings, 0);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let m = pool.install(|| measure(&x, &t, 0.05));
            assert_eq!(m.closest, Some(brute), "{threads} threads");
        }
        // Beyond the reach: none.
        assert_eq!(measure(&x, &t, brute * 0.99).closest, None);
    }

    #[test]
    fn segment_distance_matches_closed_forms() {
        let d = segment_distance(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, -1.0, 0.3),
            DVec3::new(0.5, 1.0, 0.3),
        );
        assert!((d - 0.3).abs() < 1e-15);
        let d = segment_distance(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
        );
        assert!((d - 1.0).abs() < 1e-15);
    }
}
