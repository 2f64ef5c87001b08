//! A still mesh's contacts on its grid for a run of particles side by side: each particle's
//! first test, against the triangle it touched last, a block of particles at a time (eight
//! on the AVX-512 path, four on AVX2) in explicit vectors (`grid_lanes`). A particle that
//! the triangle settles (clear of the mesh, or pushed out of its face) is done here; the
//! others go on to the walk and the cell of `grid_contacts`, particle by particle. The
//! one-particle path starts with the same test ([`first_test`] with one lane), so the bits do
//! not depend on where a particle falls in a block.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::Simd;
use weft_solver::lane_ops::{LaneKernel, Ops, V3, load, load_at, on_path, store};
use weft_solver::{Contacts, ParticleRun};

use super::candidates::MeshFrame;
use super::contact_grid::ContactGrid;
use super::grid_contacts::GridParticles;
use super::grid_lanes::{Lanes, Verdict, gather, local, settle, world};

/// What the first test reads of one triangle, in f64, two cache lines: a corner, the unit
/// normal, the in-plane dual basis of the edges (barycentric coordinates β = u · (x − a),
/// γ = v · (x − a) of x's projection) and the clearance, as one array so that a block reads
/// each field of its lanes' triangles together.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct FaceCert(pub(super) [f64; 16]);

/// Where each field of a [`FaceCert`] starts: corner a, unit normal n, the dual vectors u and
/// v (each three axes), then the clearance.
pub(super) const A: usize = 0;
pub(super) const N: usize = 3;
pub(super) const U: usize = 6;
pub(super) const V: usize = 9;
pub(super) const CLEAR: usize = 12;
/// Fields a block gathers.
pub(super) const FIELDS: usize = 13;

/// Projections nearer than this (barycentric) to an edge are left to the walk.
pub(super) const INSIDE: f64 = 1e-9;

impl FaceCert {
    /// The record of a triangle that settles nothing: every particle goes on to the walk.
    pub const NONE: Self = {
        let mut f = [0.0; 16];
        f[CLEAR] = -1.0;
        Self(f)
    };

    /// The record of the triangle with `corners`, unit `normal` and `clearance`: with
    /// e₁ = b − a, e₂ = c − a and m = e₁ × e₂, u = (e₂ × m) / |m|² and v = (m × e₁) / |m|²
    /// (so u · e₁ = v · e₂ = 1, u · e₂ = v · e₁ = 0, both in the plane). A degenerate triangle,
    /// or one so thin that rounding of β and γ at the clearance's reach could pass 10⁻¹²,
    /// settles nothing.
    pub fn new(corners: [DVec3; 3], normal: DVec3, clearance: f64) -> Self {
        let [a, b, c] = corners;
        let (e1, e2) = (b - a, c - a);
        let m = e1.cross(e2);
        let m2 = m.length_squared();
        if normal == DVec3::ZERO || m2.is_nan() || m2 <= 0.0 {
            return Self::NONE;
        }
        let (u, v) = (e2.cross(m) / m2, m.cross(e1) / m2);
        let reach = (u.length() + v.length()) * (clearance.max(0.0) + e1.length() + e2.length());
        if reach.is_nan() || reach >= 1e3 {
            return Self::NONE;
        }
        let mut f = [0.0; 16];
        for (at, w) in [(A, a), (N, normal), (U, u), (V, v)] {
            f[at..at + 3].copy_from_slice(&w.to_array());
        }
        f[CLEAR] = clearance;
        Self(f)
    }
}

/// A still mesh's pose as a block reads it: the world's frame, or a basis B (columns) and a
/// translation t, local = Bᵀ (x − t).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placement {
    /// Whether the pose is the world's frame.
    pub(super) identity: bool,
    /// B's columns.
    pub(super) basis: [[f64; 3]; 3],
    /// t.
    pub(super) shift: [f64; 3],
}

impl Placement {
    /// `frame`'s pose (its end pose; the mesh is still over the substep).
    pub fn of(frame: &MeshFrame<'_>) -> Self {
        let b = frame.pose.basis;
        Self {
            identity: frame.identity,
            basis: [b.x_axis, b.y_axis, b.z_axis].map(|c| c.to_array()),
            shift: frame.pose.translation.to_array(),
        }
    }
}

