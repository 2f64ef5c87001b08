//! A still mesh's first test (`grid_run`) for `L` particles side by side in explicit vectors
//! of any [`pulp::Simd`]: eight lanes of AVX-512, four of AVX2, two of portable code, one for
//! a particle alone. Every lane runs the same IEEE operations in the same order (no fused
//! multiply-adds, every branch a select), so a particle gets the same bits at every width.
//!
//! Written with explicit vectors: the same test over lane arrays in a block struct compiled to
//! scalar code and stores read back at another width (the draped cloth's grid pass ran about
//! 1,400 instructions a block of eight).

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use pulp::Simd;
use weft_simd::{Ops, V3, load, store};
use weft_solver::Contacts;

use super::face_cert::{A, CLEAR, FIELDS, FaceCert, INSIDE, N, Placement, Settled, U, V};
use crate::friction::Friction;

/// The lanes of a block, in the mesh's frame, and the triangles they touched last.
pub(crate) struct Lanes<S: Simd> {
    /// Positions, moved by the test.
    pub x: V3<S>,
    /// Where each path starts: the substep's start, or the last projection.
    pub from: V3<S>,
    /// Positions at the substep's start.
    pub prev: V3<S>,
    /// Thickness (m).
    pub r: S::f64s,
    /// Lanes that take part (free particles).
    pub live: S::m64s,
    /// Where each clear ball is centred.
    pub anchor: V3<S>,
    /// Its radius; NaN where there is none.
    pub ball: S::f64s,
}

/// What the first test did with a block's lanes.
pub(crate) struct Verdict<const L: usize> {
    /// What it did per lane.
    pub settled: [Settled; L],
    /// A new clear ball about the lane's position, where the triangle's test cleared it
    /// outside its ball: the radius, or NaN.
    pub new_ball: [f64; L],
    /// The contacts it made.
    pub contacts: Contacts,
}

impl<S: Simd> Lanes<S> {
    /// Whether each lane's path lies in its clear ball (NaN radius: none does).
    #[inline(always)]
    pub fn in_ball(&self, o: Ops<S>) -> S::m64s {
        let b2 = o.mul(self.ball, self.ball);
        let q = o.dif(&self.x, &self.anchor);
        let e = o.dif(&self.from, &self.anchor);
        o.and(o.le(o.dot(&q, &q), b2), o.le(o.dot(&e, &e), b2))
    }
}

/// Each lane's triangle record `certs[t[l]]` per field, or the last record where t[l] is
/// past it (the grid keeps [`FaceCert::NONE`] there).
#[inline(always)]
pub(crate) fn gather<S: Simd, const L: usize>(
    certs: &[FaceCert],
    t: [usize; L],
) -> [S::f64s; FIELDS] {
    let Some(last) = certs.len().checked_sub(1) else {
        return std::array::from_fn(|k| load::<S, L>([FaceCert::NONE.0[k]; L]));
    };
    let at: [&FaceCert; L] = std::array::from_fn(|l| &certs[t[l].min(last)]);
    std::array::from_fn(|k| load::<S, L>(std::array::from_fn(|l| at[l].0[k])))
}

