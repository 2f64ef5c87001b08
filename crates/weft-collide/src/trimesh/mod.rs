//! Particle–triangle-mesh contact in closed form and in f64, for still, moving and deforming
//! meshes. This file holds the mesh as contact reads it (`MeshGeometry`: faces, their f32
//! `Planes`, a deforming mesh's frame); its modules hold the rest:
//!
//! - `closest`: the closest point of a triangle to a point (Ericson).
//! - `normals`: the mesh's topology and pseudo-normals that tell inside from outside.
//! - `bvh_node`: a node of the binary bounding-volume hierarchy.
//! - `bvh`: a flat BVH in f64, built once and refitted when the mesh deforms.
//! - `wide_bvh`: the BVH's four-wide f32 copy for nearest-first searches.
//! - `ccd`: continuous collision of a moving point with a still or moving triangle.
//! - `deforming`: what drives a deforming mesh (vertex animations, keyframes).
//! - `face_update`: a moving mesh's face normals every substep and planes every frame.
//! - `frame`: one mesh as every particle sees it in one projection (`MeshFrame`).
//! - `chunk_lists`: what a mesh keeps per particle of a chunk: its candidate list.
//! - `candidates`: per-particle candidate lists kept with a skin, and contacts through them.
//! - `riding`: a list's certificate that rides with a deforming surface.
//! - `contact_grid`: a still mesh's uniform grid of cell lists, sides and clearances.
//! - `face_cert`: what the grid's first test reads of one triangle, and what it decides.
//! - `grid_lanes`: that first test over `L` lanes in explicit vectors.
//! - `grid_run`: a run of particles' first test on a still mesh's grid, a block at a time.
//! - `grid_contacts`: contacts through the grid, and the little each particle keeps.
//! - `open_side_tests` (tests only): an open surface keeps a particle on its side.
//! - `queries_vs_brute_force` (tests only): the BVH queries against brute force.
//! - `vs_parry` (tests only): the mesh queries against brute force and parry.
//! - `test_particles` (tests only): particles about a mesh for the block paths' tests.

pub(crate) mod bvh;
pub(crate) mod bvh_node;
pub(crate) mod candidates;
pub(crate) mod ccd;
pub(crate) mod chunk_lists;
pub(crate) mod closest;
pub(crate) mod contact_grid;
pub(crate) mod deforming;
pub(crate) mod face_cert;
pub(crate) mod face_update;
pub(crate) mod frame;
pub(crate) mod grid_contacts;
pub(crate) mod grid_lanes;
pub(crate) mod grid_run;
pub(crate) mod normals;
#[cfg(test)]
mod open_side_tests;
#[cfg(test)]
mod queries_vs_brute_force;
pub(crate) mod riding;
#[cfg(test)]
pub(crate) mod test_particles;
#[cfg(test)]
mod vs_parry;
pub(crate) mod wide_bvh;

use glam::DVec3;

use bvh::Bvh;
use closest::{Closest, closest_on_triangle};
use normals::{Topology, pseudo_normal};

/// One triangle at the end of the substep: its corners and unit normal (what the contact
/// loops read after a triangle passes its [`Planes`] bound), put together from the vertices
/// and the normals kept per face ([`MeshGeometry::face`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Face {
    /// Corners a, b, c (m, the collider's frame).
    pub corners: [DVec3; 3],
    /// Unit normal (b − a) × (c − a) / |…|, zero if degenerate.
    pub normal: DVec3,
}

/// A triangle's planes in f32, one cache line, for a cheap conservative distance bound: its
/// plane n · x = n · a and its three edge lines' in-plane outward normals e_k · x = e_k · p_k.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(align(64))]
pub(crate) struct Planes(pub(crate) [f32; 16]);

