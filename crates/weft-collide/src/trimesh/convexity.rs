//! Which triangles of a face's one-ring may come in front of the face's plane at some instant
//! of a frame over which the vertices move linearly (few or none on a smooth surface): a
//! particle over the face is then at least its height from every other ring triangle, and
//! only those few need their distances worked out (`certified`).
//!
//! A face F = (a, b, c) with a ring vertex v (a corner of a triangle sharing a corner with F,
//! not itself a corner of F) is tested through G(s) = (E₁ × E₂) · W with E₁ = b − a,
//! E₂ = c − a and W = v − a, each linear in the frame fraction s: v lies behind F's plane
//! where G < 0 (G is |E₁ × E₂| times v's height). G is a cubic in s, and for s in [0, 1]
//!
//! G(s) ≤ (1 − s) G(0) + s G(1) + max |G''| / 8,   G'' = 2 (A′B′C + A′BC′ + AB′C′)
//!
//! with A, B, C = E₁, E₂, W and primes their motions over the frame, so
//! |G''| ≤ 2 (|ΔE₁||ΔE₂| |W|max + |ΔE₁| |E₂|max |ΔW| + |E₁|max |ΔE₂| |ΔW|), each maximum taken at
//! an end of the frame (a norm of a linear function is largest at an end). A ring vertex whose
//! max(G(0), G(1)) plus that bound (and a rounding margin) is below zero stays behind the plane
//! throughout; a ring triangle with no other corner lies behind it (its corners are F's, on
//! the plane, or such vertices), so a point in front of the face at height h is at least h
//! from it, since |x − y| ≥ n · (x − y). The other ring triangles are the face's front list.

use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering::Relaxed;

use glam::DVec3;
use multiversion::multiversion;
use rayon::prelude::*;

use super::normals::Topology;

/// Ring triangles a face may have in front of it and still be settled by [`Fronts`]: the
/// certified test works out a particle's distance to each.
pub(crate) const FRONT: usize = 8;

/// [`Fronts::count`] of a face that settles nothing (degenerate, or more than [`FRONT`] ring
/// triangles in front of it).
pub(crate) const UNUSABLE: u8 = u8::MAX;

/// Per face, its one-ring: the triangles sharing a corner with it and their corners that are
/// not its own.
#[derive(Clone, Debug, Default)]
pub(crate) struct Rings {
    /// Face f's ring vertices: `vertices[vertex_start[f]..vertex_start[f + 1]]`.
    vertex_start: Vec<u32>,
    /// Ring vertices, face by face, each once, in increasing order.
    vertices: Vec<u32>,
    /// Face f's ring triangles (itself excluded): `triangles[triangle_start[f]..][..]`.
    triangle_start: Vec<u32>,
    /// Ring triangles, face by face, each once, in increasing order.
    triangles: Vec<u32>,
    /// Face f's ring triangles sharing neither end of its edge k (those about its third
    /// corner alone): `beyond[beyond_start[3 f + k]..beyond_start[3 f + k + 1]]`.
    beyond_start: Vec<u32>,
    /// Those triangles, face by face and edge by edge, in increasing order.
    beyond: Vec<u32>,
}

impl Rings {
    /// The rings of `triangles` with adjacency `topology`.
    pub fn new(triangles: &[[u32; 3]], topology: &Topology) -> Self {
        let mut rings = Self {
            vertex_start: vec![0],
            triangle_start: vec![0],
            beyond_start: vec![0],
            ..Self::default()
        };
        let (mut verts, mut tris): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
        for (f, tri) in triangles.iter().enumerate() {
            verts.clear();
            tris.clear();
            for &v in tri {
                let (s, e) = (
                    topology.ring_start[v as usize] as usize,
                    topology.ring_start[v as usize + 1] as usize,
                );
                for &u in &topology.ring[s..e] {
                    if u as usize != f {
                        tris.push(u);
                    }
                    verts.extend((triangles[u as usize].iter()).filter(|w| !tri.contains(w)));
                }
            }
            for list in [&mut verts, &mut tris] {
                list.sort_unstable();
                list.dedup();
            }
            rings.vertices.extend_from_slice(&verts);
            rings.vertex_start.push(rings.vertices.len() as u32);
            rings.triangles.extend_from_slice(&tris);
            rings.triangle_start.push(rings.triangles.len() as u32);
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                let off = |&&t: &&u32| !triangles[t as usize].iter().any(|&v| v == p || v == q);
                rings.beyond.extend(tris.iter().filter(off));
                rings.beyond_start.push(rings.beyond.len() as u32);
            }
        }
        rings
    }

    /// Face `f`'s ring triangles that share neither end of its edge `k` (corners k, k + 1).
    #[inline]
    pub fn beyond_edge(&self, f: usize, k: usize) -> &[u32] {
        let i = 3 * f + k;
        &self.beyond[self.beyond_start[i] as usize..self.beyond_start[i + 1] as usize]
    }

    /// Face `f`'s ring vertices.
    #[inline]
    pub fn of(&self, f: usize) -> &[u32] {
        &self.vertices[self.vertex_start[f] as usize..self.vertex_start[f + 1] as usize]
    }

    /// Face `f`'s ring triangles (not itself).
    #[inline]
    pub fn triangles_of(&self, f: usize) -> &[u32] {
        &self.triangles[self.triangle_start[f] as usize..self.triangle_start[f + 1] as usize]
    }
}

