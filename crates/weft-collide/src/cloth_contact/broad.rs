//! The broad phase of cloth contact: a Verlet list of vertex–triangle and edge–edge pairs
//! that can come within the distance they keep before the list is rebuilt, found through a
//! uniform grid of the elements' boxes (a hash table of `(cell, element)` entries) and kept
//! only where the elements' exact distance says so.
//!
//! Invariant (the list's guarantee): at a build each member particle i gets a box Bᵢ, that of
//! its substep path `x_prev → x` grown by skin / 2, an anchor aᵢ, the path's midpoint, and a
//! radius Rᵢ, half the path plus skin / 2; an element's box B_E is the union of its corners'
//! and its radius R_E the largest of theirs. Every pair of elements that share no vertex whose
//! boxes lie within the reach (the largest distance kept) of each other on every axis and
//! whose distance at the anchors d_a is at most t + R_A + R_B, with t the distance the pair
//! keeps, is listed with d_a. The list is kept while every member's `x_prev` and `x` lie
//! inside Bᵢ and within Rᵢ of aᵢ ([`Candidates::holds`]). Then so does every point of the
//! straight path `x_prev → x` (boxes and balls are convex), and so does a closest point of
//! an element, a convex combination of its corners, inside B_E and within R_E of where it was
//! at the anchors. So anywhere on the substep's paths an unlisted pair is either more than
//! the reach apart on some axis, or at least d_a − R_A − R_B > t apart: it does not come
//! within t. Both the contacts (distance below t) and the continuous check (paths that come
//! within a fraction of t) need no pair beyond those. A fast particle enlarges only its own
//! box and radius, so only its own elements' pairs; the boxes keep a long straight path from
//! listing pairs beside it, the distance keeps box corners from listing pairs on a diagonal.
//! With the displacements δᵢ from the anchors measured at a check ([`Candidates::measure`]),
//! d_a − max δ (first) − max δ (second) bounds a listed pair's distance from below
//! ([`Candidates::lower_bound`]), which spares the contacts and the check a distance.
//!
//! The grid only narrows the search: the elements' boxes grown by half the reach overlap
//! exactly when the boxes lie within the reach, and a pair is taken in one cell alone, the one
//! holding the low corner of the two boxes' overlap. A box spanning too many cells is not
//! binned but tried against every query, and a query spanning too many tries every element.
//!
//! The list is built in parallel, in an order fixed by the elements and the grid (by vertex,
//! then the cells it touches; by edge, then its cells), so it does not depend on the thread
//! count.

use glam::{DVec3, I64Vec3};
use rayon::prelude::*;

use super::geometry::{point_triangle_distance, segment_distance};
use super::topology::Elements;

/// An axis-aligned box `(lo, hi)`.
type Aabb = (DVec3, DVec3);

/// A box spanning more cells than this is not binned: every query tries it.
const BIN_LIMIT: f64 = 64.0;

/// A query spanning more cells than this tries every element instead.
const QUERY_LIMIT: f64 = 128.0;

/// Slack for rounding (m), added to the listing distance and taken off every
/// [`Candidates::lower_bound`]: distances are rounded to within a few ulps of coordinates up
/// to kilometres (under 1e-12 m), so 1 nm keeps both sides of the invariant in floating point
/// while listing and pruning as the exact ones would.
pub(crate) const ROUNDING: f64 = 1e-9;

/// A listed pair: the two elements (vertex and triangle, or two edges, the first lower), the
/// distance the pair keeps, and their distance at the anchors.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Listed {
    /// The vertex (particle index) or the first edge's index.
    pub a: u32,
    /// The triangle's or the second edge's index.
    pub b: u32,
    /// The distance the pair keeps (m).
    pub keep: f64,
    /// Their distance at the anchors (m).
    pub apart: f64,
}

/// The listed pairs and what they were listed for.
#[derive(Clone, Debug, Default)]
pub(crate) struct Candidates {
    /// Vertex–triangle pairs.
    pub vf: Vec<Listed>,
    /// Edge–edge pairs.
    pub ee: Vec<Listed>,
    /// Per particle, its anchor aᵢ (members only).
    anchors: Vec<DVec3>,
    /// Per particle, its radius Rᵢ (members only).
    radius: Vec<f64>,
    /// Per particle, its path's box grown by half the skin (members only).
    boxes: Vec<Aabb>,
    /// Per particle, δᵢ at the last [`Self::measure`] (members only).
    moved: Vec<f64>,
    /// Whether a list is built (and not dropped since).
    built: bool,
    /// Lists built so far.
    pub builds: u64,
}

