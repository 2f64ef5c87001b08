//! A mesh's contacts through its candidate lists (`candidates`) for a run of particles side by
//! side, [`LANES`] at a time, in the mesh's own frame (a mesh whose pose is the identity
//! throughout: a deforming mesh, or a still one too large for a contact grid). A list that
//! does not hold is built again first, as `MeshFrame::resolve` would. Two cases, which make
//! up most of a draped cloth's particles, then settle here a block at a time:
//!
//! - a particle whose list is empty: nothing within reach, nothing to do;
//! - a particle whose path is short (no sweep is due) and whose list holds no triangle within
//!   its thickness r but, perhaps, the one it touched last, touched from in front and inside
//!   its face, or holds others within r but none nearer than that face (shown without a
//!   distance where every other listed triangle lies below the face's plane, as on a convex
//!   patch; else each one's distance worked out a block of triangles at a time, or on a still
//!   mesh bounded by its plane first): it is pushed along that face's normal to r and slid
//!   back by friction against the surface's motion there, as `resolve` would, and settles if
//!   every other listed triangle is then r away.
//!
//! Every other particle goes through `resolve`, from where it was. What a lane does depends on
//! that particle alone, the run's last particles (past the last full block) take the same
//! test a lane at a time, and so does a particle resolved on its own, in the fused frame or
//! the general loop ([`MeshFrame::resolve_listed`]): the bits do not depend on where a
//! particle falls, nor on which loop runs it.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::{Scalar, Simd};
use weft_simd::{LaneKernel, Ops, on_path};
use weft_solver::{Contacts, ParticleRun};

use super::MeshGeometry;
use super::certified::{certified, face_test, path_starts, screen};
use super::chunk_lists::ChunkLists;
use super::frame::{MeshFrame, Outcome, RunParticle};
use crate::friction::push_lanes;

/// Particles per block of the lane test: eight f64, one AVX-512 register or two AVX2 ones.
const LANES: usize = 8;

/// Projections nearer than this (barycentric) to an edge of the face are left to `resolve`.
const INSIDE: f64 = 1e-9;

/// How far (a fraction of r) another listed triangle may rise above the plane below which
/// the flat test counts it r away: the rounding of its corners' heights (a contact that
/// shallow is none, as the lane test's own push leaves one of up to 10⁻⁶ r).
const FLAT: f64 = 1e-9;

impl MeshFrame<'_> {
    /// Whether the block test of [`resolve_list_run`] applies: the mesh's pose is the identity
    /// over the substep (its surface may deform).
    #[inline]
    pub(crate) fn lists_settle(&self) -> bool {
        self.identity && self.still
    }
}

/// Every free particle of `run` (thickness `r`) against the mesh of `frame` (for which
/// [`MeshFrame::lists_settle`] holds), through the run's candidate lists `lists` (indexed
/// from the run's start): the certified test's screen (`screen`) a block at a time, its face
/// test (`face_test`) on the particles the screen sends it packed into full blocks, then the
/// lane test and `MeshFrame::resolve` for each particle they left open. Compiled for the run's
/// kernel path (every path gives the same bits).
pub(crate) fn resolve_list_run(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    on_path(
        run.path,
        Blocks {
            frame,
            lists,
            r,
            run,
        },
    )
}

/// [`resolve_list_run`]'s arguments, a [`LaneKernel`] run on the vectors of whatever [`Simd`]
/// [`on_path`] hands it.
struct Blocks<'f, 'a, 'r, 'c> {
    frame: &'f MeshFrame<'a>,
    lists: &'f mut ChunkLists,
    r: &'f [f64],
    run: &'r mut ParticleRun<'c>,
}

impl LaneKernel for Blocks<'_, '_, '_, '_> {
    type Output = Contacts;

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> Contacts {
        run_blocks::<S, L>(Ops(s), self)
    }
}

