//! The certified test of a mesh that keeps candidate lists: a block of particles at a time in
//! explicit vectors (eight lanes on the AVX-512 path, four on AVX2, one for a particle
//! alone), each particle against the face its certificate names (`certificate`), with no list.
//!
//! A lane whose certificate does not hold has it made again first. A lane whose certificate
//! is clear (no triangle within ψ), or whose path lies in its hover ball, is clear: nothing is
//! within r of it. Otherwise, with F the certificate's face, every triangle off F's ring is at
//! least r away, and every triangle of the ring lies behind F's plane throughout the frame but
//! for a few per face (F's front list, `convexity`), so where the particle's path is short (no
//! sweep is due) and it is at height h > 0 in front of F's plane:
//!
//! - at h ≥ r it is clear wherever it projects (|x − y| ≥ n · (x − y) ≥ h for every y behind
//!   the plane), if each front triangle is at least r away;
//! - nearer, with its projection inside F, F is the nearest triangle of all if each front
//!   triangle is at least h away: the particle is pushed along F's normal to r and slid back
//!   by Coulomb friction against the surface's displacement at the touched point over the
//!   substep (Macklin et al. 2014, eq. 24), as `MeshFrame::resolve` would, and is done if it
//!   ends within its certificate's reach and each front triangle is then at least r away
//!   (every other ring triangle is: the slip is tangential, so the particle stays r in front
//!   of the plane).
//!
//! A front triangle is at least d away where the particle is d in front of its plane, else by
//! its distance, worked out a block of lanes at a time. A clear lane keeps a hover ball about
//! where it stands: every triangle is at least min(h, the front triangles' bounds, what its
//! certificate leaves) away, so no triangle is within r of a point of the ball shrunk by that
//! excess, less the surface's travel since.
//!
//! What a lane does depends on that particle alone and every lane runs the same IEEE
//! operations in the same order (no fused multiply-adds, every branch a select), so the bits
//! do not depend on the kernel path, on where a particle falls in a run, or on which lanes
//! share its block: a run screens its particles a block at a time ([`screen`]: certificates,
//! clear lanes, hover balls) and packs those sent on to the face test ([`face_test`]) into
//! full blocks.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::Simd;
use weft_simd::{Ops, V3, load, load_at, load3, store};
use weft_solver::Contacts;

use super::MeshGeometry;
use super::chunk_lists::ChunkLists;
use super::chunk_lists::{CLEAR, Certificates, NO_FACE};
use super::convexity::UNUSABLE;
use super::frame::MeshFrame;
use super::grid_lanes::push_vectors;

/// Projections nearer than this (barycentric) to an edge of the face are left to the ring.
const INSIDE: f64 = 1e-9;

/// What the certified test did with a block's lanes.
pub(crate) struct Certified<const L: usize> {
    /// Lanes settled (clear, or pushed out of their face): nothing more to do.
    pub settled: [bool; L],
    /// Lanes not settled whose certificate holds, with a face, on a short path: their
    /// contacts are among the face's ring (`MeshFrame::resolve_ring`).
    pub ring: [bool; L],
    /// The contacts made.
    pub contacts: Contacts,
}