impl Candidates {
    /// Whether the list holds for the paths `prev → x` (see the module's invariant); records
    /// each member's displacement δᵢ = max(|x_prevᵢ − aᵢ|, |xᵢ − aᵢ|).
    pub(crate) fn holds(&mut self, el: &Elements, prev: &[DVec3], x: &[DVec3]) -> bool {
        if !self.built {
            return false;
        }
        self.measure(prev, x);
        let (moved, radius, boxes) = (&self.moved, &self.radius, &self.boxes);
        el.vertices.iter().all(|&v| {
            let i = v as usize;
            let (lo, hi) = boxes[i];
            let inside = |p: DVec3| p.cmpge(lo).all() && p.cmple(hi).all();
            moved[i] <= radius[i] && inside(prev[i]) && inside(x[i])
        })
    }

    /// Records each member's displacement δᵢ = max(|x_prevᵢ − aᵢ|, |xᵢ − aᵢ|) from its
    /// anchor, for [`Self::lower_bound`] along the paths `prev → x`.
    pub(crate) fn measure(&mut self, prev: &[DVec3], x: &[DVec3]) {
        (self
            .moved
            .par_iter_mut()
            .zip(&self.anchors)
            .zip(prev)
            .zip(x))
        .for_each(|(((m, a), p), x)| *m = p.distance(*a).max(x.distance(*a)));
    }

    /// Records each member's distance δᵢ from its anchor at `x` alone (after this, a
    /// [`Self::lower_bound`] holds at `x`, not along the substep's paths).
    pub(crate) fn measure_at(&mut self, x: &[DVec3]) {
        (self.moved.par_iter_mut().zip(&self.anchors).zip(x))
            .for_each(|((m, a), x)| *m = x.distance(*a));
    }

    /// Drops the list: the next check rebuilds it.
    pub(crate) fn invalidate(&mut self) {
        self.built = false;
    }

    /// A lower bound on the distance of `pair`'s elements (corners `ids`, the first `split`
    /// one element's) at the positions of the last [`Self::measure`] (or
    /// [`Self::measure_at`]), less [`ROUNDING`] so that it holds in floating point too.
    #[inline]
    pub(crate) fn lower_bound(&self, pair: &Listed, ids: &[u32; 4], split: usize) -> f64 {
        let d = |k: usize| self.moved[ids[k] as usize];
        let first = (0..split).map(d).fold(0.0, f64::max);
        let second = (split..4).map(d).fold(0.0, f64::max);
        pair.apart - first - second - ROUNDING
    }