#[inline(always)]
fn run_blocks<S: Simd, const L: usize>(o: Ops<S>, b: Blocks<'_, '_, '_, '_>) -> Contacts {
    let Blocks {
        frame,
        lists,
        r,
        run,
    } = b;
    let n = run.w.len();
    if !r[..n].iter().any(|&r| frame.certifies(r)) {
        return lane_blocks(frame, lists, r, run);
    }
    let full = n - n % L;
    let mut total = Contacts::default();
    // The screen a block at a time; the lanes it sends to the face test are queued, and
    // tested packed into full blocks after (what a lane does depends on that particle
    // alone, so not on which block it is tested in).
    let mut queue = std::mem::take(&mut lists.queue);
    queue.clear();
    for s in (0..full).step_by(L) {
        let (mut x, mut prev, mut rr) = ([[0.0; L]; 3], [[0.0; L]; 3], [0.0; L]);
        for k in 0..3 {
            x[k].copy_from_slice(&run.x[k][s..s + L]);
            prev[k].copy_from_slice(&run.prev[k][s..s + L]);
        }
        rr.copy_from_slice(&r[s..s + L]);
        let live: [bool; L] = std::array::from_fn(|l| run.w[s + l] != 0.0);
        let screened = screen::<S, L>(o, frame, lists, s, (&x, &prev), (&rr, live));
        queue.extend((0..L).filter(|&l| screened.near[l]).map(|l| s + l));
        for l in 0..L {
            if live[l] && !screened.settled[l] && !screened.near[l] {
                let j = s + l;
                total = total.merge(on_particle(run, j, |prev, p| {
                    frame
                        .open(RunParticle::new(lists, j, prev, p, r[j]), false)
                        .into()
                }));
            }
        }
    }
    for block in queue.chunks(L) {
        // A short block's spare lanes repeat its first particle and take no part.
        let j: [usize; L] = std::array::from_fn(|l| block.get(l).copied().unwrap_or(block[0]));
        let near: [bool; L] = std::array::from_fn(|l| l < block.len());
        let (mut x, mut prev, mut rr) = ([[0.0; L]; 3], [[0.0; L]; 3], [0.0; L]);
        for l in 0..L {
            for k in 0..3 {
                x[k][l] = run.x[k][j[l]];
                prev[k][l] = run.prev[k][j[l]];
            }
            rr[l] = r[j[l]];
        }
        let done = face_test::<S, L>(o, frame, lists, &j, (&mut x, &prev), (&rr, near));
        total = total.merge(done.contacts);
        for l in (0..L).filter(|&l| near[l]) {
            for k in 0..3 {
                run.x[k][j[l]] = x[k][l];
            }
            if !done.settled[l] {
                total = total.merge(on_particle(run, j[l], |prev, p| {
                    frame
                        .open(RunParticle::new(lists, j[l], prev, p, rr[l]), done.ring[l])
                        .into()
                }));
            }
        }
    }
    lists.queue = queue;
    for j in full..n {
        if run.w[j] == 0.0 {
            continue;
        }
        total = total.merge(on_particle(run, j, |prev, p| {
            frame
                .resolve_listed(RunParticle::new(lists, j, prev, p, r[j]))
                .into()
        }));
    }
    total
}

/// `f` on particle `j` of `run`: its substep start, and its position, moved in place.
#[inline(always)]
fn on_particle(
    run: &mut ParticleRun<'_>,
    j: usize,
    f: impl FnOnce(DVec3, &mut DVec3) -> Contacts,
) -> Contacts {
    let mut p = DVec3::new(run.x[0][j], run.x[1][j], run.x[2][j]);
    let prev = DVec3::new(run.prev[0][j], run.prev[1][j], run.prev[2][j]);
    let made = f(prev, &mut p);
    for k in 0..3 {
        run.x[k][j] = p[k];
    }
    made
}

/// A run none of whose particles the mesh certifies (`MeshFrame::certifies`): the lane test
/// [`LANES`] particles at a time, then `resolve` for each lane it leaves open (the same bits
/// as one at a time).
#[inline(always)]
fn lane_blocks(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    let n = run.w.len();
    let full = n - n % LANES;
    let mut total = Contacts::default();
    for s in (0..full).step_by(LANES) {
        total = total.merge(block::<LANES>(frame, lists, r, run, s));
    }
    for s in full..n {
        total = total.merge(block::<1>(frame, lists, r, run, s));
    }
    total
}