#[cfg(test)]
thread_local! {
    /// Lanes the certified test settled on this thread: clear, pushed, in a hover ball.
    pub(crate) static SETTLED: std::cell::Cell<[usize; 3]> = const { std::cell::Cell::new([0; 3]) };
    /// (lane, front triangle) pairs whose distance the test worked out on this thread.
    pub(crate) static FRONT_DISTANCES: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Adds `n` to counter `k` of [`SETTLED`] (tests only).
#[inline(always)]
fn tally(_k: usize, _n: usize) {
    #[cfg(test)]
    SETTLED.with(|c| {
        let mut v = c.get();
        v[_k] += _n;
        c.set(v);
    });
}

/// The certified test (see the module's notes) of particle `j` of `lists` at `x` (the mesh's
/// frame, moved in place where settled), `prev` at the substep's start, thickness `r`, taking
/// part where `live` and certified (`MeshFrame::certifies`), against the mesh of `frame` (for
/// which `MeshFrame::lists_settle` holds): [`screen`], then [`face_test`], as a block's
/// particles take them.
#[inline(always)]
pub(crate) fn certified<S: Simd>(
    o: Ops<S>,
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    j: usize,
    (x, prev): (&mut [[f64; 1]; 3], &[[f64; 1]; 3]),
    (r, live): (&[f64; 1], [bool; 1]),
) -> Certified<1> {
    let screened = screen::<S, 1>(o, frame, lists, j, (x, prev), (r, live));
    if !screened.near[0] {
        return Certified {
            settled: screened.settled,
            ring: [false],
            contacts: Contacts::default(),
        };
    }
    face_test::<S, 1>(o, frame, lists, &[j], (x, prev), (r, screened.near))
}

/// What [`screen`] found of a block's lanes.
pub(crate) struct Screened<const L: usize> {
    /// Lanes settled by a clear certificate or by their hover ball: nothing more to do.
    pub settled: [bool; L],
    /// Lanes whose certificate holds and names a face, not in their hover ball: for
    /// [`face_test`].
    pub near: [bool; L],
}

/// The first part of the certified test of particles `s .. s + L` of `lists` at positions `x`
/// (the mesh's frame), `prev` at the substep's start, thicknesses `r`, taking part where
/// `live` and certified (`MeshFrame::certifies`): certificates that do not hold made again,
/// then each lane settled where its certificate is clear or its path lies in its hover ball,
/// or marked for the face test where its certificate names a face. A lane neither settled
/// nor near is left open.
#[inline(always)]
pub(crate) fn screen<S: Simd, const L: usize>(
    o: Ops<S>,
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    s: usize,
    (x, prev): (&[[f64; L]; 3], &[[f64; L]; 3]),
    (r, mut live): (&[f64; L], [bool; L]),
) -> Screened<L> {
    debug_assert_eq!(L, S::F64_LANES);
    let g = frame.geometry;
    for l in 0..L {
        live[l] &= frame.certifies(r[l]);
    }
    let mut out = Screened {
        settled: [false; L],
        near: [false; L],
    };
    if !live.contains(&true) {
        return out;
    }
    let from = path_starts::<L>(frame, lists, &std::array::from_fn(|l| s + l), prev);
    let path = (&load3::<S, L>(x), &load3::<S, L>(&from));
    let rv = load::<S, L>(*r);
    // Certificates that do not hold are made again, then read anew.
    let mut valid = holds::<S, L>(o, &lists.certs, s, path, (rv, g.travel));
    let stale: [bool; L] = std::array::from_fn(|l| live[l] & !valid[l]);
    if stale.contains(&true) {
        for l in (0..L).filter(|&l| stale[l]) {
            let at = |v: &[[f64; L]; 3]| DVec3::new(v[0][l], v[1][l], v[2][l]);
            frame.certify(lists, s + l, at(x), at(&from), r[l]);
        }
        valid = holds::<S, L>(o, &lists.certs, s, path, (rv, g.travel));
    }
    let certs = &lists.certs;
    let hover_slack = o.sub(load_at::<S, L>(&certs.hover[3], s), o.c(g.travel));
    let hovers = in_ball::<S, L>(o, anchors::<S, L>(&certs.hover, s), hover_slack, path);
    for l in 0..L {
        let ok = live[l] & valid[l];
        let face = certs.face[s + l];
        out.settled[l] = ok & ((face == CLEAR) | hovers[l]);
        out.near[l] = ok & (face < NO_FACE) & !hovers[l];
    }
    tally(
        0,
        (0..L)
            .filter(|&l| out.settled[l] & (certs.face[s + l] == CLEAR))
            .count(),
    );
    tally(
        2,
        (0..L)
            .filter(|&l| out.settled[l] & (certs.face[s + l] != CLEAR))
            .count(),
    );
    for l in (0..L).filter(|&l| out.settled[l]) {
        lists.last[s + l] = DVec3::new(x[0][l], x[1][l], x[2][l]);
    }
    out
}

/// Where each lane's path starts: the substep's start `prev` on its first projection, else
/// where the last left particle `j[l]`.
#[inline(always)]
pub(crate) fn path_starts<const L: usize>(
    frame: &MeshFrame<'_>,
    lists: &ChunkLists,
    j: &[usize; L],
    prev: &[[f64; L]; 3],
) -> [[f64; L]; 3] {
    let mut from = *prev;
    if !frame.fresh {
        for l in 0..L {
            let f = lists.last[j[l]];
            for k in 0..3 {
                from[k][l] = f[k];
            }
        }
    }
    from
}

/// The second part of the certified test: the face test (see the module's notes) of the
/// `near` lanes ([`screen`]'s), particles `j[l]` of `lists` at `x` (moved in place where
/// settled), `prev` at the substep's start, thicknesses `r`. A block's lanes may be any
/// particles of the run (a lane not near takes no part and is left as it is).
#[inline(always)]
pub(crate) fn face_test<S: Simd, const L: usize>(
    o: Ops<S>,
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    j: &[usize; L],
    (x, prev): (&mut [[f64; L]; 3], &[[f64; L]; 3]),
    (r, near): (&[f64; L], [bool; L]),
) -> Certified<L> {
    debug_assert_eq!(L, S::F64_LANES);
    let mut out = Certified {
        settled: [false; L],
        ring: [false; L],
        contacts: Contacts::default(),
    };
    let from = path_starts::<L>(frame, lists, j, prev);
    let face: [u32; L] = std::array::from_fn(|l| if near[l] { lists.certs.face[j[l]] } else { 0 });
    let lanes = Lanes {
        j,
        x,
        from: &from,
        prev,
        r,
        face: &face,
        near,
    };
    out.contacts = settle::<S, L>(o, frame, lists, lanes, &mut out.settled);
    let surface = frame.surface_travel();
    for l in 0..L {
        let p = DVec3::new(
            x[0][l] - from[0][l],
            x[1][l] - from[1][l],
            x[2][l] - from[2][l],
        );
        let half = 0.5 * r[l] - surface;
        let short = half >= 0.0 && p.length_squared() <= half * half;
        out.ring[l] = near[l] & !out.settled[l] & short;
    }
    for l in (0..L).filter(|&l| out.settled[l]) {
        lists.last[j[l]] = DVec3::new(x[0][l], x[1][l], x[2][l]);
    }
    out
}

/// Whether the certificates of lanes `s .. s + L` hold for their paths (thickness `r`, the
/// surface's travel bound now `travel`).
#[inline(always)]
fn holds<S: Simd, const L: usize>(
    o: Ops<S>,
    certs: &Certificates,
    s: usize,
    path: (&V3<S>, &V3<S>),
    (r, travel): (S::f64s, f64),
) -> [bool; L] {
    let slack = o.sub(o.sub(load_at::<S, L>(&certs.reach, s), o.c(travel)), r);
    in_ball::<S, L>(o, anchors::<S, L>(&certs.anchor, s), slack, path)
}

/// Whether each lane's path (`x`, `from`) lies in its ball: centre `centre`, radius `slack`
/// (none where negative or NaN).
#[inline(always)]
fn in_ball<S: Simd, const L: usize>(
    o: Ops<S>,
    centre: V3<S>,
    slack: S::f64s,
    (x, from): (&V3<S>, &V3<S>),
) -> [bool; L] {
    let (dx, df) = (o.dif(x, &centre), o.dif(from, &centre));
    let s2 = o.mul(slack, slack);
    let ok = o.and(
        o.ge(slack, o.c(0.0)),
        o.and(o.le(o.dot(&dx, &dx), s2), o.le(o.dot(&df, &df), s2)),
    );
    o.bits::<L>(ok)
}

/// The lanes of a block that [`settle`] tests: their particles `j` in the lists, positions
/// `x` (moved in place), path starts `from`, substep starts `prev`, thicknesses `r`, and the
/// faces of the `near` lanes (whose certificates hold and name a face).
struct Lanes<'b, const L: usize> {
    j: &'b [usize; L],
    x: &'b mut [[f64; L]; 3],
    from: &'b [[f64; L]; 3],
    prev: &'b [[f64; L]; 3],
    r: &'b [f64; L],
    face: &'b [u32; L],
    near: [bool; L],
}