    /// Lists every pair that can come within the distance it keeps (`keep(pair)`, at most
    /// `reach`) while each particle stays inside its path's (`prev → x`) box grown by `skin` /
    /// 2 and within half its path plus `skin` / 2 of the path's midpoint (see the module's
    /// invariant).
    pub(crate) fn build(
        &mut self,
        el: &Elements,
        prev: &[DVec3],
        x: &[DVec3],
        reach: f64,
        skin: f64,
        keep: impl Fn(Pair) -> f64 + Sync,
    ) {
        self.builds += 1;
        let n = prev.len();
        self.anchors.resize(n, DVec3::ZERO);
        self.radius.resize(n, 0.0);
        self.moved.resize(n, 0.0);
        self.boxes.resize(n, (DVec3::ZERO, DVec3::ZERO));
        for &v in &el.vertices {
            let i = v as usize;
            let (a, r) = ball(prev[i], x[i], skin);
            self.anchors[i] = a;
            self.moved[i] = prev[i].distance(a).max(x[i].distance(a));
            self.radius[i] = r;
            self.boxes[i] = path_box(prev[i], x[i], skin);
        }
        let (anchors, radius, boxes) = (&self.anchors, &self.radius, &self.boxes);
        let at = |i: u32| anchors[i as usize];
        let half = DVec3::splat(0.5 * reach);
        // An element's box (its corners' boxes) grown by half the reach, and its radius.
        let grown = |ids: &[u32]| {
            let (mut lo, mut hi, mut r) = (DVec3::INFINITY, DVec3::NEG_INFINITY, 0.0f64);
            for &i in ids {
                let b = boxes[i as usize];
                (lo, hi) = (lo.min(b.0), hi.max(b.1));
                r = r.max(radius[i as usize]);
            }
            ((lo - half, hi + half), r)
        };
        let tris: Vec<(Aabb, f64)> = el.triangles.par_iter().map(|t| grown(t)).collect();
        let edges: Vec<(Aabb, f64)> = el.edges.par_iter().map(|e| grown(e)).collect();
        let (tri_grid, edge_grid) = rayon::join(|| Grid::new(&tris), || Grid::new(&edges));
        let (tris, edges, keep) = (&tris, &edges, &keep);
        // A pair of elements `ids` at distance `apart` at the anchors, with radii summing to
        // `r`: listed if within the distance it keeps (the reach first, which needs no
        // `keep`; not a number lists nothing either).
        let listed = |pair: Pair, (a, b): (u32, u32), apart: f64, r: f64| {
            let within = apart <= reach + r;
            if !within {
                return None;
            }
            let keep = keep(pair);
            (apart <= keep + r + ROUNDING).then_some(Listed { a, b, keep, apart })
        };
        // Vertex v against triangle f, found in cell `home` (`None`: its only cell, or outside
        // the grid).
        let vertex_face = |v: u32, vbox: &Aabb, rv: f64, f: u32, home: Option<I64Vec3>| {
            let (fbox, rf) = &tris[f as usize];
            let t = el.triangles[f as usize];
            if t.contains(&v) || !overlap(vbox, fbox) || !tri_grid.is_home(home, vbox, fbox) {
                return None;
            }
            let apart = point_triangle_distance(at(v), [at(t[0]), at(t[1]), at(t[2])]);
            listed(Pair::VertexFace(v, f), (v, f), apart, rv + rf)
        };
        self.vf = el
            .vertices
            .par_iter()
            .flat_map_iter(|&v| {
                let rv = radius[v as usize];
                let b = boxes[v as usize];
                let vbox = (b.0 - half, b.1 + half);
                let mut found = Vec::new();
                tri_grid.query(&vbox, tris.len() as u32, |f, home| {
                    found.extend(vertex_face(v, &vbox, rv, f, home));
                });
                found
            })
            .collect();
        // Edge e against a later edge g.
        let edge_edge = |e: u32, g: u32, home: Option<I64Vec3>| {
            let ((ebox, re), (gbox, rg)) = (&edges[e as usize], &edges[g as usize]);
            let ([a0, a1], [b0, b1]) = (el.edges[e as usize], el.edges[g as usize]);
            if a0 == b0
                || a0 == b1
                || a1 == b0
                || a1 == b1
                || !overlap(ebox, gbox)
                || !edge_grid.is_home(home, ebox, gbox)
            {
                return None;
            }
            let apart = segment_distance(at(a0), at(a1), at(b0), at(b1));
            listed(Pair::EdgeEdge(e, g), (e, g), apart, re + rg)
        };
        self.ee = (0..el.edges.len() as u32)
            .into_par_iter()
            .flat_map_iter(|e| {
                let mut found = Vec::new();
                edge_grid.query_after(e, &edges[e as usize].0, edges.len() as u32, |g, home| {
                    found.extend(edge_edge(e, g, home));
                });
                found
            })
            .collect();
        self.built = true;
    }
}

/// A particle's anchor and radius for its path `prev → x`: the path's midpoint, and half the
/// path plus `skin` / 2.
#[inline]
fn ball(prev: DVec3, x: DVec3, skin: f64) -> (DVec3, f64) {
    let a = prev.midpoint(x);
    (a, prev.distance(a).max(x.distance(a)) + 0.5 * skin)
}

/// A particle's box for its path `prev → x`: the path's box grown by `skin` / 2.
#[inline]
fn path_box(prev: DVec3, x: DVec3, skin: f64) -> Aabb {
    let g = DVec3::splat(0.5 * skin);
    (prev.min(x) - g, prev.max(x) + g)
}

/// A pair of elements, by index.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Pair {
    /// A particle and a triangle index.
    VertexFace(u32, u32),
    /// Two edge indices.
    EdgeEdge(u32, u32),
}

/// Whether two boxes overlap (touching counts).
#[inline]
fn overlap(a: &Aabb, b: &Aabb) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

/// Element boxes binned by the cells they touch, in a hash table of `(cell key, element)`
/// entries (counting-sorted by bucket, each bucket in element order), with the boxes that
/// span too many cells apart.
struct Grid {
    cell: f64,
    /// Bits of the bucket index.
    bits: u32,
    /// Where each bucket's entries start (one more for the end).
    starts: Vec<u32>,
    entries: Vec<(u64, u32)>,
    /// Elements tried against every query, ascending.
    big: Vec<u32>,
}