/// Whether triangles `a` and `b` share a corner (b is in a's one-ring, or is a).
#[inline]
pub(crate) fn share_a_corner(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().any(|v| b.contains(v))
}

/// Per face, over a frame: how many of its ring triangles may come in front of its plane
/// (0: the whole ring stays behind it; [`UNUSABLE`]: more than [`FRONT`], a degenerate face,
/// or a face neither named by a particle's certificate in the frame before nor in the ring of
/// one that was), and which.
#[derive(Debug, Default)]
pub(crate) struct Fronts {
    /// Per face, how many ring triangles may be in front, or [`UNUSABLE`].
    pub count: Vec<u8>,
    /// Per face, those triangles (the first `count`).
    pub front: Vec<[u32; FRONT]>,
    /// Per face, the last frame in which a certified test read it (`certified`): only those
    /// read in the frame before, and their rings, are worked out for a frame.
    used: Vec<AtomicU64>,
}

impl Clone for Fronts {
    fn clone(&self) -> Self {
        Self {
            count: self.count.clone(),
            front: self.front.clone(),
            used: (self.used.iter())
                .map(|u| AtomicU64::new(u.load(Relaxed)))
                .collect(),
        }
    }
}

impl Fronts {
    /// The ring triangles of the faces of `triangles` (`rings`) that may lie in front of
    /// their plane at some instant of a frame over which each vertex moves linearly from
    /// `from` to `to` (see the module's notes): every other one lies strictly behind it
    /// throughout. `extent` bounds the vertices' coordinates (for the rounding margin). Every
    /// face for `frame` 0 (a still mesh, passing the same vertices twice), else those read in
    /// the frame before `frame` and the faces of their rings (the others are left
    /// [`UNUSABLE`] for this one).
    pub fn update(
        &mut self,
        triangles: &[[u32; 3]],
        rings: &Rings,
        (from, to): (&[DVec3], &[DVec3]),
        (extent, frame): (f64, u64),
    ) {
        let n = triangles.len();
        self.count.resize(n, 0);
        self.front.resize(n, [0; FRONT]);
        self.used.resize_with(n, || AtomicU64::new(0));
        let used = &self.used;
        (self
            .count
            .par_chunks_mut(PART)
            .zip(self.front.par_chunks_mut(PART)))
        .enumerate()
        .for_each(|(k, (count, front))| {
            let faces = (k * PART, triangles, rings);
            update_part(faces, (from, to), (extent, frame), used, (count, front));
        });
    }

    /// Records that a certified test read face `f` in `frame`.
    #[inline]
    pub fn mark(&self, f: usize, frame: u64) {
        if let Some(u) = self.used.get(f)
            && u.load(Relaxed) != frame
        {
            u.store(frame, Relaxed);
        }
    }
}

/// Faces a parallel task updates.
const PART: usize = 256;