/// The face test of the `near` lanes (see the module's notes): settles (marks in `settled`,
/// moves in `x`) every lane it can; returns the contacts made.
#[inline(always)]
fn settle<S: Simd, const L: usize>(
    o: Ops<S>,
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    b: Lanes<'_, L>,
    settled: &mut [bool; L],
) -> Contacts {
    let g = frame.geometry;
    let near = b.near;
    // Each near lane's face (a lane that is not near reads face 0, and is masked out).
    let t: [usize; L] = std::array::from_fn(|l| if near[l] { b.face[l] as usize } else { 0 });
    let [a, bb, c] = corners::<S, L, 3>(&g.triangles, &g.end, &t, [0, 1, 2]);
    let n = normals::<S, L>(&g.normals, &t);
    let count: [u8; L] = std::array::from_fn(|l| if near[l] { g.fronts.count[t[l]] } else { 0 });
    for l in (0..L).filter(|&l| near[l]) {
        g.fronts.mark(t[l], g.frame_id);
    }
    let xv = load3::<S, L>(b.x);
    let rv = load::<S, L>(*b.r);
    // A short path (no sweep due), relative to the surface on the substep's first projection.
    let half = o.sub(o.mul(o.c(0.5), rv), o.c(frame.surface_travel()));
    let p = o.dif(&xv, &load3::<S, L>(b.from));
    let short = o.and(o.ge(half, o.c(0.0)), o.le(o.dot(&p, &p), o.mul(half, half)));
    // With e₁ = b − a, e₂ = c − a, m = e₁ × e₂ and d = x − a, the projection of x is
    // a + β e₁ + γ e₂ with β |m|² = (d × e₂) · m and γ |m|² = (e₁ × d) · m.
    let (e1, e2) = (o.dif(&bb, &a), o.dif(&c, &a));
    let m = o.cross(&e1, &e2);
    let m2 = o.dot(&m, &m);
    let d = o.dif(&xv, &a);
    let h = o.dot(&n, &d);
    let bm = o.dot(&o.cross(&d, &e2), &m);
    let gm = o.dot(&o.cross(&e1, &d), &m);
    let edge = o.mul(o.c(INSIDE), m2);
    let inside = o.and(
        o.and(o.gt(bm, edge), o.gt(gm, edge)),
        o.lt(o.add(bm, gm), o.mul(o.c(1.0 - INSIDE), m2)),
    );
    let usable: [bool; L] = std::array::from_fn(|l| near[l] & (count[l] != UNUSABLE));
    let ok = o.and(
        o.and(mask::<S, L>(o, usable), short),
        o.and(o.or(inside, o.ge(h, rv)), o.gt(h, o.c(1e-12))),
    );
    if !o.any(ok) {
        return Contacts::default();
    }
    let depth = o.sub(rv, h);
    let tiny = o.le(depth, o.mul(o.c(1e-6), o.max(rv, o.c(1e-3))));
    let push = o.and(o.and(ok, inside), o.not(tiny));
    let (mut moved, mut slip2, mut lifted) = (xv, o.c(0.0), xv);
    let mut within = o.c(1.0);
    if o.any(push) {
        // Pushed to r along the normal, then friction against the surface's displacement at
        // the touched point over the substep (none where it is still).
        let bary = {
            let (beta, gamma) = (o.div(bm, m2), o.div(gm, m2));
            [o.sub(o.sub(o.c(1.0), beta), gamma), beta, gamma]
        };
        let mut carried = load3::<S, L>(b.prev);
        if g.moving {
            let start = corners::<S, L, 3>(&g.triangles, &g.start, &t, [0, 1, 2]);
            let end = [a, bb, c];
            // As `MeshFrame::surface_displacement`: Σ wₖ endₖ − Σ wₖ startₖ.
            for i in 0..3 {
                let (mut e, mut st) = (o.c(0.0), o.c(0.0));
                for k in 0..3 {
                    e = o.add(e, o.mul(end[k][i], bary[k]));
                    st = o.add(st, o.mul(start[k][i], bary[k]));
                }
                carried[i] = o.add(carried[i], o.sub(e, st));
            }
        }
        (moved, slip2) = push_vectors(o, frame.friction, &xv, &carried, &n, depth, push);
        for k in 0..3 {
            lifted[k] = o.sel(push, o.add(xv[k], o.mul(n[k], depth)), xv[k]);
        }
        // Where it ends is still within the certificate's reach (a lane not pushed: 1).
        let certs = &lists.certs;
        let anchor = gather3::<S, L>(&certs.anchor, b.j);
        let reach = gather::<S, L>(&certs.reach, b.j);
        let slack = o.sub(o.sub(reach, o.c(g.travel)), rv);
        let e = o.dif(&moved, &anchor);
        within = o.sel(push, o.sub(o.mul(slack, slack), o.dot(&e, &e)), within);
    }
    // Each front triangle at least min(h, r) from the lane, or, pushed, at least r plus the
    // slip from where the push left it (then at least h before it, and r after the slip).
    let fronts = Fronts {
        t: &t,
        count: &count,
        usable: &usable,
    };
    let need = o.sel(push, o.add(rv, o.sqrt(slip2)), o.min(h, rv));
    let (clear, front) = fronts.clear(o, g, (&xv, &moved, &lifted), (h, rv, need), push);
    let done = o.and(o.and(ok, clear), o.ge(within, o.c(0.0)));
    let pushed = o.and(push, done);
    for k in 0..3 {
        b.x[k] = store::<S, L>(o.sel(pushed, moved[k], xv[k]));
    }
    // A lane clear of r: a hover ball about it (every triangle behind F's plane at least h
    // away, each front triangle at least `front`, every other one what the certificate
    // leaves).
    let hover = o.and(done, o.le(depth, o.c(0.0)));
    if o.any(hover) {
        let certs = &lists.certs;
        let e = o.dif(&xv, &gather3::<S, L>(&certs.anchor, b.j));
        let reach = gather::<S, L>(&certs.reach, b.j);
        let far = o.sub(o.sub(reach, o.c(g.travel)), o.sqrt(o.dot(&e, &e)));
        let least = o.min(o.min(h, far), front);
        let room = store::<S, L>(o.sel(hover, o.sub(least, rv), o.c(0.0)));
        for l in (0..L).filter(|&l| room[l] > 0.0) {
            let at = DVec3::new(b.x[0][l], b.x[1][l], b.x[2][l]);
            lists.certs.set_hover(b.j[l], at, room[l], g.travel);
        }
    }
    let (done, pushed) = (o.bits::<L>(done), o.bits::<L>(pushed));
    let depth = store::<S, L>(depth);
    let mut made = Contacts::default();
    for l in 0..L {
        settled[l] |= done[l];
        if pushed[l] {
            lists.hint[b.j[l]] = b.face[l];
            made.contacts += 1;
            made.depth = made.depth.max(depth[l]);
        }
    }
    tally(1, made.contacts);
    made
}