impl Planes {
    /// The planes of the triangle with `corners` and unit `normal`.
    fn new(corners: [DVec3; 3], normal: DVec3) -> Self {
        // Unit in-plane normal of edge k (corners k, k + 1), pointing away from the triangle.
        let edge = |k: usize| {
            (corners[(k + 1) % 3] - corners[k])
                .cross(normal)
                .normalize_or_zero()
        };
        let mut p = [0f32; 16];
        let planes = [
            (normal, corners[0]),
            (edge(0), corners[0]),
            (edge(1), corners[1]),
            (edge(2), corners[2]),
        ];
        for (k, (n, at)) in planes.into_iter().enumerate() {
            p[4 * k..4 * k + 3].copy_from_slice(&n.as_vec3().to_array());
            p[4 * k + 3] = n.dot(at) as f32;
        }
        Self(p)
    }

    /// A lower bound on the squared distance from `x` to the triangle, less `margin` (the
    /// f32 rounding of these terms) on each part: the squared distance to the plane plus the
    /// square of the farthest in-plane distance beyond an edge's line.
    #[inline]
    pub fn distance_squared_bound(&self, x: glam::Vec3, margin: f32) -> f32 {
        let p = &self.0;
        let d = |k: usize| p[k] * x.x + p[k + 1] * x.y + p[k + 2] * x.z - p[k + 3];
        let h = (d(0).abs() - margin).max(0.0);
        let beyond = (d(4).max(d(8)).max(d(12)) - margin).max(0.0);
        h * h + beyond * beyond
    }
}

/// `m` (finite, not negative) as f32, rounded up.
fn widen(m: f64) -> f32 {
    let m32 = m as f32;
    if f64::from(m32) < m {
        f32::from_bits(m32.to_bits() + 1)
    } else {
        m32
    }
}

/// A closest point on the mesh: triangle, point, signed distance (negative inside a closed
/// mesh) and outward unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MeshPoint {
    /// Triangle index (storage order).
    pub triangle: usize,
    /// The closest point on that triangle.
    pub closest: Closest,
    /// Signed distance (m).
    pub distance: f64,
    /// Unit normal pointing from the surface to the particle's side (outward if inside).
    pub normal: DVec3,
}

/// A triangle mesh in the collider's frame, with its vertices at the start and end of the
/// substep (equal unless it deforms), per-triangle faces at the end, topology and BVH.
#[derive(Clone, Debug)]
pub(crate) struct MeshGeometry {
    /// Triangles in BVH storage order.
    triangles: Vec<[u32; 3]>,
    /// Rest vertices (m), as given.
    rest: Vec<DVec3>,
    /// Vertices at the start of the substep.
    start: Vec<DVec3>,
    /// Vertices at the end of the substep: the current surface.
    end: Vec<DVec3>,
    /// The faces' unit normals at the end of the substep, in storage order (their corners
    /// are `end`'s: [`Self::face`]).
    normals: Vec<DVec3>,
    /// Their bounding planes, apart (a scan reads only these for most triangles).
    planes: Vec<Planes>,
    /// The f32 rounding bound of [`Planes::distance_squared_bound`] near the mesh (m).
    margin: f32,
    /// The largest vertex coordinate, in absolute value (m).
    extent: f64,
    /// Adjacency and closedness.
    topology: Topology,
    /// Boxes of the triangles over the substep (start and end).
    bvh: Bvh,
    /// A bound on how far any vertex moved, summed over the substeps so far (m).
    travel: f64,
    /// The bound before the current substep.
    travel_before: f64,
    /// Whether the vertices moved in the current substep.
    moving: bool,
    /// A deforming mesh's frame: its vertices at the frame's start and end, between which
    /// they move linearly over the frame's substeps (empty until the first frame).
    frame: (Vec<DVec3>, Vec<DVec3>),
    /// Per vertex over the current frame: the box of its two ends and its motion (kept
    /// between frames, not to allocate).
    vertex_boxes: Vec<[DVec3; 3]>,
    /// A bound on how far any vertex has still to move before the frame's end (m): the
    /// planes are the frame end's, so every bound on them is this much less.
    slack: f64,
    /// The frame begun last, counted from 1 (0: none yet).
    frame_id: u64,
    /// Where in that frame the current substep starts and ends (fractions, 0 to 1).
    frame_span: (f64, f64),
}

impl MeshGeometry {
    /// The rest vertices (m), as given.
    pub fn rest(&self) -> &[DVec3] {
        &self.rest
    }

