//! A still mesh's contacts on its grid for a run of particles side by side: each particle's
//! first test, against the triangle it touched last, a block of [`LANES`] particles at a
//! time in struct-of-arrays, every branch a select. A particle that the triangle settles
//! (clear of the mesh, or pushed out of its face) is done here; the others go on to the walk
//! and the cell of `grid_contacts`, particle by particle. The one-particle path starts with
//! the same test ([`settle`] with one lane), so the bits do not depend on where a particle
//! falls in a block.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use multiversion::multiversion;
use weft_solver::{Contacts, ParticleRun, SimdPath};

use super::candidates::MeshFrame;
use super::contact_grid::ContactGrid;
use super::grid_contacts::GridParticles;
use crate::friction::{Friction, push_lanes};

/// Particles per block: eight f64, one AVX-512 register or two AVX2 ones.
const LANES: usize = 8;

/// What the first test reads of one triangle, in f64, two cache lines: a corner, the unit
/// normal, the in-plane dual basis of the edges (barycentric coordinates β = u · (x − a),
/// γ = v · (x − a) of x's projection) and the clearance, as one array so that a block reads
/// each field of its lanes' triangles together.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct FaceCert([f64; 16]);

/// Where each field of a [`FaceCert`] starts: corner a, unit normal n, the dual vectors u and
/// v (each three axes), then the clearance.
const A: usize = 0;
const N: usize = 3;
const U: usize = 6;
const V: usize = 9;
const CLEAR: usize = 12;
/// Fields a block gathers.
const FIELDS: usize = 13;

/// Projections nearer than this (barycentric) to an edge are left to the walk.
const INSIDE: f64 = 1e-9;

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
    identity: bool,
    basis: [[f64; 3]; 3],
    shift: [f64; 3],
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

    /// The lanes' world positions `w` in the mesh's frame.
    #[inline(always)]
    pub fn local<const L: usize>(&self, w: &[[f64; L]; 3]) -> [[f64; L]; 3] {
        if self.identity {
            return *w;
        }
        let mut out = [[0.0; L]; 3];
        for l in 0..L {
            let d = [0, 1, 2].map(|a| w[a][l] - self.shift[a]);
            for k in 0..3 {
                let c = &self.basis[k];
                out[k][l] = c[0] * d[0] + c[1] * d[1] + c[2] * d[2];
            }
        }
        out
    }

    /// World positions `w` of lanes the block moved from `old` to `new` in the mesh's frame
    /// (lanes `moved` false keep theirs): w + B (new − old), or `new` in the world's frame.
    #[inline(always)]
    pub fn world<const L: usize>(
        &self,
        w: &[[f64; L]; 3],
        old: &[[f64; L]; 3],
        new: &[[f64; L]; 3],
        moved: &[bool; L],
    ) -> [[f64; L]; 3] {
        let mut out = *w;
        for l in 0..L {
            let d = [0, 1, 2].map(|k| new[k][l] - old[k][l]);
            for a in 0..3 {
                let shifted = if self.identity {
                    new[a][l]
                } else {
                    let b = &self.basis;
                    w[a][l] + (b[0][a] * d[0] + b[1][a] * d[1] + b[2][a] * d[2])
                };
                out[a][l] = if moved[l] { shifted } else { w[a][l] };
            }
        }
        out
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

/// A block of `L` particles and the triangles they touched last, struct-of-arrays.
pub(crate) struct Block<const L: usize> {
    /// Positions in the mesh's frame, moved in place.
    pub x: [[f64; L]; 3],
    /// Where each path starts: the substep's start, or the last projection.
    pub from: [[f64; L]; 3],
    /// Positions at the substep's start, in the mesh's frame.
    pub prev: [[f64; L]; 3],
    /// Thickness (m).
    pub r: [f64; L],
    /// Whether the lane takes part (a free particle).
    pub live: [bool; L],
    /// Where each particle's clear ball is centred (`GridParticles::ball`).
    pub anchor: [[f64; L]; 3],
    /// Its radius; NaN where there is none.
    pub ball: [f64; L],
    /// Whether the block moved the lane.
    pub pushed: [bool; L],
    /// A new clear ball about the lane's position, where the triangle's test cleared it
    /// outside its ball: the radius, or NaN.
    pub new_ball: [f64; L],

    /// The lanes' triangles, gathered per field ([`FaceCert`]'s order).
    f: [[f64; L]; FIELDS],
}

impl<const L: usize> Block<L> {
    /// An empty block: no lane takes part.
    pub fn new() -> Self {
        Self {
            x: [[0.0; L]; 3],
            from: [[0.0; L]; 3],
            prev: [[0.0; L]; 3],
            r: [0.0; L],
            live: [false; L],
            anchor: [[0.0; L]; 3],
            ball: [f64::NAN; L],
            pushed: [false; L],
            new_ball: [f64::NAN; L],
            f: std::array::from_fn(|k| [FaceCert::NONE.0[k]; L]),
        }
    }

    /// Gives lane `l` the triangle record `f`.
    #[inline(always)]
    pub fn gather(&mut self, l: usize, f: &FaceCert) {
        for k in 0..FIELDS {
            self.f[k][l] = f.0[k];
        }
    }

    /// Gives each lane l the record `certs[t[l]]`, or the last record where t[l] is past it
    /// (the grid keeps [`FaceCert::NONE`] there), field by field.
    #[inline(always)]
    pub fn gather_all(&mut self, certs: &[FaceCert], t: [usize; L]) {
        let Some(last) = certs.len().checked_sub(1) else {
            for l in 0..L {
                self.gather(l, &FaceCert::NONE);
            }
            return;
        };
        let at: [&FaceCert; L] = std::array::from_fn(|l| &certs[t[l].min(last)]);
        // Each field's lanes built as one value, then stored whole (scalar stores read back
        // as a vector stall the load).
        for k in 0..FIELDS {
            self.f[k] = std::array::from_fn(|l| at[l].0[k]);
        }
    }
}

impl<const L: usize> Block<L> {
    /// Whether each lane's path lies in its clear ball (NaN radius: none does).
    #[inline(always)]
    pub fn in_ball(&self) -> [bool; L] {
        std::array::from_fn(|l| {
            let (ball, o) = (self.ball[l], [0, 1, 2].map(|k| self.anchor[k][l]));
            let q = [0, 1, 2].map(|k| self.x[k][l] - o[k]);
            let e = [0, 1, 2].map(|k| self.from[k][l] - o[k]);
            (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= ball * ball)
                & (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] <= ball * ball)
        })
    }
}