/// What the first test did with a lane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Settled {
    /// Not settled: the walk and the cell follow, from the particle as it was.
    #[default]
    Open,
    /// Clear, or pushed out of the face with room to spare: nothing more to do.
    Done,
    /// Pushed out of the face, then slipped far enough that the cell must be scanned.
    Rounds,
}

/// A block after its first test: positions in the world's frame and the mesh's, path starts
/// (mesh's frame) and what the test did per lane.
pub(crate) struct Tested<const L: usize> {
    /// Positions in the world's frame (moved where pushed).
    pub world: [[f64; L]; 3],
    /// Positions in the mesh's frame.
    pub local: [[f64; L]; 3],
    /// Path starts in the mesh's frame.
    pub from: [[f64; L]; 3],
    /// What the test did per lane.
    pub verdict: Verdict<L>,
}

impl<const L: usize> Tested<L> {
    /// Lane `l`'s position in the world's frame.
    #[inline(always)]
    pub fn world_at(&self, l: usize) -> DVec3 {
        DVec3::new(self.world[0][l], self.world[1][l], self.world[2][l])
    }

    /// Lane `l`'s position in the mesh's frame.
    #[inline(always)]
    pub fn local_at(&self, l: usize) -> DVec3 {
        DVec3::new(self.local[0][l], self.local[1][l], self.local[2][l])
    }

    /// Lane `l`'s path start in the mesh's frame.
    #[inline(always)]
    pub fn path_start(&self, l: usize) -> DVec3 {
        DVec3::new(self.from[0][l], self.from[1][l], self.from[2][l])
    }
}

/// The first test of particles `i0 .. i0 + L` (global indices, `L` the f64 lanes of `S`) at
/// world positions `wx`, at `wp` at the substep's start, thickness `r`, taking part where
/// `live`, against the triangles they touched last, with the mesh of `frame` still over the
/// substep ([`settle`]). A block whose every live path lies in its clear ball reads no
/// triangle. The block path and the one-particle path test alike through this.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn first_test<S: Simd, const L: usize>(
    o: Ops<S>,
    frame: &MeshFrame<'_>,
    (certs, state): (&[FaceCert], &GridParticles),
    place: &Placement,
    (wx, wp): (&V3<S>, &V3<S>),
    r: S::f64s,
    live: S::m64s,
    i0: usize,
) -> Tested<L> {
    debug_assert_eq!(L, S::F64_LANES);
    let x = local(o, place, wx);
    let prev = local(o, place, wp);
    let from = if frame.fresh {
        prev
    } else {
        let last: [DVec3; L] = std::array::from_fn(|l| state.last(i0 + l));
        std::array::from_fn(|k| load::<S, L>(last.map(|p| p[k])))
    };
    let balls: [(DVec3, f64); L] = std::array::from_fn(|l| state.ball(i0 + l));
    let t: [usize; L] = std::array::from_fn(|l| state.hint(i0 + l) as usize);
    let mut b = Lanes::<S> {
        x,
        from,
        prev,
        r,
        live,
        anchor: std::array::from_fn(|k| load::<S, L>(balls.map(|(c, _)| c[k]))),
        ball: load::<S, L>(balls.map(|(_, radius)| radius)),
    };
    let in_ball = b.in_ball(o);
    let (verdict, moved) = if o.any(o.and(live, o.not(in_ball))) {
        let f = gather::<S, L>(certs, t);
        let (verdict, push) = settle::<S, L>(o, &mut b, in_ball, &f, frame.friction);
        let moved = if o.any(push) {
            world(o, place, wx, &x, &b.x, push)
        } else {
            *wx
        };
        (verdict, moved)
    } else {
        // Nothing within r of any path: no triangle to read.
        let settled = o
            .bits::<L>(live)
            .map(|l| if l { Settled::Done } else { Settled::Open });
        let verdict = Verdict {
            settled,
            new_ball: [f64::NAN; L],
            contacts: Contacts::default(),
        };
        (verdict, *wx)
    };
    Tested {
        world: moved.map(store::<S, L>),
        local: b.x.map(store::<S, L>),
        from: b.from.map(store::<S, L>),
        verdict,
    }
}