/// The front lists of a block's faces: each lane's face `t`, its front count `count`, and
/// whether the lane's face has a usable list.
struct Fronts<'b, const L: usize> {
    t: &'b [usize; L],
    count: &'b [u8; L],
    usable: &'b [bool; L],
}

impl<const L: usize> Fronts<'_, L> {
    /// Whether every front triangle of each lane is far enough: at least min(h, r) from `x`
    /// before the push and, where the lane is `pushed`, at least r from where it ends
    /// (`moved`), shown by the triangle's plane; else at least `need` from `lifted` (where the
    /// push left it, before the slip), shown by its distance. And, for a lane not pushed, how
    /// near to `x` the front triangles may be, at least (infinite: none).
    #[inline(always)]
    fn clear<S: Simd>(
        &self,
        o: Ops<S>,
        g: &MeshGeometry,
        (x, moved, lifted): (&V3<S>, &V3<S>, &V3<S>),
        (h, r, need): (S::f64s, S::f64s, S::f64s),
        pushed: S::m64s,
    ) -> (S::m64s, S::f64s) {
        let need2 = o.mul(need, need);
        let mut clear = mask::<S, L>(o, [true; L]);
        let mut nearest = o.c(f64::INFINITY);
        let usable = self.usable;
        let most = (0..L).filter(|&l| usable[l]).map(|l| self.count[l]).max();
        for k in 0..usize::from(most.unwrap_or(0)) {
            let on: [bool; L] =
                std::array::from_fn(|l| usable[l] && k < usize::from(self.count[l]));
            let u: [usize; L] = std::array::from_fn(|l| {
                if on[l] {
                    g.fronts.front[self.t[l]][k] as usize
                } else {
                    0
                }
            });
            // The plane first (a corner and the normal); the other corners only for a
            // distance.
            let [a] = corners::<S, L, 1>(&g.triangles, &g.end, &u, [0]);
            let nt = normals::<S, L>(&g.normals, &u);
            let listed = mask::<S, L>(o, on);
            let height = o.dot(&nt, &o.dif(x, &a));
            let before = o.ge(height, o.min(h, r));
            let after = o.ge(o.dot(&nt, &o.dif(moved, &a)), r);
            let by_plane = o.and(before, o.or(o.not(pushed), after));
            let open = o.and(listed, o.not(by_plane));
            if !o.any(open) {
                // The plane's height is a lower bound on the distance to the triangle.
                nearest = o.sel(listed, o.min(nearest, height), nearest);
                continue;
            }
            #[cfg(test)]
            FRONT_DISTANCES
                .with(|c| c.set(c.get() + o.bits::<L>(open).iter().filter(|&&b| b).count()));
            let [b, c] = corners::<S, L, 2>(&g.triangles, &g.end, &u, [1, 2]);
            let d2 = distance_squared(o, lifted, [&a, &b, &c]);
            clear = o.and(clear, o.or(o.not(open), o.ge(d2, need2)));
            // A lane not pushed was measured where it is (`lifted` is `x`): its distance;
            // else the plane's height, a lower bound.
            let exact = o.and(open, o.not(pushed));
            let bound = o.sel(exact, o.sqrt(d2), height);
            nearest = o.sel(listed, o.min(nearest, bound), nearest);
        }
        (clear, nearest)
    }
}