/// The first test of every live lane against its triangle, with the mesh still over the
/// substep (positions in its frame); moves the lanes it pushes, and returns what it did per lane with the
/// contacts made. A lane is settled where its path lies in its clear ball (no point of the
/// ball is within r of the mesh, so neither a contact nor a crossing), or where its path is
/// shorter than r/2 (so no sweep is due) and either
///
/// - it is r or more in front of the plane and near enough to corner a that every triangle
///   in front of the plane is beyond r (`ContactGrid::clearance`): clear; or
/// - its projection lies inside the face, in front, with d + r (d the distance, at least r)
///   within the clearance: the face is nearest of all within r, and a particle nearer than r
///   is pushed along the normal to r, then slid back by Coulomb friction against the still
///   surface (Macklin et al. 2014, eq. 24; `Friction::correction`). If the slip may have
///   carried it past the clearance, the cell is scanned next ([`Settled::Rounds`]).
#[inline(always)]
pub(crate) fn settle<const L: usize>(
    b: &mut Block<L>,
    friction: Friction,
    out: &mut [Settled; L],
) -> Contacts {
    let mut s = [0.0; L];
    let mut clear = [false; L];
    let mut settled = [false; L];
    // How far past r from the mesh the triangle's test proves each lane to be.
    let mut spare = [0.0; L];
    let in_ball = b.in_ball();
    for l in 0..L {
        let p = [
            b.x[0][l] - b.from[0][l],
            b.x[1][l] - b.from[1][l],
            b.x[2][l] - b.from[2][l],
        ];
        let half = 0.5 * b.r[l];
        let short = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= half * half;
        let f = |k: usize| b.f[k][l];
        let v = [b.x[0][l] - f(A), b.x[1][l] - f(A + 1), b.x[2][l] - f(A + 2)];
        let dot = |at: usize| f(at) * v[0] + f(at + 1) * v[1] + f(at + 2) * v[2];
        let h = dot(N);
        let to_a = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let r = b.r[l];
        let room = f(CLEAR) - r;
        let (beta, gamma) = (dot(U), dot(V));
        let inside = (beta > INSIDE) & (gamma > INSIDE) & (beta + gamma < 1.0 - INSIDE);
        let live = b.live[l] & short;
        s[l] = h;
        clear[l] =
            (b.live[l] & in_ball[l]) | (live & (h >= r) & (room >= 0.0) & (to_a <= room * room));
        settled[l] = live & inside & (h > 1e-12) & (h.max(r) + r <= f(CLEAR));
        // Triangles behind the plane are h or more away, those in front the clearance less
        // the distance to this triangle (h over the face, at most |x − a| anywhere).
        let near = if inside { h } else { to_a.sqrt() };
        spare[l] = h.min(f(CLEAR) - near) - r;
    }
    let mut depth = [0.0; L];
    let mut push = [false; L];
    for l in 0..L {
        depth[l] = b.r[l] - s[l];
        push[l] = settled[l] & !clear[l] & (depth[l] > 1e-6 * b.r[l].max(1e-3));
        out[l] = if clear[l] | settled[l] {
            Settled::Done
        } else {
            Settled::Open
        };
        // A clear ball about a lane the triangle cleared outside its ball: no triangle is
        // within r of any point within `spare` of it.
        let fresh = (clear[l] | settled[l]) & !push[l] & !in_ball[l] & (spare[l] > 0.0);
        b.new_ball[l] = if fresh {
            spare[l] * (1.0 - 1e-9)
        } else {
            f64::NAN
        };
    }
    b.pushed = push;
    if !push.contains(&true) {
        return Contacts::default();
    }
    // Pushed out along the normal, then friction on the slip since the substep's start.
    let normal = [&b.f[N], &b.f[N + 1], &b.f[N + 2]];
    let (moved, slip2) = push_lanes(friction, &b.x, &b.prev, normal, &depth, &push);
    b.x = moved;
    let mut tally = Contacts::default();
    for l in 0..L {
        if push[l] {
            // Pushed to r off the face, then slipped across its normal: still clear of the
            // triangles in front if within the clearance less r.
            let room = b.f[CLEAR][l] - 2.0 * b.r[l];
            if slip2[l] > room * room {
                out[l] = Settled::Rounds;
            }
            tally.contacts += 1;
            tally.depth = tally.depth.max(depth[l]);
        }
    }
    tally
}