/// The first test of every live lane against its triangle `f`, with the mesh still over the
/// substep; moves the lanes it pushes, and returns what it did with them and the mask of
/// those it pushed. A lane is settled where its path lies in its clear
/// ball (no point of the ball is within r of the mesh, so neither a contact nor a crossing),
/// or where its path is shorter than r/2 (so no sweep is due) and either
///
/// - it is r or more in front of the plane and near enough to corner a that every triangle
///   in front of the plane is beyond r (`ContactGrid::clearance`): clear; or
/// - its projection lies inside the face, in front, with d + r (d the distance, at least r)
///   within the clearance: the face is nearest of all within r, and a particle nearer than r
///   is pushed along the normal to r, then slid back by Coulomb friction against the still
///   surface (Macklin et al. 2014, eq. 24; `Friction::correction`). If the slip may have
///   carried it past the clearance, the cell is scanned next ([`Settled::Rounds`]).
#[inline(always)]
pub(crate) fn settle<S: Simd, const L: usize>(
    o: Ops<S>,
    b: &mut Lanes<S>,
    in_ball: S::m64s,
    f: &[S::f64s; FIELDS],
    friction: Friction,
) -> (Verdict<L>, S::m64s) {
    let p = o.dif(&b.x, &b.from);
    let half = o.mul(o.c(0.5), b.r);
    let short = o.le(o.dot(&p, &p), o.mul(half, half));
    let v = [
        o.sub(b.x[0], f[A]),
        o.sub(b.x[1], f[A + 1]),
        o.sub(b.x[2], f[A + 2]),
    ];
    let normal = [f[N], f[N + 1], f[N + 2]];
    let h = o.dot(&normal, &v);
    let to_a = o.dot(&v, &v);
    let r = b.r;
    let room = o.sub(f[CLEAR], r);
    let (beta, gamma) = (
        o.dot(&[f[U], f[U + 1], f[U + 2]], &v),
        o.dot(&[f[V], f[V + 1], f[V + 2]], &v),
    );
    let inside = o.and(
        o.and(o.gt(beta, o.c(INSIDE)), o.gt(gamma, o.c(INSIDE))),
        o.lt(o.add(beta, gamma), o.c(1.0 - INSIDE)),
    );
    let live = o.and(b.live, short);
    let clear = o.or(
        o.and(b.live, in_ball),
        o.and(
            o.and(o.and(live, o.ge(h, r)), o.ge(room, o.c(0.0))),
            o.le(to_a, o.mul(room, room)),
        ),
    );
    let settled = o.and(
        o.and(o.and(live, inside), o.gt(h, o.c(1e-12))),
        o.le(o.add(o.max(h, r), r), f[CLEAR]),
    );
    // How far past r from the mesh the triangle's test proves each lane to be: triangles
    // behind the plane are h or more away, those in front the clearance less the distance to
    // this triangle (h over the face, at most |x − a| anywhere).
    let near = o.sel(inside, h, o.sqrt(to_a));
    let spare = o.sub(o.min(h, o.sub(f[CLEAR], near)), r);
    let depth = o.sub(r, h);
    let push = o.and(
        o.and(settled, o.not(clear)),
        o.gt(depth, o.mul(o.c(1e-6), o.max(r, o.c(1e-3)))),
    );
    let done = o.or(clear, settled);
    // A clear ball about a lane the triangle cleared outside its ball: no triangle is within
    // r of any point within `spare` of it.
    let fresh = o.and(
        o.and(o.and(done, o.not(push)), o.not(in_ball)),
        o.gt(spare, o.c(0.0)),
    );
    let new_ball = store::<S, L>(o.sel(fresh, o.mul(spare, o.c(1.0 - 1e-9)), o.c(f64::NAN)));
    let done_lanes = o.bits::<L>(done);
    let mut settled_out = done_lanes.map(|d| if d { Settled::Done } else { Settled::Open });
    if !o.any(push) {
        let verdict = Verdict {
            settled: settled_out,
            new_ball,
            contacts: Contacts::default(),
        };
        return (verdict, push);
    }
    // Pushed out along the normal, then friction on the slip since the substep's start.
    let (moved, slip2) = push_vectors(o, friction, &b.x, &b.prev, &normal, depth, push);
    b.x = moved;
    // Pushed to r off the face, then slipped across its normal: still clear of the triangles
    // in front if within the clearance less r.
    let room = o.sub(f[CLEAR], o.mul(o.c(2.0), r));
    let rounds = o.bits::<L>(o.and(push, o.gt(slip2, o.mul(room, room))));
    let pushed = o.bits::<L>(push);
    let depth = store::<S, L>(depth);
    let mut tally = Contacts::default();
    for l in 0..L {
        if pushed[l] {
            if rounds[l] {
                settled_out[l] = Settled::Rounds;
            }
            tally.contacts += 1;
            tally.depth = tally.depth.max(depth[l]);
        }
    }
    let verdict = Verdict {
        settled: settled_out,
        new_ball,
        contacts: tally,
    };
    (verdict, push)
}