/// [`lanes`] on particles `s .. s + L` of `run`.
#[inline(always)]
fn block<const L: usize>(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    r: &[f64],
    run: &mut ParticleRun<'_>,
    s: usize,
) -> Contacts {
    let (mut x, mut prev, mut rr) = ([[0.0; L]; 3], [[0.0; L]; 3], [0.0; L]);
    for k in 0..3 {
        x[k].copy_from_slice(&run.x[k][s..s + L]);
        prev[k].copy_from_slice(&run.prev[k][s..s + L]);
    }
    rr.copy_from_slice(&r[s..s + L]);
    let mut live = [false; L];
    for l in 0..L {
        live[l] = run.w[s + l] != 0.0;
    }
    let total = lanes(frame, lists, s, (&mut x, &prev), (&rr, live));
    for k in 0..3 {
        run.x[k][s..s + L].copy_from_slice(&x[k]);
    }
    total
}

impl MeshFrame<'_> {
    /// Particle `j` of `lists` (thickness `r`, previous position `prev`, current `x`) as a
    /// run of one: the certified test and the lane test where [`Self::lists_settle`] holds,
    /// else `resolve`. Every particle of a mesh with lists takes this path or a block of the
    /// same tests, so its bits do not depend on which.
    pub(crate) fn resolve_listed(&self, p: RunParticle<'_>) -> Outcome {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        if !self.lists_settle() {
            return self.resolve(RunParticle::new(lists, j, prev, x, r));
        }
        let mut at = [[x.x], [x.y], [x.z]];
        let before = [[prev.x], [prev.y], [prev.z]];
        let done = certified::<Scalar>(
            Ops(Scalar),
            self,
            lists,
            j,
            (&mut at, &before),
            (&[r], [true]),
        );
        *x = DVec3::new(at[0][0], at[1][0], at[2][0]);
        if done.settled[0] {
            return done.contacts.into();
        }
        let out = self.open(RunParticle::new(lists, j, prev, x, r), done.ring[0]);
        Contacts::from(out).merge(done.contacts).into()
    }

    /// Particle `j` left open by the certified test: among its face's ring where its
    /// certificate allows (`ring`), else through the lists; a new certificate where it has
    /// come to rest on another face.
    fn open(&self, p: RunParticle<'_>, ring: bool) -> Outcome {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        // Over a convex edge of its face by that edge, else among the face's ring, else
        // through the lists.
        let settled = if ring {
            (self.edge_contact(RunParticle::new(lists, j, prev, x, r)))
                .or_else(|| self.resolve_ring(RunParticle::new(lists, j, prev, x, r)))
        } else {
            None
        };
        let out = match settled {
            Some(out) => out,
            None => self.listed(RunParticle::new(lists, j, prev, x, r)),
        };
        // As a run none of whose particles the mesh certifies would (`lane_blocks`).
        if self.certifies(r) {
            self.recertify(lists, j, *x, r);
        }
        out
    }

    /// Particle `j` through its lists: the lane test as a run of one, then `resolve` where it
    /// leaves it open.
    fn listed(&self, p: RunParticle<'_>) -> Outcome {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        let mut at = [[x.x], [x.y], [x.z]];
        let before = [[prev.x], [prev.y], [prev.z]];
        let total = lanes::<1>(self, lists, j, (&mut at, &before), (&[r], [true]));
        *x = DVec3::new(at[0][0], at[1][0], at[2][0]);
        total.into()
    }
}