/// Every free particle of `run` against the mesh of `frame`, still over the substep, on
/// `grid`: [`settle`] a block at a time, each lane taken into the mesh's frame and back, then each particle it left open through
/// `MeshFrame::resolve_in_grid`'s walk, in order. Compiled for the run's kernel path (every
/// path gives the same bits).
pub(crate) fn resolve_grid_run(
    frame: &MeshFrame<'_>,
    grid: (&ContactGrid, &GridParticles),
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    match run.path {
        SimdPath::Avx512 => run_avx512(frame, grid, r, run),
        SimdPath::Avx2 => run_avx2(frame, grid, r, run),
        SimdPath::Neon => run_neon(frame, grid, r, run),
        SimdPath::Scalar => run_scalar(frame, grid, r, run),
    }
}

/// [`resolve_grid_run`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn run_avx512<'a, 'b, 'c>(
    frame: &'b MeshFrame<'a>,
    grid: (&'b ContactGrid, &'b GridParticles),
    r: &'b [f64],
    run: &'b mut ParticleRun<'c>,
) -> Contacts {
    run_body(frame, grid, r, run)
}

/// [`resolve_grid_run`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn run_avx2<'a, 'b, 'c>(
    frame: &'b MeshFrame<'a>,
    grid: (&'b ContactGrid, &'b GridParticles),
    r: &'b [f64],
    run: &'b mut ParticleRun<'c>,
) -> Contacts {
    run_body(frame, grid, r, run)
}

/// [`resolve_grid_run`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn run_neon<'a, 'b, 'c>(
    frame: &'b MeshFrame<'a>,
    grid: (&'b ContactGrid, &'b GridParticles),
    r: &'b [f64],
    run: &'b mut ParticleRun<'c>,
) -> Contacts {
    run_body(frame, grid, r, run)
}

/// [`resolve_grid_run`] compiled for the baseline target.
#[inline(never)]
fn run_scalar<'a, 'b, 'c>(
    frame: &'b MeshFrame<'a>,
    grid: (&'b ContactGrid, &'b GridParticles),
    r: &'b [f64],
    run: &'b mut ParticleRun<'c>,
) -> Contacts {
    run_body(frame, grid, r, run)
}