/// Corners `k` of the triangles `t[l]` (vertex indices `triangles`, positions `vertices`),
/// per corner as vectors (a lane that takes no part names triangle 0).
#[inline(always)]
fn corners<S: Simd, const L: usize, const K: usize>(
    triangles: &[[u32; 3]],
    vertices: &[DVec3],
    t: &[usize; L],
    k: [usize; K],
) -> [V3<S>; K] {
    let mut v = [[[0.0; L]; 3]; K];
    for l in 0..L {
        let tri = triangles[t[l]];
        for i in 0..K {
            let p = vertices[tri[k[i]] as usize];
            for a in 0..3 {
                v[i][a][l] = p[a];
            }
        }
    }
    std::array::from_fn(|i| load3::<S, L>(&v[i]))
}

/// The unit normals `normals[t[l]]`, as vectors.
#[inline(always)]
fn normals<S: Simd, const L: usize>(normals: &[DVec3], t: &[usize; L]) -> V3<S> {
    let mut v = [[0.0; L]; 3];
    for l in 0..L {
        let n = normals[t[l]];
        for a in 0..3 {
            v[a][l] = n[a];
        }
    }
    load3::<S, L>(&v)
}

/// Lanes `s .. s + L` of a field kept per axis, as vectors.
#[inline(always)]
fn anchors<S: Simd, const L: usize>(field: &[Vec<f64>], s: usize) -> V3<S> {
    [
        load_at::<S, L>(&field[0], s),
        load_at::<S, L>(&field[1], s),
        load_at::<S, L>(&field[2], s),
    ]
}