/// The lane test of particles `s .. s + L` of `lists` (see the module's notes) at `x`
/// (moved in place), their substep starts `prev`, thicknesses `r`, taking part where `live`,
/// then `MeshFrame::resolve` for each lane it left open, in order.
#[inline(always)]
fn lanes<const L: usize>(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    s: usize,
    (x, prev): (&mut [[f64; L]; 3], &[[f64; L]; 3]),
    (rr, live): (&[f64; L], [bool; L]),
) -> Contacts {
    let from = path_starts::<L>(frame, lists, &std::array::from_fn(|l| s + l), prev);
    // Done: the list holds and is empty. Near: the list holds and is not, the path is short
    // and the particle was outside: the hint's test follows. Open: `resolve`.
    let (mut done, mut near, mut open) = ([false; L], [false; L], [false; L]);
    let mut stale = [false; L];
    for l in 0..L {
        let lane = Lane::of(frame, lists, s + l, (x, &from, rr[l]), l);
        stale[l] = live[l] & !lane.valid;
        done[l] = live[l] & lane.valid & lane.empty & lane.outside;
        near[l] = live[l] & lane.valid & !lane.empty & lane.outside & lane.short;
        open[l] = live[l] & !done[l] & !near[l];
    }
    // A list the surface's travel does not show to hold may hold by its riding certificate;
    // if not, it is built again here (as `resolve` would first), and the lane tested with it.
    for l in 0..L {
        if !stale[l] {
            continue;
        }
        let at = |v: &[[f64; L]; 3]| DVec3::new(v[0][l], v[1][l], v[2][l]);
        frame.ensure(lists, s + l, at(x), at(&from), rr[l]);
        let lane = Lane::of(frame, lists, s + l, (x, &from, rr[l]), l);
        done[l] = lane.empty & lane.outside;
        near[l] = !lane.empty & lane.outside & lane.short;
        open[l] = !done[l] & !near[l];
    }
    let mut total = Contacts::default();
    if near.contains(&true) {
        total = settle(
            frame,
            lists,
            s,
            (x, prev, rr),
            (&mut done, &near, &mut open),
        );
    }
    for l in 0..L {
        let j = s + l;
        if done[l] {
            lists.last[j] = DVec3::new(x[0][l], x[1][l], x[2][l]);
        } else if open[l] {
            let mut p = DVec3::new(x[0][l], x[1][l], x[2][l]);
            let before = DVec3::new(prev[0][l], prev[1][l], prev[2][l]);
            let out = frame.resolve(RunParticle::new(lists, j, before, &mut p, rr[l]));
            for k in 0..3 {
                x[k][l] = p[k];
            }
            total = total.merge(out.into());
        }
    }
    total
}

/// What a lane's list says of it.
struct Lane {
    /// The list holds every triangle within r of the particle and its path (by the surface's
    /// travel alone, as `MeshFrame::valid_by_travel`).
    valid: bool,
    /// The list is empty.
    empty: bool,
    /// The particle was outside when its list was built.
    outside: bool,
    /// The path is too short to cross the surface from r away (as `first_crossing`).
    short: bool,
}

impl Lane {
    /// Lane `l` (particle `j` of the run) at `x`, its path from `from`, thickness `r`.
    #[inline(always)]
    fn of<const L: usize>(
        frame: &MeshFrame<'_>,
        lists: &ChunkLists,
        j: usize,
        (x, from, r): (&[[f64; L]; 3], &[[f64; L]; 3], f64),
        l: usize,
    ) -> Self {
        let (x, from) = (
            DVec3::from_array(lane(x, l)),
            DVec3::from_array(lane(from, l)),
        );
        Self {
            valid: frame.valid_by_travel(lists, j, x, from, r),
            empty: lists.range[j].1 == 0,
            outside: !lists.inside[j],
            short: frame.short_path(from, x, r),
        }
    }
}