/// [`Fronts::update`] for the faces from `first` on (as many as `count` holds), compiled for
/// the widest vector unit the CPU has (the same operations, so the same bits, on every one).
#[multiversion(targets("x86_64+avx2+fma", "aarch64+neon"))]
fn update_part(
    (first, triangles, rings): (usize, &[[u32; 3]], &Rings),
    ends: (&[DVec3], &[DVec3]),
    (extent, frame): (f64, u64),
    used: &[AtomicU64],
    (count, front): (&mut [u8], &mut [[u32; FRONT]]),
) {
    let mut ahead = [0u32; AHEAD];
    let read = |t: u32| {
        used.get(t as usize)
            .is_some_and(|u| u.load(Relaxed) + 1 >= frame)
    };
    for (k, (count, front)) in count.iter_mut().zip(front.iter_mut()).enumerate() {
        let f = first + k;
        // Read in the frame before, or beside a face that was (where particles go next).
        let wanted = read(f as u32) || rings.triangles_of(f).iter().any(|&t| read(t));
        *count = if frame == 0 || wanted {
            fronts_of(f, triangles, rings, ends, extent, &mut ahead, front)
        } else {
            UNUSABLE
        };
    }
}

/// Ring vertices that may be in front of a face, at most, before it is unusable.
const AHEAD: usize = 16;