#[inline(always)]
fn run_body(
    frame: &MeshFrame<'_>,
    (grid, state): (&ContactGrid, &GridParticles),
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    let start = run.start;
    let n = run.w.len();
    let w = run.w;
    let prev = [&run.prev[0][..n], &run.prev[1][..n], &run.prev[2][..n]];
    let r = &r[..n];
    let [x0, x1, x2] = &mut run.x;
    let x = [&mut x0[..n], &mut x1[..n], &mut x2[..n]];
    let certs = grid.certs();
    let friction = frame.friction;
    let mut total = Contacts::default();
    let full = n - n % LANES;
    let mut b = Block::<LANES>::new();
    let mut settled = [Settled::Open; LANES];
    let place = Placement::of(frame);
    let (mut wx, mut wp) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3]);
    for s in (0..full).step_by(LANES) {
        for k in 0..3 {
            wx[k].copy_from_slice(&x[k][s..s + LANES]);
            wp[k].copy_from_slice(&prev[k][s..s + LANES]);
        }
        let (mut live, mut rb) = ([false; LANES], [0.0; LANES]);
        for l in 0..LANES {
            live[l] = w[s + l] != 0.0;
        }
        rb.copy_from_slice(&r[s..s + LANES]);
        let t = b.load(frame, state, &place, (&wx, &wp), (&rb, live), start + s);
        let in_ball = b.in_ball();
        if (0..LANES).all(|l| in_ball[l] | !b.live[l]) {
            // Nothing within r of any path: no triangle to read.
            for l in 0..LANES {
                if b.live[l] {
                    frame.settled_in_grid(state, start + s + l, b.at(l), f64::NAN);
                }
            }
            continue;
        }
        b.gather_all(certs, t);
        let before = b.x;
        total = total.merge(settle(&mut b, friction, &mut settled));
        // The block's own pushes (the other lanes' positions as they were), then the lanes it
        // left to the walk and the cell, one by one (in the world's frame).
        let moved = place.world(&wx, &before, &b.x, &b.pushed);
        for k in 0..3 {
            x[k][s..s + LANES].copy_from_slice(&moved[k]);
        }
        for l in 0..LANES {
            let i = start + s + l;
            let mut p = DVec3::new(moved[0][l], moved[1][l], moved[2][l]);
            let start_pos = DVec3::new(wp[0][l], wp[1][l], wp[2][l]);
            let out = match settled[l] {
                Settled::Done => {
                    frame.settled_in_grid(state, i, b.at(l), b.new_ball[l]);
                    continue;
                }
                Settled::Rounds => frame.rounds_after_settle(
                    (grid, state),
                    i,
                    start_pos,
                    (&mut p, b.at(l)),
                    b.start_at(l),
                    b.r[l],
                ),
                Settled::Open if w[s + l] == 0.0 => continue,
                Settled::Open => frame.walk_in_grid((grid, state), i, start_pos, &mut p, b.r[l]),
            };
            for k in 0..3 {
                x[k][s + l] = p[k];
            }
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

impl<const L: usize> Block<L> {
    /// Loads the lanes of particles `i0 .. i0 + L` (global indices) at world positions `wx`,
    /// `wp` at the substep's start, thickness `r`, taking part where `live`: positions and path
    /// starts in the mesh's frame (the substep's start and end poses are the same), clear
    /// balls. Returns the triangles they touched last. The block path and the one-particle
    /// path load alike through this.
    #[inline(always)]
    pub fn load(
        &mut self,
        frame: &MeshFrame<'_>,
        state: &GridParticles,
        place: &Placement,
        (wx, wp): (&[[f64; L]; 3], &[[f64; L]; 3]),
        (r, live): (&[f64; L], [bool; L]),
        i0: usize,
    ) -> [usize; L] {
        self.x = place.local(wx);
        self.prev = place.local(wp);
        self.r = *r;
        self.live = live;
        if frame.fresh {
            self.from = self.prev;
        }
        let mut t = [0usize; L];
        for l in 0..L {
            let i = i0 + l;
            if !frame.fresh {
                let from = state.last(i);
                for k in 0..3 {
                    self.from[k][l] = from[k];
                }
            }
            let (anchor, ball) = state.ball(i);
            for k in 0..3 {
                self.anchor[k][l] = anchor[k];
            }
            self.ball[l] = ball;
            t[l] = state.hint(i) as usize;
        }
        t
    }

    /// Lane `l`'s position.
    #[inline(always)]
    fn at(&self, l: usize) -> DVec3 {
        DVec3::new(self.x[0][l], self.x[1][l], self.x[2][l])
    }

    /// Lane `l`'s path start.
    #[inline(always)]
    fn start_at(&self, l: usize) -> DVec3 {
        DVec3::new(self.from[0][l], self.from[1][l], self.from[2][l])
    }
}

#[cfg(test)]
#[path = "grid_run_tests.rs"]
mod tests;