impl Grid {
    /// Bins the boxes of `elements` in cells about as large as the mean box.
    fn new(elements: &[(Aabb, f64)]) -> Self {
        let mean = (elements.iter())
            .map(|((lo, hi), _)| (*hi - *lo).max_element())
            .filter(|s| s.is_finite())
            .sum::<f64>()
            / elements.len().max(1) as f64;
        let mut grid = Self {
            cell: mean.max(1e-6),
            bits: 0,
            starts: Vec::new(),
            entries: Vec::new(),
            big: Vec::new(),
        };
        let mut raw = Vec::with_capacity(elements.len() * 8);
        for (k, (b, _)) in elements.iter().enumerate() {
            match grid.span(b, BIN_LIMIT) {
                Span::Cells(lo, hi) => raw.extend(cells(lo, hi).map(|c| (key(c), k as u32))),
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

    /// Calls `f(element, cell)` with every element whose box may overlap `b`: those binned in
    /// the cells `b` touches (with the cell, if more than one), then the unbinned ones
    /// (`None`); or every one of `count` elements (`None`) if `b` spans too many cells.
    fn query(&self, b: &Aabb, count: u32, f: impl FnMut(u32, Option<I64Vec3>)) {
        self.query_from(0, b, count, f);
    }

    /// As [`Self::query`] for the elements after `e`, whose own box is `b`.
    fn query_after(&self, e: u32, b: &Aabb, count: u32, f: impl FnMut(u32, Option<I64Vec3>)) {
        self.query_from(e + 1, b, count, f);
    }

    /// As [`Self::query`] for the elements from `from` on.
    fn query_from(&self, from: u32, b: &Aabb, count: u32, mut f: impl FnMut(u32, Option<I64Vec3>)) {
        match self.span(b, QUERY_LIMIT) {
            Span::Cells(lo, hi) => {
                // In a single cell every overlapping pair has it as its home.
                let one = lo == hi;
                for c in cells(lo, hi) {
                    let home = (!one).then_some(c);
                    for g in self.bin(c, from) {
                        f(g, home);
                    }
                }
                let start = self.big.partition_point(|&g| g < from);
                for &g in &self.big[start..] {
                    f(g, None);
                }
            }
            Span::Many => (from..count).for_each(|g| f(g, None)),
            Span::None => {}
        }
    }

    /// Whether cell `home` is the one a pair of overlapping boxes `a`, `b` is taken in: the
    /// cell of their overlap's low corner (`None`: the only one the pair is found in).
    #[inline]
    fn is_home(&self, home: Option<I64Vec3>, a: &Aabb, b: &Aabb) -> bool {
        home.is_none_or(|c| (a.0.max(b.0) / self.cell).floor().as_i64vec3() == c)
    }
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
    use super::super::topology::edges_of;
    use super::*;

    /// A pseudo-random number in [0, 1).
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A `n`×`n` grid mesh crumpled into a small box, with paths `prev → x` of random lengths
    /// (a few particles far faster than the rest): many close pairs, within and across rows.
    fn crumpled(n: usize, seed: u64) -> (Elements, Vec<DVec3>, Vec<DVec3>) {
        let mut r = rng(seed);
        let mut x = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (u, v) = (i as f64 * 0.02, j as f64 * 0.02);
                x.push(DVec3::new(u, 0.03 * r() + 0.01 * (u * 40.0).sin(), v));
            }
        }
        let prev: Vec<DVec3> = (x.iter())
            .map(|p| {
                let fast = if r() < 0.05 { 0.05 } else { 0.004 };
                *p + (DVec3::new(r(), r(), r()) - 0.5) * fast
            })
            .collect();
        let id = |i: usize, j: usize| (i * n + j) as u32;
        let mut triangles = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                triangles.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                triangles.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let edges = edges_of(&triangles);
        let el = Elements {
            vertices: (0..(n * n) as u32).collect(),
            triangles,
            edges,
            cloth: vec![0; n * n],
            rest: x.clone(),
        };
        (el, prev, x)
    }

    /// Pairs keep the reach or less, as the distance kept at rest does.
    fn keep(reach: f64) -> impl Fn(Pair) -> f64 + Sync {
        move |p: Pair| match p {
            Pair::VertexFace(v, f) => reach * (0.5 + 0.5 * ((v + f) % 2) as f64),
            Pair::EdgeEdge(e, g) => reach * (0.5 + 0.5 * ((e + g) % 2) as f64),
        }
    }

    /// Builds the list for `prev → x` and checks it against an O(n²) search by the module's
    /// rule (pairs within a hair of the bound aside, for rounding): every pair is listed,
    /// once, and nothing beyond the bound. Returns the list.
    fn build_and_compare(el: &Elements, prev: &[DVec3], x: &[DVec3], tag: &str) -> Candidates {
        let (reach, skin) = (0.012, 0.006);
        let keep = keep(reach);
        let mut list = Candidates::default();
        list.build(el, prev, x, reach, skin, &keep);
        let (a, r): (Vec<DVec3>, Vec<f64>) = (prev.iter().zip(x))
            .map(|(p, q)| ball(*p, *q, skin))
            .unzip();
        let rmax = |ids: &[u32]| ids.iter().map(|&i| r[i as usize]).fold(0.0, f64::max);
        let bx: Vec<Aabb> = (prev.iter().zip(x))
            .map(|(p, q)| path_box(*p, *q, skin))
            .collect();
        let unite = |ids: &[u32]| {
            (ids.iter()).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| {
                (lo.min(bx[i as usize].0), hi.max(bx[i as usize].1))
            })
        };
        // The boxes within the reach on every axis.
        let near = |a: Aabb, b: Aabb| {
            let g = DVec3::splat(reach);
            (a.0 - g).cmple(b.1).all() && (b.0 - g).cmple(a.1).all()
        };
        let q = |i: u32| a[i as usize];
        // (pair, inside the bound by more than rounding, within it up to rounding)
        let mut vf = Vec::new();
        for &v in &el.vertices {
            for (f, t) in (0u32..).zip(&el.triangles) {
                let d = point_triangle_distance(q(v), [q(t[0]), q(t[1]), q(t[2])]);
                let bound = keep(Pair::VertexFace(v, f)) + rmax(&[v]) + rmax(t);
                if !t.contains(&v) && near(unite(&[v]), unite(t)) {
                    vf.push(((v, f), d <= bound * (1.0 - 1e-9), d <= bound * (1.0 + 1e-9)));
                }
            }
        }
        let mut ee = Vec::new();
        for (e, &[a0, a1]) in (0u32..).zip(&el.edges) {
            for (g, &[b0, b1]) in (0u32..).zip(&el.edges).skip(e as usize + 1) {
                let shared = a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1;
                let d = segment_distance(q(a0), q(a1), q(b0), q(b1));
                let bound = keep(Pair::EdgeEdge(e, g)) + rmax(&[a0, a1]) + rmax(&[b0, b1]);
                if !shared && near(unite(&[a0, a1]), unite(&[b0, b1])) {
                    ee.push(((e, g), d <= bound * (1.0 - 1e-9), d <= bound * (1.0 + 1e-9)));
                }
            }
        }
        for (kind, got, want) in [("vf", &list.vf, vf), ("ee", &list.ee, ee)] {
            let mut got: Vec<(u32, u32)> = got.iter().map(|l| (l.a, l.b)).collect();
            got.sort_unstable();
            let n = got.len();
            got.dedup();
            assert_eq!(n, got.len(), "{tag}: a {kind} pair listed twice");
            assert!(
                want.iter().filter(|w| w.1).count() > 20,
                "{tag}: too few {kind}"
            );
            for (pair, inside, near) in want {
                let listed = got.binary_search(&pair).is_ok();
                assert!(listed || !inside, "{tag}: {kind} {pair:?} unlisted");
                assert!(
                    !listed || near,
                    "{tag}: {kind} {pair:?} listed beyond the bound"
                );
            }
        }
        list
    }

    #[test]
    fn cloth_contact_list_holds_every_pair_brute_force_finds() {
        for seed in 1..5 {
            let (el, prev, x) = crumpled(10, seed);
            let mut list = build_and_compare(&el, &prev, &x, &format!("seed {seed}"));
            // Right after the build the list holds, and no longer once a particle leaves its
            // ball.
            assert!(list.holds(&el, &prev, &x));
            let mut far = x.clone();
            let (a, r) = ball(prev[5], x[5], 0.006);
            far[5] = a + DVec3::X * (r * 1.001);
            assert!(!list.holds(&el, &prev, &far));
        }
    }

    #[test]
    fn cloth_contact_list_is_found_through_unbinned_boxes_too() {
        // Particles very far from their starts: their elements span more cells than are
        // binned, and their own queries try every element.
        for seed in 1..3 {
            let (el, mut prev, x) = crumpled(9, seed);
            prev[20] += DVec3::new(3.0, -2.0, 1.0);
            prev[47] += DVec3::new(0.0, 0.3, 0.0);
            prev[60] += DVec3::new(0.1, 0.1, -0.1);
            build_and_compare(&el, &prev, &x, &format!("far, seed {seed}"));
        }
    }
}