/// Lanes `j[l]` of `field`, as a vector.
#[inline(always)]
fn gather<S: Simd, const L: usize>(field: &[f64], j: &[usize; L]) -> S::f64s {
    load::<S, L>(std::array::from_fn(|l| field[j[l]]))
}

/// Lanes `j[l]` of a field kept per axis, as vectors.
#[inline(always)]
fn gather3<S: Simd, const L: usize>(field: &[Vec<f64>; 3], j: &[usize; L]) -> V3<S> {
    std::array::from_fn(|k| gather::<S, L>(&field[k], j))
}

/// `bits` as a mask of `S`.
#[inline(always)]
fn mask<S: Simd, const L: usize>(o: Ops<S>, bits: [bool; L]) -> S::m64s {
    let mut ones = [0.0; L];
    for l in 0..L {
        ones[l] = if bits[l] { 1.0 } else { 0.0 };
    }
    o.eq(load::<S, L>(ones), o.c(1.0))
}

/// The squared distance from each lane's point `p` to its triangle (`a`, `b`, `c`), with no
/// branch: the squared distance to the plane where `p` projects inside the triangle, else the
/// least squared distance to its three edges (Ericson, *Real-Time Collision Detection*,
/// §5.1.2 and §5.1.5).
#[inline(always)]
fn distance_squared<S: Simd>(o: Ops<S>, p: &V3<S>, [a, b, c]: [&V3<S>; 3]) -> S::f64s {
    let (e1, e2, d) = (o.dif(b, a), o.dif(c, a), o.dif(p, a));
    let m = o.cross(&e1, &e2);
    let m2 = o.dot(&m, &m);
    let beta = o.dot(&o.cross(&e2, &m), &d);
    let gamma = o.dot(&o.cross(&m, &e1), &d);
    let hm = o.dot(&m, &d);
    let zero = o.c(0.0);
    let some = o.gt(m2, zero);
    let inside = o.and(
        o.and(o.ge(beta, zero), o.ge(gamma, zero)),
        o.and(o.le(o.add(beta, gamma), m2), some),
    );
    let edges = o.min(
        o.min(segment(o, p, a, &e1), segment(o, p, b, &o.dif(c, b))),
        segment(o, p, c, &o.dif(a, c)),
    );
    o.sel(
        inside,
        o.div(o.mul(hm, hm), o.sel(some, m2, o.c(1.0))),
        edges,
    )
}

/// The squared distance from each lane's `p` to the segment from `q` along `e`.
#[inline(always)]
fn segment<S: Simd>(o: Ops<S>, p: &V3<S>, q: &V3<S>, e: &V3<S>) -> S::f64s {
    let zero = o.c(0.0);
    let w = o.dif(p, q);
    let ee = o.dot(e, e);
    let some = o.gt(ee, zero);
    let t = o.div(o.dot(&w, e), o.sel(some, ee, o.c(1.0)));
    let t = o.sel(some, o.min(o.max(t, zero), o.c(1.0)), zero);
    let mut rr = w;
    for k in 0..3 {
        rr[k] = o.sub(w[k], o.mul(t, e[k]));
    }
    o.dot(&rr, &rr)
}