/// The test of the `near` lanes of the block at `s` (positions `x`, moved in place where a
/// lane settles, substep starts `prev`, thicknesses `r`) against the triangle each touched
/// last: marks each lane it settles `done` and each it cannot `open`; returns the contacts
/// made. A lane settles where every other listed triangle is at least r away ([`below`] where
/// they all lie below the face's plane, else [`others`]) and its last triangle is too. Where
/// the lane's projection lies inside that face, in front of it at h < r, and the face is
/// nearest of all (every other listed triangle at least h away, as `resolve`'s scan would
/// find it), it is pushed to h = r along the normal and slid back by Coulomb friction against
/// the surface's displacement at the touched point over the substep (Macklin et al. 2014,
/// eq. 24; `Friction::correction`), and it settles if the others are then r away: by their
/// distance less the push and the slip, or else from where it is now (as
/// `MeshFrame::look_again`; beside a convex edge the face across it is within r before the
/// push and r away after).
#[inline(always)]
fn settle<const L: usize>(
    frame: &MeshFrame<'_>,
    lists: &ChunkLists,
    s: usize,
    (x, prev, r): (&mut [[f64; L]; 3], &[[f64; L]; 3], &[f64; L]),
    (done, near, open): (&mut [bool; L], &[bool; L], &mut [bool; L]),
) -> Contacts {
    let g = frame.geometry;
    // The lanes' last triangles: corners a, b, c and unit normal, per field.
    let mut f = [[0.0; L]; 12];
    let mut tri = [u32::MAX; L];
    for l in 0..L {
        let t = lists.hint[s + l];
        if let (true, Some(face)) = (near[l], g.face_get(t as usize)) {
            tri[l] = t;
            for c in 0..3 {
                for k in 0..3 {
                    f[3 * c + k][l] = face.corners[c][k];
                }
            }
            for k in 0..3 {
                f[9 + k][l] = face.normal[k];
            }
        }
    }
    // With e₁ = b − a, e₂ = c − a, m = e₁ × e₂: u = (e₂ × m)/|m|², v = (m × e₁)/|m|², so that
    // x's projection is a + β e₁ + γ e₂ with β = u · (x − a), γ = v · (x − a).
    let (mut h, mut beta, mut gamma) = ([0.0; L], [0.0; L], [0.0; L]);
    for l in 0..L {
        let at = |k: usize| [f[k][l], f[k + 1][l], f[k + 2][l]];
        let (a, b, c, n) = (at(0), at(3), at(6), at(9));
        let (e1, e2) = (sub(b, a), sub(c, a));
        let m = cross(e1, e2);
        let m2 = dot(m, m);
        let (u, v) = (cross(e2, m), cross(m, e1));
        let d = sub(lane(x, l), a);
        h[l] = dot(n, d);
        beta[l] = dot(u, d) / m2;
        gamma[l] = dot(v, d) / m2;
    }
    // The face test stands where the projection is inside the face and x in front of it.
    let mut face = [false; L];
    for l in 0..L {
        face[l] = (tri[l] != u32::MAX)
            & (beta[l] > INSIDE)
            & (gamma[l] > INSIDE)
            & (beta[l] + gamma[l] < 1.0 - INSIDE)
            & (h[l] > 1e-12);
    }
    // The other listed triangles (the last one too, where its face test does not stand).
    let mut skip = [u32::MAX; L];
    for l in 0..L {
        if face[l] {
            skip[l] = tri[l];
        }
    }
    // Where the face test stands and every other listed triangle lies below the face's plane
    // (every corner no higher than where the particle will sit less r), each is r away and
    // the face nearest: their distances are not needed.
    let (mut depth, mut tiny, mut lift) = ([0.0; L], [false; L], [0.0; L]);
    let mut faced = [false; L];
    for l in 0..L {
        depth[l] = r[l] - h[l];
        tiny[l] = depth[l] <= 1e-6 * r[l].max(1e-3);
        // Pushed, the particle sits at r; else where it is.
        let sits = if tiny[l] { h[l] } else { r[l] };
        lift[l] = sits - r[l] + FLAT * r[l];
        faced[l] = near[l] & face[l];
    }
    let flat = below(g, lists, s, (&f, &lift), &faced, &skip);
    let mut rest = [false; L];
    for l in 0..L {
        rest[l] = near[l] & !flat[l];
        #[cfg(test)]
        tests::FLAT.with(|c| c.set(c.get() + usize::from(flat[l])));
    }
    // The others' least distance (none, infinite, for the flat lanes).
    let second = others(g, lists, s, (x, r), &rest, &skip);
    let mut push = [false; L];
    for l in 0..L {
        let others_clear = second[l] >= r[l] * r[l];
        let tiny = tiny[l];
        // The last triangle is nearest of all (`resolve` tests it first and keeps it on a
        // tie): pushed out of it first, the others are checked from there.
        let nearest = h[l] * h[l] <= second[l];
        push[l] = near[l] & (others_clear | nearest) & face[l] & !tiny;
        // Nothing within r, or within rounding of r already (`push` leaves it).
        let clear = near[l] & others_clear & (!face[l] | tiny);
        done[l] |= clear;
        #[cfg(test)]
        tests::SETTLED.with(|c| c.set(c.get() + usize::from(clear)));
        open[l] |= near[l] & !clear & !push[l];
    }
    if !push.contains(&true) {
        return Contacts::default();
    }
    // The friction's reference: the start position carried along with the surface's
    // displacement at the touched point (none where it is still).
    let mut carried = *prev;
    if g.moving {
        for l in 0..L {
            if !push[l] {
                continue;
            }
            let bary = [1.0 - beta[l] - gamma[l], beta[l], gamma[l]];
            let moved = frame.surface_displacement(tri[l] as usize, bary);
            for k in 0..3 {
                carried[k][l] += moved[k];
            }
        }
    }
    let normal = [&f[9], &f[10], &f[11]];
    let (moved, slip2) = push_lanes(frame.friction, x, &carried, normal, &depth, &push);
    let mut tally = Contacts::default();
    let mut again = [false; L];
    for l in 0..L {
        if !push[l] {
            continue;
        }
        // After a push by δ and a slip of s every distance drops by at most δ + s.
        again[l] = second[l].sqrt() - depth[l] - slip2[l].sqrt() < r[l];
    }
    // Where that does not clear the others, their distances from where the push left it.
    if again.contains(&true) {
        let after = others(g, lists, s, (&moved, r), &again, &skip);
        for l in 0..L {
            if again[l] && after[l] < r[l] * r[l] {
                push[l] = false;
                open[l] = true;
            }
        }
    }
    for l in 0..L {
        if !push[l] {
            continue;
        }
        for k in 0..3 {
            x[k][l] = moved[k][l];
        }
        done[l] = true;
        #[cfg(test)]
        tests::SETTLED.with(|c| c.set(c.get() + 1));
        tally.contacts += 1;
        tally.depth = tally.depth.max(depth[l]);
    }
    tally
}