/// The push-out and friction of the lanes `push` against a still surface, as
/// `friction::push_lanes` (Macklin et al. 2014, eq. 24), operation for operation: each
/// lane's position `x` moved by `depth` along its unit `normal`, then its slip since `prev`
/// across the normal corrected as [`Friction::correction`] does. Returns the new positions (a
/// lane not pushed keeps its own) and each pushed lane's correction, squared.
#[inline(always)]
pub(super) fn push_vectors<S: Simd>(
    o: Ops<S>,
    friction: Friction,
    x: &V3<S>,
    prev: &V3<S>,
    n: &V3<S>,
    depth: S::f64s,
    push: S::m64s,
) -> (V3<S>, S::f64s) {
    let mut moved = *x;
    for a in 0..3 {
        moved[a] = o.add(x[a], o.mul(n[a], depth));
    }
    let rel = o.dif(&moved, prev);
    let along = o.dot(n, &rel);
    let mut t = rel;
    for a in 0..3 {
        t[a] = o.sub(rel[a], o.mul(n[a], along));
    }
    let t2 = o.dot(&t, &t);
    let grip = o.mul(o.c(friction.static_coefficient), depth);
    let stick = o.lt(t2, o.mul(grip, grip));
    let no_slip = o.le(t2, o.c(0.0));
    // Sticking: t itself (t · 1 = t exactly). The square root and the division only where a
    // pushed lane slides (a block at rest sticks throughout).
    let one = o.c(1.0);
    let scale = if o.any(o.and(push, o.not(stick))) {
        let sliding = o.min(
            o.div(o.mul(o.c(friction.dynamic_coefficient), depth), o.sqrt(t2)),
            one,
        );
        o.sel(stick, one, sliding)
    } else {
        one
    };
    let mut slip2 = o.c(0.0);
    let mut out = *x;
    for a in 0..3 {
        // No slip: the correction is +0 (t · 0 may be −0, which would turn a −0 position
        // into +0).
        let correction = o.sel(no_slip, o.c(0.0), o.mul(t[a], scale));
        slip2 = o.add(slip2, o.mul(correction, correction));
        out[a] = o.sel(push, o.sub(moved[a], correction), x[a]);
    }
    (out, slip2)
}

/// World positions `w` in the mesh's frame: Bᵀ (w − t), or `w` itself where the mesh's pose
/// is the world's frame.
#[inline(always)]
pub(crate) fn local<S: Simd>(o: Ops<S>, place: &Placement, w: &V3<S>) -> V3<S> {
    if place.identity {
        return *w;
    }
    let mut d = *w;
    for a in 0..3 {
        d[a] = o.sub(w[a], o.c(place.shift[a]));
    }
    let mut out = d;
    for k in 0..3 {
        let c = &place.basis[k];
        out[k] = o.add(
            o.add(o.mul(o.c(c[0]), d[0]), o.mul(o.c(c[1]), d[1])),
            o.mul(o.c(c[2]), d[2]),
        );
    }
    out
}

/// World positions `w` of lanes moved from `old` to `new` in the mesh's frame (lanes not
/// `moved` keep theirs): w + B (new − old), or `new` where the mesh's pose is the world's
/// frame.
#[inline(always)]
pub(crate) fn world<S: Simd>(
    o: Ops<S>,
    place: &Placement,
    w: &V3<S>,
    old: &V3<S>,
    new: &V3<S>,
    moved: S::m64s,
) -> V3<S> {
    let d = o.dif(new, old);
    let mut out = *w;
    for a in 0..3 {
        let shifted = if place.identity {
            new[a]
        } else {
            let b = &place.basis;
            o.add(
                w[a],
                o.add(
                    o.add(o.mul(o.c(b[0][a]), d[0]), o.mul(o.c(b[1][a]), d[1])),
                    o.mul(o.c(b[2][a]), d[2]),
                ),
            )
        };
        out[a] = o.sel(moved, shifted, w[a]);
    }
    out
}