/// [`Fronts::update`] for face `f`: writes its front triangles into `front`, returns their
/// count. `ahead` is scratch.
#[inline(always)]
fn fronts_of(
    f: usize,
    triangles: &[[u32; 3]],
    rings: &Rings,
    (from, to): (&[DVec3], &[DVec3]),
    extent: f64,
    ahead: &mut [u32; AHEAD],
    front: &mut [u32; FRONT],
) -> u8 {
    let tri = triangles[f];
    let [a0, b0, c0] = tri.map(|i| from[i as usize]);
    let [a1, b1, c1] = tri.map(|i| to[i as usize]);
    let (e1_0, e2_0) = (b0 - a0, c0 - a0);
    let (e1_1, e2_1) = (b1 - a1, c1 - a1);
    let (n0, n1) = (e1_0.cross(e2_0), e1_1.cross(e2_1));
    if n0 == DVec3::ZERO || n1 == DVec3::ZERO {
        return UNUSABLE;
    }
    let ring = rings.of(f);
    // The largest end value of G over the ring, and the largest |W| and |ΔW|, squared
    // (plain comparisons: a NaN leaves the face unusable below).
    let (mut worst, mut w2, mut dw2) = (f64::NEG_INFINITY, 0.0f64, 0.0f64);
    let larger = |a: f64, b: f64| if a > b { a } else { b };
    for &v in ring {
        let (w0, w1) = (from[v as usize] - a0, to[v as usize] - a1);
        worst = larger(worst, larger(n0.dot(w0), n1.dot(w1)));
        w2 = larger(w2, larger(w0.length_squared(), w1.length_squared()));
        dw2 = larger(dw2, (w1 - w0).length_squared());
    }
    let e1 = e1_0.length_squared().max(e1_1.length_squared()).sqrt();
    let e2 = e2_0.length_squared().max(e2_1.length_squared()).sqrt();
    let (de1, de2) = ((e1_1 - e1_0).length(), (e2_1 - e2_0).length());
    let (w, dw) = (w2.sqrt(), dw2.sqrt());
    // max |G''| / 8, and G's rounding (a few ulps of its terms and of the interpolated
    // vertices' coordinates).
    let bend = 0.25 * (de1 * de2 * w + (de1 * e2 + e1 * de2) * dw);
    let slack = bend + 1e-12 * e1 * e2 * (w + extent);
    if worst + slack < 0.0 {
        return 0;
    }
    if !(slack.is_finite() && worst.is_finite()) {
        return UNUSABLE;
    }
    // The ring vertices that may come in front, then the ring triangles holding one.
    let mut n_ahead = 0;
    for &v in ring {
        let (w0, w1) = (from[v as usize] - a0, to[v as usize] - a1);
        // Not certainly behind (a NaN counts as in front).
        let behind = larger(n0.dot(w0), n1.dot(w1)) + slack < 0.0;
        if !behind {
            if n_ahead == AHEAD {
                return UNUSABLE;
            }
            ahead[n_ahead] = v;
            n_ahead += 1;
        }
    }
    let ahead = &ahead[..n_ahead];
    let mut count = 0;
    for &t in rings.triangles_of(f) {
        if !triangles[t as usize].iter().any(|v| ahead.contains(v)) {
            continue;
        }
        if count == FRONT {
            return UNUSABLE;
        }
        front[count] = t;
        count += 1;
    }
    count as u8
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::{FRONT, Fronts, Rings, UNUSABLE, share_a_corner};
    use crate::analytic_vs_parry::Rng;
    use crate::mesh::TriangleMesh;
    use crate::trimesh::normals::Topology;

    /// The breathing and rippling of `v` at time `t` (as the benches' ball, stronger).
    fn ripple(v: DVec3, t: f64, amplitude: f64) -> DVec3 {
        v * (1.0 + amplitude * (std::f64::consts::TAU * (t + 2.0 * v.y)).sin())
    }

    /// A ring is every triangle sharing a corner with the face (less the face) and their
    /// corners (less its own), each once.
    #[test]
    fn rings_hold_the_triangles_around_a_face_and_their_corners() {
        let m = TriangleMesh::icosphere(0.5, 2);
        let topology = Topology::new(m.vertices.len(), &m.triangles);
        let rings = Rings::new(&m.triangles, &topology);
        for (f, tri) in m.triangles.iter().enumerate() {
            let around: Vec<u32> = (0..m.triangles.len() as u32)
                .filter(|&t| t as usize != f && share_a_corner(m.triangles[t as usize], *tri))
                .collect();
            assert_eq!(rings.triangles_of(f), &around[..], "face {f}");
            let mut want: Vec<u32> = (around.iter())
                .flat_map(|&t| m.triangles[t as usize])
                .filter(|v| !tri.contains(v))
                .collect();
            want.sort_unstable();
            want.dedup();
            assert_eq!(rings.of(f), &want[..], "face {f}");
        }
    }

    /// On a rippling sphere, every ring triangle a face does not list as in front has its
    /// corners behind the face's plane at many instants of the frame (checked directly, with
    /// the vertices where the interpolation puts them). The lists are not vacuous: most faces
    /// list none, and the ripple's concave parts list some. Without the curvature bound
    /// (`slack` less `bend`) the test fails: a vertex behind at both ends of a frame comes in
    /// front between them.
    #[test]
    fn a_ring_triangle_not_listed_in_front_stays_behind_the_face_throughout_the_frame() {
        let m = TriangleMesh::icosphere(0.5, 3);
        let topology = Topology::new(m.vertices.len(), &m.triangles);
        let rings = Rings::new(&m.triangles, &topology);
        let mut rng = Rng(11);
        let (mut clear, mut listing, mut unusable, mut checked) = (0, 0, 0, 0);
        let mut fronts = Fronts::default();
        for frame in 0..40 {
            // Frames of varying length: short ones and long, jerky ones.
            let t0 = frame as f64 * 0.05;
            let t1 = t0 + 0.01 + 0.1 * rng.next();
            let amplitude = 0.02 + 0.06 * rng.next();
            let from: Vec<DVec3> = m
                .vertices
                .iter()
                .map(|v| ripple(*v, t0, amplitude))
                .collect();
            let to: Vec<DVec3> = m
                .vertices
                .iter()
                .map(|v| ripple(*v, t1, amplitude))
                .collect();
            fronts.update(&m.triangles, &rings, (&from, &to), (0.6, 0));
            for (f, tri) in m.triangles.iter().enumerate() {
                let count = fronts.count[f];
                match count {
                    0 => clear += 1,
                    UNUSABLE => {
                        unusable += 1;
                        continue;
                    }
                    _ => listing += 1,
                }
                let listed = &fronts.front[f][..usize::from(count)];
                for k in 0..=16 {
                    let s = k as f64 / 16.0;
                    let at = |i: u32| from[i as usize] + (to[i as usize] - from[i as usize]) * s;
                    let [a, b, c] = tri.map(at);
                    let n = (b - a).cross(c - a);
                    for &t in rings.triangles_of(f).iter().filter(|t| !listed.contains(t)) {
                        for v in m.triangles[t as usize]
                            .into_iter()
                            .filter(|v| !tri.contains(v))
                        {
                            checked += 1;
                            assert!(n.dot(at(v) - a) < 0.0, "face {f}, triangle {t} at {s}");
                        }
                    }
                }
            }
        }
        assert!(
            checked > 0 && clear > listing + unusable,
            "{clear} {listing} {unusable}"
        );
        assert!(listing > 100, "{listing} faces list a triangle in front");
    }

    /// A flat fan of four triangles about the origin in the plane z = 0 (normals +z), with
    /// corners 3 and 4 lowered by `lift`.
    fn fan(lift: f64) -> Vec<DVec3> {
        vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, -lift),
            DVec3::new(0.0, -1.0, -lift),
        ]
    }

    /// A ring vertex that crosses a face's plane and comes back within one frame puts its
    /// triangles in the face's front list, though it is behind the plane at both ends.
    #[test]
    fn a_vertex_crossing_the_plane_between_the_frame_ends_is_in_front() {
        let triangles = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
        let topology = Topology::new(5, &triangles);
        let rings = Rings::new(&triangles, &topology);
        let mut fronts = Fronts::default();
        // Still, corners 3 and 4 below the plane of face 0: nothing in front.
        let below = fan(0.1);
        fronts.update(&triangles, &rings, (&below, &below), (1.0, 0));
        assert_eq!(fronts.count[0], 0);
        // Lifted above it: the three triangles holding them.
        let above = fan(-0.1);
        fronts.update(&triangles, &rings, (&above, &above), (1.0, 0));
        assert_eq!(&fronts.front[0][..usize::from(fronts.count[0])], &[1, 2, 3]);
        // Corner 3 sweeping through the plane of face 0 while face 0 tilts about the x axis
        // and back: behind at both ends, so only the curvature term can list it.
        let (mut a, mut b) = (fan(0.1), fan(0.1));
        a[2] = DVec3::new(0.0, 1.0, 2.0);
        b[2] = DVec3::new(0.0, 1.0, -2.0);
        a[3] = DVec3::new(-1.0, 2.0, 0.3);
        b[3] = DVec3::new(-1.0, -2.0, 0.3);
        fronts.update(&triangles, &rings, (&a, &b), (3.0, 0));
        let g = |s: f64| {
            let at = |i: usize| a[i] + (b[i] - a[i]) * s;
            (at(1) - at(0)).cross(at(2) - at(0)).dot(at(3) - at(0))
        };
        assert!(g(0.0) < 0.0 && g(1.0) < 0.0 && g(0.5) > 0.0);
        let listed = &fronts.front[0][..usize::from(fronts.count[0])];
        assert!(listed.contains(&1) && listed.contains(&2), "{listed:?}");
    }

    /// A face with more ring triangles in front than a list holds settles nothing, nor does
    /// a degenerate one.
    #[test]
    fn too_many_in_front_or_degenerate_is_unusable() {
        // A fan of FRONT + 2 triangles about the origin, all but the first lifted.
        let n = FRONT + 2;
        let mut v = vec![DVec3::ZERO];
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            let lift = if k < 2 { 0.0 } else { 0.2 };
            v.push(DVec3::new(a.cos(), a.sin(), lift));
        }
        let triangles: Vec<[u32; 3]> = (0..n as u32)
            .map(|k| [0, k + 1, (k + 1) % n as u32 + 1])
            .collect();
        let topology = Topology::new(v.len(), &triangles);
        let rings = Rings::new(&triangles, &topology);
        let mut fronts = Fronts::default();
        fronts.update(&triangles, &rings, (&v, &v), (1.0, 0));
        assert_eq!(fronts.count[0], UNUSABLE);
        let mut flat = v.clone();
        flat[2] = flat[1] * 2.0;
        fronts.update(&triangles, &rings, (&flat, &flat), (1.0, 0));
        assert_eq!(fronts.count[0], UNUSABLE, "degenerate face 0");
    }

    /// Past the first frame, a face's list is worked out where a certified test read it in
    /// the frame before or read a face of its ring (where particles go next), and no other.
    #[test]
    fn the_faces_read_and_their_rings_are_worked_out() {
        let m = TriangleMesh::icosphere(0.5, 2);
        let topology = Topology::new(m.vertices.len(), &m.triangles);
        let rings = Rings::new(&m.triangles, &topology);
        let still = (&m.vertices[..], &m.vertices[..]);
        let mut fronts = Fronts::default();
        fronts.update(&m.triangles, &rings, still, (0.6, 1));
        let read = [3, 17];
        for f in read {
            fronts.mark(f, 1);
        }
        fronts.update(&m.triangles, &rings, still, (0.6, 2));
        let mut worked = 0;
        for f in 0..m.triangles.len() {
            let near = read
                .iter()
                .any(|&t| share_a_corner(m.triangles[t], m.triangles[f]));
            // The convex sphere: a face worked out lists nothing in front.
            assert_eq!(fronts.count[f] == 0, near, "face {f}");
            worked += usize::from(near);
        }
        assert!(worked > 12 && worked < m.triangles.len() / 4, "{worked}");
        // Read in neither frame 1 nor 2: none for frame 3.
        fronts.update(&m.triangles, &rings, still, (0.6, 3));
        assert!(fronts.count.iter().all(|&c| c == UNUSABLE));
    }
}