/// Whether every triangle of each `which` lane's list but `skip` lies on or below the plane
/// `lift` above the lane's face (`f`: corners a, b, c and unit normal n, per field), every
/// corner c with n · (c − a) ≤ lift. Then every point y of them is at least
/// n · (x − a) − lift from a particle at x, since |x − y| ≥ n · (x − y): at least r once the
/// particle sits r + lift above the plane (on a convex patch every other triangle lies below
/// the face's plane, lift 0).
#[inline(always)]
fn below<const L: usize>(
    g: &MeshGeometry,
    lists: &ChunkLists,
    s: usize,
    (f, lift): (&[[f64; L]; 12], &[f64; L]),
    which: &[bool; L],
    skip: &[u32; L],
) -> [bool; L] {
    let mut out = [false; L];
    for l in 0..L {
        if !which[l] {
            continue;
        }
        let a = [f[0][l], f[1][l], f[2][l]];
        let n = [f[9][l], f[10][l], f[11][l]];
        out[l] = listed_but(lists, s + l, skip[l]).all(|t| {
            let c = g.corners(t as usize);
            let high = |k: usize| dot(n, sub(c[k].to_array(), a));
            high(0).max(high(1)).max(high(2)) <= lift[l]
        });
    }
    out
}

/// The triangles of particle `j`'s list but `skip`, in its order.
#[inline(always)]
fn listed_but(lists: &ChunkLists, j: usize, skip: u32) -> impl Iterator<Item = u32> + '_ {
    let (start, len) = lists.range[j];
    (lists.tris[start as usize..(start + len) as usize].iter())
        .copied()
        .filter(move |&t| t != skip)
}

/// Lane `l` of `v`.
#[inline(always)]
fn lane<const L: usize>(v: &[[f64; L]; 3], l: usize) -> [f64; 3] {
    [v[0][l], v[1][l], v[2][l]]
}

#[inline(always)]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The least squared distance from each lane's position in `x` (thickness `r`) where `which`
/// to the triangles of its list but `skip`: on a still surface each one's bound (`Planes`)
/// and, where that does not clear r, the distance itself; on a moving one the distance
/// always (its planes are the frame end's, every bound less the surface's travel still to
/// come, and most neighbours of a touched face fail them). Distances are worked out for a
/// block of triangles at a time.
#[inline(always)]
fn others<const L: usize>(
    g: &MeshGeometry,
    lists: &ChunkLists,
    s: usize,
    (x, r): (&[[f64; L]; 3], &[f64; L]),
    which: &[bool; L],
    skip: &[u32; L],
) -> [f64; L] {
    let mut least = [f64::INFINITY; L];
    let mut pending = Pending::new();
    for l in 0..L {
        if !which[l] {
            continue;
        }
        let x32 = DVec3::new(x[0][l], x[1][l], x[2][l]).as_vec3();
        let r2 = r[l] * r[l];
        let mut bounds = f64::INFINITY;
        for t in listed_but(lists, s + l, skip[l]) {
            let bound = if g.moving {
                0.0
            } else {
                f64::from(g.planes[t as usize].distance_squared_bound(x32, g.margin))
            };
            if bound >= r2 {
                bounds = bounds.min(bound);
            } else if pending.add(l, t) {
                pending.flush(g, x, &mut least);
            }
        }
        least[l] = least[l].min(bounds);
    }
    pending.flush(g, x, &mut least);
    least
}