    /// The vertices at the end of the substep: the current surface (m).
    pub fn vertices(&self) -> &[DVec3] {
        &self.end
    }

    /// Builds the geometry of `vertices` and `triangles` (already validated).
    pub fn new(vertices: &[DVec3], triangles: &[[u32; 3]]) -> Self {
        let boxes: Vec<(DVec3, DVec3)> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let (bvh, order) = Bvh::build(&boxes);
        let triangles: Vec<[u32; 3]> = order.iter().map(|&i| triangles[i as usize]).collect();
        let topology = Topology::new(vertices.len(), &triangles);
        let extent = vertices
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs().max_element()));
        let mut geometry = Self {
            normals: Vec::new(),
            planes: Vec::new(),
            margin: 0.0,
            extent: 0.0,
            triangles,
            rest: vertices.to_vec(),
            start: vertices.to_vec(),
            end: vertices.to_vec(),
            topology,
            bvh,
            travel: 0.0,
            travel_before: 0.0,
            moving: false,
            frame: (Vec::new(), Vec::new()),
            vertex_boxes: Vec::new(),
            slack: 0.0,
            frame_id: 0,
            frame_span: (0.0, 0.0),
        };
        // The faces' normals and planes as a moving mesh's are worked out (the same bits).
        let n = geometry.triangles.len();
        geometry.normals = vec![DVec3::ZERO; n];
        geometry.planes = vec![Planes::default(); n];
        face_update::update_normals(&mut geometry.normals, &geometry.triangles, &geometry.end);
        face_update::update_planes(&mut geometry.planes, &geometry.triangles, &geometry.end);
        geometry.set_margin(extent);
        geometry
    }

    /// The rounding margin for particles near a mesh within `extent` of the origin: a few
    /// f32 ulps of the largest coordinate (with the lists' reach, 1 m), and the vertices'
    /// travel still to come in the frame.
    fn set_margin(&mut self, extent: f64) {
        self.extent = extent;
        self.margin = widen(1e-6 * (extent + 1.0) + self.slack);
    }

    /// The rounding margin of [`Planes::distance_squared_bound`] for a particle at `x`,
    /// anywhere: as [`Self::margin`] with x's own size added.
    fn margin_at(&self, x: DVec3) -> f32 {
        widen(1e-6 * (self.extent + x.abs().max_element() + 1.0) + self.slack)
    }

    /// Triangle `t`'s corners at the end of the substep.
    #[inline(always)]
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.end[a as usize],
            self.end[b as usize],
            self.end[c as usize],
        ]
    }

    /// Triangle `t`'s face at the end of the substep: its corners and unit normal.
    #[inline(always)]
    pub fn face(&self, t: usize) -> Face {
        Face {
            corners: self.corners(t),
            normal: self.normals[t],
        }
    }

    /// [`Self::face`], or `None` for an index past the last triangle.
    #[inline(always)]
    pub fn face_get(&self, t: usize) -> Option<Face> {
        (t < self.normals.len()).then(|| self.face(t))
    }

    /// How many triangles (faces) the mesh has.
    #[inline]
    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }

    /// Whether the mesh is closed and consistently wound.
    pub fn closed(&self) -> bool {
        self.topology.closed
    }

    /// Starts a frame over which the surface moves linearly from the current vertices to
    /// `to` (same length, finite; checked by the caller): the planes become the frame end's
    /// and the BVH is refitted to the boxes swept over the frame, so that both hold for every
    /// substep of it (the planes' bounds less the travel still to come, [`Self::slack`]).
    pub fn begin_frame(&mut self, to: &[DVec3]) {
        let (from, end) = &mut self.frame;
        from.clone_from(&self.end);
        end.clear();
        end.extend_from_slice(to);
        let (from, end) = (&self.frame.0, &self.frame.1);
        let triangles = &self.triangles;
        // In place: no allocation (nor its page faults) once a frame.
        face_update::update_planes(&mut self.planes, triangles, end);
        // Each vertex's box and motion once (a vertex is a corner of about six triangles),
        // then each triangle's as their bounds (exact: min and max do not round).
        let vertex = &mut self.vertex_boxes;
        vertex.clear();
        vertex.extend((from.iter().zip(end)).map(|(&p, &q)| [p.min(q), p.max(q), q - p]));
        let vertex = &self.vertex_boxes;
        self.bvh.refit_moving(|i| {
            let [a, b, c] = triangles[i].map(|v| vertex[v as usize]);
            [
                (a[0].min(b[0]).min(c[0]), a[1].max(b[1]).max(c[1])),
                (a[2].min(b[2]).min(c[2]), a[2].max(b[2]).max(c[2])),
            ]
        });
        let extent = (from.iter().chain(end)).fold(0.0f64, |m, v| m.max(v.abs().max_element()));
        self.slack = Self::remaining(&self.end, end);
        self.frame_id += 1;
        self.frame_span = (0.0, 0.0);
        self.set_margin(extent);
    }

    /// How far vertex `v` moves over the current frame (zero before the first).
    #[inline]
    pub fn frame_motion(&self, v: u32) -> DVec3 {
        let (from, end) = &self.frame;
        match (from.get(v as usize), end.get(v as usize)) {
            (Some(a), Some(b)) => *b - *a,
            _ => DVec3::ZERO,
        }
    }

    /// How far triangle `t`'s corners' motions over the frame lie from `motion`, at most.
    #[inline]
    pub fn motion_spread(&self, t: usize, motion: DVec3) -> f64 {
        (self.triangles[t].iter())
            .map(|&v| (self.frame_motion(v) - motion).length_squared())
            .fold(0.0, f64::max)
            .sqrt()
    }

    /// How far any of `now` has still to go to `end`, rounded up.
    fn remaining(now: &[DVec3], end: &[DVec3]) -> f64 {
        let d2 = (now.iter().zip(end))
            .map(|(a, b)| (*b - *a).length_squared())
            .fold(0.0, f64::max);
        Self::rounded_up(d2)
    }

    /// The distance whose square is `d2`, rounded up.
    fn rounded_up(d2: f64) -> f64 {
        d2.sqrt() * (1.0 + 1e-12)
    }

    /// Starts a substep that ends at fraction `w` (0 < w ≤ 1) of the frame begun last
    /// ([`Self::begin_frame`]): the vertices there (the frame's end ones, to the bit, at 1),
    /// the faces at them, and the travel bounds.
    pub fn advance_to(&mut self, w: f64) {
        let (from, end) = (&self.frame.0, &self.frame.1);
        std::mem::swap(&mut self.start, &mut self.end);
        // One pass: the vertices, how far they moved, how far they have still to go.
        let (mut moved, mut to_go) = (0.0f64, 0.0f64);
        for (((now, before), a), b) in self.end.iter_mut().zip(&self.start).zip(from).zip(end) {
            *now = if w >= 1.0 { *b } else { *a + (*b - *a) * w };
            moved = moved.max((*now - *before).length_squared());
            to_go = to_go.max((*b - *now).length_squared());
        }
        let moved = moved.sqrt();
        self.frame_span = (self.frame_span.1, w);
        self.moving = moved > 0.0;
        self.travel_before = self.travel;
        self.travel += moved;
        self.slack = Self::rounded_up(to_go);
        self.set_margin(self.extent);
        if !self.moving {
            return;
        }
        face_update::update_normals(&mut self.normals, &self.triangles, &self.end);
    }

    /// Moves the surface to `next` at once (a frame of one substep).
    pub fn advance(&mut self, next: &[DVec3]) {
        self.begin_frame(next);
        self.advance_to(1.0);
    }

    /// Triangle `t`'s corners at the start of the substep.
    pub fn start_corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.start[i as usize])
    }

    /// The (not normalised) pseudo-normal of `feature` of triangle `t` at the end of the
    /// substep.
    pub fn pseudo_normal(&self, t: usize, feature: closest::Feature) -> DVec3 {
        pseudo_normal(
            &self.topology,
            &self.triangles,
            t,
            feature,
            |u| self.normals[u],
            |u, k| self.corners(u)[k],
        )
    }

    /// Signed answer for the closest point `c` of triangle `t` to `x` at distance² `d2`:
    /// for a closed mesh the sign of (x − q) · pseudo-normal (Bærentzen & Aanæs 2005,
    /// Theorem 1), else positive.
    pub fn signed(&self, x: DVec3, t: usize, c: Closest, d2: f64) -> MeshPoint {
        self.signed_with_normal(x, t, c, d2).0
    }

    /// [`Self::signed`], and the pseudo-normal (not normalised) of the closest feature.
    pub fn signed_with_normal(
        &self,
        x: DVec3,
        t: usize,
        c: Closest,
        d2: f64,
    ) -> (MeshPoint, DVec3) {
        let delta = x - c.point;
        let len = d2.sqrt();
        let pn = self.pseudo_normal(t, c.feature);
        let inside = self.closed() && delta.dot(pn) < 0.0;
        let normal = if len > 1e-12 {
            if inside { -delta / len } else { delta / len }
        } else {
            pn.normalize_or(self.normals[t])
        };
        let p = MeshPoint {
            triangle: t,
            closest: c,
            distance: if inside { -len } else { len },
            normal,
        };
        (p, pn)
    }

    /// The closest point of the whole mesh to `x` within `max_dist` (BVH branch and bound).
    pub fn nearest(&self, x: DVec3, max_dist: f64) -> Option<MeshPoint> {
        let (t, d2, c) = self.nearest_unsigned(x, max_dist)?;
        Some(self.signed(x, t, c, d2))
    }

    /// [`Self::nearest`] without its sign: the triangle, the squared distance and the closest
    /// point.
    pub fn nearest_unsigned(&self, x: DVec3, max_dist: f64) -> Option<(usize, f64, Closest)> {
        let limit = if max_dist.is_finite() {
            max_dist * max_dist
        } else {
            f64::INFINITY
        };
        let (x32, margin) = (x.as_vec3(), self.margin_at(x));
        // Each triangle passed over where its planes' bound is no nearer than the best so far.
        self.bvh.nearest(x, limit, |t, bound| {
            self.closest_within(t, x, (x32, margin), bound)
        })
    }

    /// Triangle `t`'s squared distance from `x` and closest point, or `None` where the cheap
    /// bound of its planes (one cache line; `x32` is `x` in f32, `margin` the rounding bound
    /// there) shows it is no nearer than `bound` (squared) before its corners are read.
    // Always inlined: as a call (plain `#[inline]` left it one) the breathing ball's frame
    // measured 10 % slower.
    #[inline(always)]
    pub fn closest_within(
        &self,
        t: usize,
        x: DVec3,
        (x32, margin): (glam::Vec3, f32),
        bound: f64,
    ) -> Option<(f64, Closest)> {
        if f64::from(self.planes[t].distance_squared_bound(x32, margin)) >= bound {
            return None;
        }
        let [a, b, c] = self.corners(t);
        let q = closest_on_triangle(x, a, b, c);
        Some(((x - q.point).length_squared(), q))
    }

    /// Appends to `out` every triangle within `radius` of `x` at the end of the substep, in
    /// a fixed order; returns the nearest of them or, with `beyond` = Some(d), the nearest
    /// triangle of all (found in the same search), known to lie within d of `x` (infinite:
    /// anywhere; a d that rounding left short costs a second search, not the answer).
    pub fn within(
        &self,
        x: DVec3,
        radius: f64,
        beyond: Option<f64>,
        out: &mut Vec<u32>,
    ) -> Option<MeshPoint> {
        let r2 = radius * radius;
        let (x32, margin) = (x.as_vec3(), self.margin_at(x));
        let mut best: Option<(f64, usize, Closest)> = None;
        // What a triangle must be within to matter: r², or the best so far beyond it (at
        // first, what is known of the nearest).
        let mut limit = beyond.map_or(r2, |d| (d * d).max(r2));
        self.bvh.branch_and_bound(x, limit, |t| {
            // Cheap reject on the planes (one cache line) before the corners.
            if f64::from(self.planes[t].distance_squared_bound(x32, margin)) > limit {
                return limit;
            }
            let [a, b, c] = self.corners(t);
            let q = closest_on_triangle(x, a, b, c);
            let d2 = (x - q.point).length_squared();
            if d2 <= r2 {
                out.push(t as u32);
            }
            if d2 <= limit && best.is_none_or(|b| d2 < b.0) {
                best = Some((d2, t, q));
                if beyond.is_some() {
                    limit = d2.max(r2);
                }
            }
            limit
        });
        // Nothing within a finite bound (and so nothing listed, r ≤ the bound): anywhere.
        if best.is_none() && beyond.is_some_and(f64::is_finite) {
            return self.within(x, radius, Some(f64::INFINITY), out);
        }
        best.map(|(d2, t, q)| self.signed(x, t, q, d2))
    }

    /// A riding list's search (`riding`): appends to `out` every triangle within `radius` of
    /// `x` at the end of the substep and to `guard` every other triangle that may come
    /// within `outer` of a point riding from `x` with `motion` before the frame's end (`k`:
    /// the part of the frame left), each in a fixed order; returns the nearest listed
    /// triangle and the guard's spread (how far its corners' motions lie from `motion`, at
    /// most). Every triangle in neither lies farther than `outer` + k |dᵥ − motion| from `x`
    /// now (dᵥ: the frame motion of any of its vertices).
    pub fn within_riding(
        &self,
        x: DVec3,
        (radius, outer): (f64, f64),
        (motion, k): (DVec3, f64),
        out: &mut Vec<u32>,
        guard: &mut Vec<u32>,
    ) -> (Option<MeshPoint>, f64) {
        let r2 = radius * radius;
        let (x32, margin) = (x.as_vec3(), self.margin_at(x));
        let mut best: Option<(f64, usize, Closest)> = None;
        let mut spread = 0.0f64;
        self.bvh.visit_riding(x, outer, (motion, k), |t| {
            // A lower bound on the distance² now (and until the frame's end).
            let lower = f64::from(self.planes[t].distance_squared_bound(x32, margin));
            if lower <= r2 {
                let [a, b, c] = self.corners(t);
                let q = closest_on_triangle(x, a, b, c);
                let d2 = (x - q.point).length_squared();
                if d2 <= r2 {
                    out.push(t as u32);
                    if best.is_none_or(|b| d2 < b.0) {
                        best = Some((d2, t, q));
                    }
                    return;
                }
            }
            let dev = self.motion_spread(t, motion);
            if lower.sqrt() * (1.0 - 1e-12) - k * dev * (1.0 + 1e-12) > outer {
                return;
            }
            guard.push(t as u32);
            spread = spread.max(dev);
        });
        (best.map(|(d2, t, q)| self.signed(x, t, q, d2)), spread)
    }

    /// The mesh's box at the end of the substep (of the swept boxes while it moves).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.bvh.bounds()
    }

    /// The first crossing of the segment `from → to` with the current surface (the entry into
    /// a closed mesh, any crossing of an open one): (fraction, unit normal facing `from`).
    pub fn sweep(&self, from: DVec3, to: DVec3) -> Option<(f64, DVec3)> {
        self.sweep_sided(from, to).map(|(t, n, _)| (t, n))
    }

    /// [`Self::sweep`], and the side `from` lies on: +1 in front of the crossed face's
    /// normal, −1 behind it.
    pub fn sweep_sided(&self, from: DVec3, to: DVec3) -> Option<(f64, DVec3, f64)> {
        let (lo, hi) = (from.min(to), from.max(to));
        let closed = self.closed();
        let mut best: Option<(f64, DVec3, f64)> = None;
        self.bvh.visit(
            |l, h| l.cmple(hi).all() && h.cmpge(lo).all(),
            |t| {
                let f = self.face(t);
                if let Some(c) = ccd::segment_crossing(from, to, f.corners, f.normal, closed)
                    && best.is_none_or(|b| c.t < b.0)
                {
                    best = Some((c.t, f.normal * c.side, c.side));
                }
            },
        );
        best
    }
}