/// Every free particle of `run` against the mesh of `frame`, still over the substep, on
/// `grid`: [`first_test`] a block at a time, each lane taken into the mesh's frame and back,
/// then each particle it left open through `MeshFrame::resolve_in_grid`'s walk, in order.
/// Compiled for the run's kernel path (every path gives the same bits).
pub(crate) fn resolve_grid_run(
    frame: &MeshFrame<'_>,
    grid: (&ContactGrid, &GridParticles),
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    on_path(
        run.path,
        Blocks {
            frame,
            grid,
            r,
            run,
        },
    )
}

/// [`resolve_grid_run`]'s arguments, a [`LaneKernel`] run on the vectors of whatever [`Simd`]
/// [`on_path`] hands it.
struct Blocks<'f, 'a, 'r, 'c> {
    frame: &'f MeshFrame<'a>,
    grid: (&'f ContactGrid, &'f GridParticles),
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
        grid: (grid, state),
        r,
        run,
    } = b;
    let start = run.start;
    let n = run.w.len();
    let w = run.w;
    let prev = [&run.prev[0][..n], &run.prev[1][..n], &run.prev[2][..n]];
    let r = &r[..n];
    let [x0, x1, x2] = &mut run.x;
    let x = [&mut x0[..n], &mut x1[..n], &mut x2[..n]];
    let certs = grid.certs();
    let mut total = Contacts::default();
    let full = n - n % L;
    let place = Placement::of(frame);
    for s in (0..full).step_by(L) {
        let wx: V3<S> = std::array::from_fn(|k| load_at::<S, L>(x[k], s));
        let wp: V3<S> = std::array::from_fn(|k| load_at::<S, L>(prev[k], s));
        let wb = load_at::<S, L>(w, s);
        let live = o.not(o.eq(wb, o.c(0.0)));
        let rb = load_at::<S, L>(r, s);
        let tested = first_test::<S, L>(
            o,
            frame,
            (certs, state),
            &place,
            (&wx, &wp),
            rb,
            live,
            start + s,
        );
        total = total.merge(tested.verdict.contacts);
        // The block's own pushes (the other lanes' positions as they were), then the lanes it
        // left to the walk and the cell, one by one (in the world's frame).
        for k in 0..3 {
            x[k][s..s + L].copy_from_slice(&tested.world[k]);
        }
        for l in 0..L {
            let i = start + s + l;
            let out = match tested.verdict.settled[l] {
                Settled::Done => {
                    let ball = tested.verdict.new_ball[l];
                    frame.settled_in_grid(state, i, tested.local_at(l), ball);
                    continue;
                }
                Settled::Open if w[s + l] == 0.0 => continue,
                settled => {
                    let mut p = tested.world_at(l);
                    let start_pos = DVec3::new(prev[0][s + l], prev[1][s + l], prev[2][s + l]);
                    let out = if settled == Settled::Rounds {
                        frame.rounds_after_settle(
                            (grid, state),
                            i,
                            start_pos,
                            (&mut p, tested.local_at(l)),
                            tested.path_start(l),
                            r[s + l],
                        )
                    } else {
                        frame.walk_in_grid((grid, state), i, start_pos, &mut p, r[s + l])
                    };
                    for k in 0..3 {
                        x[k][s + l] = p[k];
                    }
                    out
                }
            };
            total = total.merge(out.into());
        }
    }
    for j in full..n {
        if w[j] == 0.0 {
            continue;
        }
        let mut p = DVec3::new(x[0][j], x[1][j], x[2][j]);
        let before = DVec3::new(prev[0][j], prev[1][j], prev[2][j]);
        let out = frame.resolve_in_grid((grid, state), start + j, before, &mut p, r[j]);
        for k in 0..3 {
            x[k][j] = p[k];
        }
        total = total.merge(out.into());
    }
    total
}

#[cfg(test)]
#[path = "grid_run_tests.rs"]
mod tests;