/// Triangles whose distance a block works out together.
const PENDING: usize = 8;

/// (lane, triangle) pairs whose squared distance is still to be worked out.
struct Pending {
    lane: [usize; PENDING],
    tri: [u32; PENDING],
    len: usize,
}

impl Pending {
    fn new() -> Self {
        Self {
            lane: [0; PENDING],
            tri: [0; PENDING],
            len: 0,
        }
    }

    /// Adds a pair; whether the buffer is now full.
    #[inline(always)]
    fn add(&mut self, lane: usize, t: u32) -> bool {
        self.lane[self.len] = lane;
        self.tri[self.len] = t;
        self.len += 1;
        self.len == PENDING
    }

    /// Lowers each pending pair's lane in `least` to its squared distance from the lane's
    /// position in `x`, and empties the buffer.
    #[inline(always)]
    fn flush<const L: usize>(&mut self, g: &MeshGeometry, x: &[[f64; L]; 3], least: &mut [f64; L]) {
        if self.len == 0 {
            return;
        }
        let mut p = [[0.0; PENDING]; 3];
        let mut corners = [[[0.0; PENDING]; 3]; 3];
        for k in 0..PENDING {
            // Unused entries repeat the first pair.
            let e = if k < self.len { k } else { 0 };
            let face = g.face(self.tri[e] as usize);
            for a in 0..3 {
                p[a][k] = x[a][self.lane[e]];
                for c in 0..3 {
                    corners[c][a][k] = face.corners[c][a];
                }
            }
        }
        let d2 = distance_squared_lanes(&p, &corners);
        for k in 0..self.len {
            let l = self.lane[k];
            least[l] = least[l].min(d2[k]);
        }
        self.len = 0;
    }
}

/// The squared distance from each lane's point `p` to its triangle (`corners` a, b, c), with
/// no branch: the squared distance to the plane, (m · (p − a))² / |m|² with m = (b − a) ×
/// (c − a), where p projects inside the triangle, else the least squared distance to its
/// three edges (Ericson, *Real-Time Collision Detection*, §5.1.2 and §5.1.5).
#[inline(always)]
fn distance_squared_lanes<const L: usize>(
    p: &[[f64; L]; 3],
    corners: &[[[f64; L]; 3]; 3],
) -> [f64; L] {
    let mut out = [0.0; L];
    for l in 0..L {
        let at = |c: usize| [corners[c][0][l], corners[c][1][l], corners[c][2][l]];
        let (a, b, c) = (at(0), at(1), at(2));
        let x = [p[0][l], p[1][l], p[2][l]];
        let (e1, e2, d) = (sub(b, a), sub(c, a), sub(x, a));
        let m = cross(e1, e2);
        let m2 = dot(m, m);
        let beta = dot(cross(e2, m), d);
        let gamma = dot(cross(m, e1), d);
        let hm = dot(m, d);
        let inside = (beta >= 0.0) & (gamma >= 0.0) & (beta + gamma <= m2) & (m2 > 0.0);
        // Squared distance to segment from q along e.
        let segment = |q: [f64; 3], e: [f64; 3]| {
            let w = sub(x, q);
            let ee = dot(e, e);
            let t = if ee > 0.0 {
                (dot(w, e) / ee).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let r = [w[0] - t * e[0], w[1] - t * e[1], w[2] - t * e[2]];
            dot(r, r)
        };
        let edges = segment(a, e1)
            .min(segment(b, sub(c, b)))
            .min(segment(c, sub(a, c)));
        out[l] = if inside { hm * hm / m2 } else { edges };
    }
    out
}

#[cfg(test)]
#[path = "list_run_tests.rs"]
mod tests;
