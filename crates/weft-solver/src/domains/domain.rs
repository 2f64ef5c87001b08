//! One domain: its particles as struct-of-arrays, the fused integration and the velocity update.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::ops::Range;

use glam::DVec3;
use multiversion::multiversion;

use super::layout::Chunk;
use crate::air::still_air;
use crate::forces::Forces;
use crate::hook::{Contacts, ParticleContacts, ParticleRun};
use crate::settings::within_bound;
use weft_simd::SimdPath;

/// Distance constraints as struct-of-arrays; rest lengths and multipliers in f32, the lane
/// type of the domain sweep (see `sweep`).
#[derive(Clone, Debug, Default)]
pub(super) struct Pairs {
    /// First end (local index).
    pub p: Vec<u32>,
    /// Second end (local index).
    pub q: Vec<u32>,
    /// Rest length (m), rounded to f32.
    pub rest: Vec<f32>,
    /// Parameter group.
    pub group: Vec<u32>,
    /// XPBD multiplier (a chunk's dead lane, see `Chunk::live`, has an entry whose multiplier
    /// means nothing).
    pub lambda: Vec<f32>,
}

impl Pairs {
    pub(super) fn push(&mut self, p: u32, q: u32, rest: f64, group: u32) {
        self.push_f32(p, q, rest as f32, group);
    }

    /// Appends an entry with its rest length already in f32.
    pub(super) fn push_f32(&mut self, p: u32, q: u32, rest: f32, group: u32) {
        self.p.push(p);
        self.q.push(q);
        self.rest.push(rest);
        self.group.push(group);
        self.lambda.push(0.0);
    }
}

/// One domain: its particles (struct-of-arrays, local indices) and interior constraints.
#[derive(Clone, Debug, Default)]
pub(crate) struct Domain {
    /// Global index of the first particle.
    pub(super) start: usize,
    /// Positions per axis (m).
    pub(super) x: [Vec<f64>; 3],
    /// Positions at the start of the substep per axis (m).
    pub(super) prev: [Vec<f64>; 3],
    /// Inverse masses (1/kg).
    pub(super) w: Vec<f64>,
    /// Local indices of the particles with no inverse mass (pinned or fixed), in order: after
    /// the first substep the integration predicts every particle alike and then puts these
    /// back where they were.
    pub(super) fixed: Vec<u32>,
    /// The sweep's working state (see [`Rebased`]).
    pub(super) work: Rebased,
    /// Interior constraints in local indices, sorted by colour, group and particle.
    pub(super) pairs: Pairs,
    /// Range of each colour in `pairs`.
    pub(super) colours: Vec<Range<usize>>,
    /// Full chunks of every colour, in order.
    pub(super) chunks: Vec<Chunk>,
    /// For each colour: its range in `chunks` and where its scalar remainder starts.
    pub(super) plan: Vec<(Range<usize>, usize)>,
    /// The kernel path its sweep and integration run on.
    pub(super) path: SimdPath,
    /// Local index ranges covering every end of a link (constraints to other domains), in
    /// order: the links read positions that must have their sweep's displacement added.
    pub(super) linked: Vec<Range<usize>>,
}

/// A domain's positions as the sweep sees them, in f32: each particle at `base + disp`
/// relative to the domain's origin (its first particle's position at the substep's start for
/// the substep's first sweep, written by the fused integration as it predicts; its position
/// when a later sweep starts). `base` is rounded once per sweep and never changes during it;
/// the sweep's corrections accumulate in `disp`, small numbers kept to f32's relative
/// precision, and are added to the f64 positions by the next pass that reads them (see
/// `unfolded`). So f32 rounding moves where a constraint is evaluated by at most half an ulp
/// of the particle's distance from the origin, but never the f64 state the integration reads
/// (f32 positions would bias XPBD's equilibrium: see the README).
#[derive(Clone, Debug, Default)]
pub(super) struct Rebased {
    /// Position at the sweep's start relative to the origin, per axis, rounded to f32.
    pub base: [Vec<f32>; 3],
    /// Displacement accumulated by the sweep, per axis.
    pub disp: [Vec<f32>; 3],
    /// x − x_prev at the sweep's start, per axis (filled only for damped sweeps).
    pub motion: [Vec<f32>; 3],
    /// Inverse masses rounded to f32 (converted wherever the domain's inverse masses are set).
    pub w: Vec<f32>,
    /// The origin `base` is relative to, per axis (m): the first particle's position at the
    /// substep's start for the substep's first sweep, its current position for later ones.
    pub origin: [f64; 3],
    /// The origin the next rebase takes, when the caller knows the substep's start (the
    /// general loop's first sweep of a substep), so that it rounds as the fused integration
    /// does.
    pub next_origin: Option<[f64; 3]>,
    /// `base` holds the positions and `disp` is zero: the fused integration rebased them while
    /// it predicted, so the sweep that follows starts without a pass of its own.
    pub fresh: bool,
    /// `disp` holds a finished sweep's displacement not yet added to the f64 positions: the
    /// next reader of the positions adds it first (the integration in its own pass, anything
    /// else through [`Domain::settle`]), so a sweep ends without a pass of its own. The ends
    /// of links are the exception, settled as the sweep ends ([`Domain::settle_linked`]).
    pub unfolded: bool,
}

impl Rebased {
    /// Rounds the inverse masses `w` for the sweep.
    pub(super) fn set_masses(&mut self, w: &[f64]) {
        for (w32, &w) in self.w.iter_mut().zip(w) {
            *w32 = w as f32;
        }
    }
}

/// A domain's share of the global particle arrays.
pub(crate) struct AosChunk<'a> {
    /// Positions.
    pub x: &'a [DVec3],
    /// Velocities.
    pub v: &'a [DVec3],
    /// Inverse masses.
    pub w: &'a [f64],
}

/// Per-substep inputs of the fused integration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Integration<'a> {
    /// Substep length (s).
    pub h: f64,
    /// External forces (gravity and linear wind drag; no aerodynamics).
    pub forces: &'a Forces,
    /// Kinematic pins as (global particle, position at the substep's end).
    pub pins: &'a [(usize, DVec3)],
}

impl Domain {
    pub(super) fn len(&self) -> usize {
        self.w.len()
    }

    pub(super) fn resize(&mut self, n: usize) {
        for a in 0..3 {
            self.x[a].resize(n, 0.0);
            self.prev[a].resize(n, 0.0);
            self.work.base[a].resize(n, 0.0);
            self.work.disp[a].resize(n, 0.0);
            self.work.motion[a].resize(n, 0.0);
        }
        self.w.resize(n, 0.0);
        self.work.w.resize(n, 0.0);
    }

    /// Copies positions (and, when `prev` is given, previous positions) in.
    pub(super) fn load_positions(&mut self, x: &[DVec3], prev: Option<&[DVec3]>, w: &[f64]) {
        for (i, p) in x.iter().enumerate() {
            for a in 0..3 {
                self.x[a][i] = p[a];
            }
        }
        if let Some(prev) = prev {
            for (i, p) in prev.iter().enumerate() {
                for a in 0..3 {
                    self.prev[a][i] = p[a];
                }
            }
        }
        self.w.copy_from_slice(w);
        self.work.set_masses(w);
        self.note_fixed();
        self.work.fresh = false;
        self.work.unfolded = false;
    }

    /// Lists the particles with no inverse mass ([`Self::fixed`]).
    fn note_fixed(&mut self) {
        self.fixed.clear();
        // Not free exactly where the integration's `w > 0` test fails (NaN included).
        let free = |w: f64| w > 0.0;
        let fixed = self.w.iter().enumerate().filter(|&(_, &w)| !free(w));
        self.fixed.extend(fixed.map(|(i, _)| i as u32));
    }

    /// Adds the last sweep's displacement to the f64 positions if it is still pending (each
    /// f32 widens exactly; the sum rounds in f64 like any position update).
    pub(super) fn settle(&mut self) {
        if !std::mem::take(&mut self.work.unfolded) {
            return;
        }
        self.fold(0..self.len());
    }

    /// [`Self::settle`] for the ends of links alone (see `linked`), as a sweep ends: their
    /// displacement becomes −0, which adds to any position exactly, so the later settle leaves
    /// their bits as the links wrote them.
    #[inline(always)]
    pub(super) fn settle_linked(&mut self) {
        for k in 0..self.linked.len() {
            let r = self.linked[k].clone();
            self.fold(r.clone());
            for d in &mut self.work.disp {
                d[r.clone()].fill(-0.0);
            }
        }
    }

    /// Adds the displacement of particles `r` to their f64 positions.
    #[inline(always)]
    fn fold(&mut self, r: Range<usize>) {
        for a in 0..3 {
            let (x, d) = (&mut self.x[a][r.clone()], &self.work.disp[a][r.clone()]);
            for (x, &d) in x.iter_mut().zip(d) {
                *x += f64::from(d);
            }
        }
    }

    /// Copies positions back out (after [`Self::settle`]).
    pub(super) fn store_positions(&self, x: &mut [DVec3]) {
        debug_assert!(!self.work.unfolded);
        for (i, p) in x.iter_mut().enumerate() {
            *p = DVec3::new(self.x[0][i], self.x[1][i], self.x[2][i]);
        }
    }

    /// Ends the frame: the PBD velocity update v = (x − x_prev)/h with global damping
    /// ([`Finish::velocity`], the general loop's arithmetic), written out with the positions and
    /// previous positions to the particle store in one pass. The last sweep's displacement, if
    /// still pending, is added as each position is read; the domain keeps it pending (its
    /// positions plus the displacement are still its state). Returns whether every position
    /// is finite with no coordinate beyond `bound` in magnitude (checked as it is copied: the
    /// solver's divergence check then needs no pass of its own).
    pub fn finish(
        &self,
        finish: Finish,
        x: &mut [DVec3],
        prev: &mut [DVec3],
        v: &mut [DVec3],
        bound: f64,
    ) -> bool {
        let out = Out { x, prev, v };
        match self.path {
            SimdPath::Avx512 => finish_avx512(self, finish, out, bound),
            SimdPath::Avx2 => finish_avx2(self, finish, out, bound),
            SimdPath::Neon => finish_neon(self, finish, out, bound),
            SimdPath::Scalar => finish_scalar(self, finish, out, bound),
        }
    }

    /// Starts a substep from `start`: the particle store at a frame's start (positions,
    /// velocities and inverse masses read straight from it), or the previous substep, which it
    /// ends (v = (x − x_prev)/h, then damping v ← v·keep of free particles). Then predicts with
    /// semi-implicit Euler, a = g + c_d (v_wind − v), and applies the pins — the same
    /// arithmetic, particle by particle, as the solver's general loop (after the first substep,
    /// in still air, it takes a = g: the same bits for any finite velocity, see
    /// `Predict::still_air`). Clears the multipliers when `lambda`.
    pub fn integrate(&mut self, step: &Integration<'_>, start: Start<'_>, lambda: bool) {
        advance(self, step, start);
        let range = self.start..self.start + self.len();
        let origin = self.work.origin;
        for &(i, p) in step.pins {
            if range.contains(&i) {
                for a in 0..3 {
                    self.x[a][i - self.start] = p[a];
                    self.work.base[a][i - self.start] = (p[a] - origin[a]) as f32;
                }
            }
        }
        self.work.fresh = true;
        if lambda {
            self.pairs.lambda.fill(0.0);
        }
    }

    /// Resolves the contacts of every free particle (see [`crate::ParticleContacts`]).
    pub fn collide(&mut self, contacts: &dyn ParticleContacts, fresh: bool) -> Contacts {
        self.settle();
        let n = self.len();
        let [x0, x1, x2] = &mut self.x;
        let [p0, p1, p2] = &self.prev;
        let run = ParticleRun {
            start: self.start,
            x: [&mut x0[..n], &mut x1[..n], &mut x2[..n]],
            prev: [&p0[..n], &p1[..n], &p2[..n]],
            w: &self.w[..n],
            path: self.path,
        };
        contacts.resolve_run(run, fresh)
    }
}

/// Which optional terms a sweep evaluates; each setting gives the same bits as the general
/// form (damped, multipliers, any k) with the coefficients it was derived from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Mode {
    /// Some group has XPBD damping (γ > 0): read previous positions.
    pub damped: bool,
    /// Some group has compliance (α̃ > 0): keep multipliers.
    pub lambda: bool,
    /// Every group has k = 1 (XPBD with none disabled): the kernel negates C instead of
    /// multiplying it by −k.
    pub unit_k: bool,
}

/// Where a fused substep starts from (see [`Domain::integrate`]).
#[derive(Clone, Copy)]
pub(crate) enum Start<'a> {
    /// The frame's first substep: the domain's share of the particle store.
    Store(&'a AosChunk<'a>),
    /// A later substep, ending the previous one as this says.
    Finish(Finish),
}

/// How a fused substep ends the previous one: 1/h and the damping factor, if any.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Finish {
    /// 1/h (1/s).
    pub inv_h: f64,
    /// Velocity factor e^(−c h) of global damping, if any.
    pub keep: Option<f64>,
}

impl Finish {
    /// One particle's PBD velocity update v = (x − x_prev)/h, then global damping v ← v·keep
    /// if it is free — the solver's general loop does the same arithmetic. v · 1 = v exactly:
    /// a factor chosen per particle keeps the store unconditional, where a kept value became a
    /// masked store (microcoded on AMD).
    #[inline(always)]
    fn velocity(&self, x: f64, prev: f64, free: bool) -> f64 {
        let v = (x - prev) * self.inv_h;
        match self.keep {
            Some(keep) => v * if free { keep } else { 1.0 },
            None => v,
        }
    }
}

/// A domain's share of the particle store, written by [`Domain::finish`].
struct Out<'a> {
    x: &'a mut [DVec3],
    prev: &'a mut [DVec3],
    v: &'a mut [DVec3],
}

/// [`Domain::finish`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn finish_avx512<'a>(dom: &Domain, finish: Finish, out: Out<'a>, bound: f64) -> bool {
    finish_body(dom, finish, out, bound)
}

/// [`Domain::finish`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn finish_avx2<'a>(dom: &Domain, finish: Finish, out: Out<'a>, bound: f64) -> bool {
    finish_body(dom, finish, out, bound)
}

/// [`Domain::finish`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn finish_neon<'a>(dom: &Domain, finish: Finish, out: Out<'a>, bound: f64) -> bool {
    finish_body(dom, finish, out, bound)
}

/// [`Domain::finish`] compiled for the baseline target.
#[inline(never)]
fn finish_scalar(dom: &Domain, finish: Finish, out: Out<'_>, bound: f64) -> bool {
    finish_body(dom, finish, out, bound)
}

#[inline(always)]
fn finish_body(dom: &Domain, finish: Finish, out: Out<'_>, bound: f64) -> bool {
    if dom.work.unfolded {
        finish_from::<true>(dom, finish, out, bound)
    } else {
        finish_from::<false>(dom, finish, out, bound)
    }
}

/// [`finish_body`], adding the pending displacement to each position it reads when
/// `UNFOLDED`.
#[inline(always)]
fn finish_from<const UNFOLDED: bool>(
    dom: &Domain,
    finish: Finish,
    out: Out<'_>,
    bound: f64,
) -> bool {
    let n = dom.len();
    let w = &dom.w[..n];
    let (xs, ps) = (&dom.x, &dom.prev);
    let ds = &dom.work.disp;
    let (x, prev, v) = (&mut out.x[..n], &mut out.prev[..n], &mut out.v[..n]);
    let at = |a: usize, i: usize| {
        if UNFOLDED {
            xs[a][i] + f64::from(ds[a][i])
        } else {
            xs[a][i]
        }
    };
    let mut ok = true;
    for i in 0..n {
        let free = w[i] > 0.0;
        let xi = DVec3::new(at(0, i), at(1, i), at(2, i));
        let pi = DVec3::new(ps[0][i], ps[1][i], ps[2][i]);
        ok &= within_bound(xi, bound);
        x[i] = xi;
        prev[i] = pi;
        v[i] = DVec3::new(
            finish.velocity(xi.x, pi.x, free),
            finish.velocity(xi.y, pi.y, free),
            finish.velocity(xi.z, pi.z, free),
        );
    }
    ok
}

/// The per-particle part of [`Domain::integrate`] on the domain's kernel path, like [`sweep`].
fn advance(dom: &mut Domain, step: &Integration<'_>, start: Start<'_>) {
    match dom.path {
        SimdPath::Avx512 => advance_avx512(dom, step, start),
        SimdPath::Avx2 => advance_avx2(dom, step, start),
        SimdPath::Neon => advance_neon(dom, step, start),
        SimdPath::Scalar => advance_scalar(dom, step, start),
    }
}

/// [`advance`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn advance_avx512<'a>(dom: &mut Domain, step: &Integration<'a>, start: Start<'a>) {
    advance_body(dom, step, start);
}

/// [`advance`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn advance_avx2<'a>(dom: &mut Domain, step: &Integration<'a>, start: Start<'a>) {
    advance_body(dom, step, start);
}

/// [`advance`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn advance_neon<'a>(dom: &mut Domain, step: &Integration<'a>, start: Start<'a>) {
    advance_body(dom, step, start);
}

/// [`advance`] compiled for the baseline target.
#[inline(never)]
fn advance_scalar(dom: &mut Domain, step: &Integration<'_>, start: Start<'_>) {
    advance_body(dom, step, start);
}

#[inline(always)]
fn advance_body(dom: &mut Domain, step: &Integration<'_>, start: Start<'_>) {
    match start {
        Start::Store(aos) => advance_load(dom, step, aos),
        // The last sweep's displacement, if still pending, is added as each position is read.
        Start::Finish(finish) => {
            if std::mem::take(&mut dom.work.unfolded) {
                advance_from::<true>(dom, step, finish);
            } else {
                advance_from::<false>(dom, step, finish);
            }
        }
    }
}

/// One axis of the prediction (semi-implicit Euler), its constants read once into locals
/// (read through the step inside the loop, they kept it from vectorising).
#[derive(Clone, Copy)]
struct Predict {
    g: f64,
    wind: f64,
    drag: f64,
    h: f64,
}

impl Predict {
    fn along(step: &Integration<'_>, a: usize) -> Self {
        let f = step.forces;
        Self {
            g: f.gravity[a],
            wind: f.wind.velocity[a],
            drag: f.wind.drag,
            h: step.h,
        }
    }

    /// Whether the air along this axis is still ([`still_air`]): a = g for every finite v.
    fn still_air(self) -> bool {
        still_air(self.drag, self.g)
    }

    /// [`Self::position`] of a free particle where [`Self::still_air`]: a = g, the same bits
    /// for a finite velocity.
    #[inline(always)]
    fn position_in_still_air(self, x0: f64, v0: f64) -> f64 {
        let vi = v0 + self.g * self.h;
        x0 + vi * self.h
    }

    /// The new position of a free particle from velocity `v0`, a = g + c_d (v_wind − v0)
    /// (the fixed ones are put back after: see [`put_back_fixed`]).
    #[inline(always)]
    fn position(self, x0: f64, v0: f64) -> f64 {
        let acc = self.g + self.drag * (self.wind - v0);
        let vi = v0 + acc * self.h;
        x0 + vi * self.h
    }
}

/// [`advance_body`] at a frame's start: positions, velocities and inverse masses read from the
/// particle store as they are used (no copy into the domain first; the velocities are never
/// kept: later substeps compute them from the positions). Like [`advance_from`], every
/// particle is predicted as a free one and the fixed ones are put back after.
#[inline(always)]
fn advance_load(dom: &mut Domain, step: &Integration<'_>, aos: &AosChunk<'_>) {
    let n = dom.len();
    let (ax, aw) = (&aos.x[..n], &aos.w[..n]);
    dom.w.copy_from_slice(aw);
    dom.work.set_masses(aw);
    dom.note_fixed();
    dom.work.unfolded = false;
    let predict = [0, 1, 2].map(|a| Predict::along(step, a));
    let origin = ax.first().map_or([0.0; 3], |p| p.to_array());
    dom.work.origin = origin;
    // One loop over the particles, three axes at a time: the store holds them side by side.
    let [x0s, x1s, x2s] = &mut dom.x;
    let [p0s, p1s, p2s] = &mut dom.prev;
    let [b0s, b1s, b2s] = &mut dom.work.base;
    let [d0s, d1s, d2s] = &mut dom.work.disp;
    let mut axes = [
        Axis::of(x0s, p0s, b0s, d0s, n),
        Axis::of(x1s, p1s, b1s, d1s, n),
        Axis::of(x2s, p2s, b2s, d2s, n),
    ];
    if predict.iter().all(|p| p.still_air()) {
        predict_loaded::<true>(&mut axes, aos, predict, origin);
    } else {
        predict_loaded::<false>(&mut axes, aos, predict, origin);
    }
    for (axis, origin) in axes.iter_mut().zip(origin) {
        put_back_fixed(&dom.fixed, axis, origin);
    }
}

/// The loop of [`advance_load`], every particle as a free one, with `STILL_AIR` the
/// prediction's form along every axis ([`Predict::still_air`]).
#[inline(always)]
fn predict_loaded<const STILL_AIR: bool>(
    axes: &mut [Axis<'_>; 3],
    aos: &AosChunk<'_>,
    predict: [Predict; 3],
    origin: [f64; 3],
) {
    let n = axes[0].x.len();
    let (ax, av) = (&aos.x[..n], &aos.v[..n]);
    for i in 0..n {
        let (p, v) = (ax[i].to_array(), av[i].to_array());
        for (a, axis) in axes.iter_mut().enumerate() {
            axis.prev[i] = p[a];
            let xi = if STILL_AIR {
                predict[a].position_in_still_air(p[a], v[a])
            } else {
                predict[a].position(p[a], v[a])
            };
            axis.x[i] = xi;
            axis.base[i] = (xi - origin[a]) as f32;
            axis.disp[i] = 0.0;
        }
    }
}

/// One axis of a domain's state, as the prediction reads and writes it, every slice cut to
/// the domain's particle count.
struct Axis<'a> {
    x: &'a mut [f64],
    prev: &'a mut [f64],
    base: &'a mut [f32],
    disp: &'a mut [f32],
}

impl<'a> Axis<'a> {
    fn of(
        x: &'a mut [f64],
        prev: &'a mut [f64],
        base: &'a mut [f32],
        disp: &'a mut [f32],
        n: usize,
    ) -> Self {
        Self {
            x: &mut x[..n],
            prev: &mut prev[..n],
            base: &mut base[..n],
            disp: &mut disp[..n],
        }
    }
}

/// Puts the `fixed` particles back where they started the substep (their previous position),
/// after a loop that predicted them as free ones.
fn put_back_fixed(fixed: &[u32], axis: &mut Axis<'_>, origin: f64) {
    for &i in fixed {
        let x0 = axis.prev[i as usize];
        axis.x[i as usize] = x0;
        axis.base[i as usize] = (x0 - origin) as f32;
    }
}

/// The loop of [`advance_from`] along one axis, every particle as a free one, with
/// `STILL_AIR` the prediction's form ([`Predict::still_air`]).
#[inline(always)]
fn predict_axis<const UNFOLDED: bool, const STILL_AIR: bool>(
    axis: &mut Axis<'_>,
    finish: Finish,
    predict: Predict,
    origin: f64,
) {
    let n = axis.x.len();
    let (x, prev) = (&mut *axis.x, &mut axis.prev[..n]);
    let (base, disp) = (&mut axis.base[..n], &mut axis.disp[..n]);
    for i in 0..n {
        let x0 = if UNFOLDED {
            x[i] + f64::from(disp[i])
        } else {
            x[i]
        };
        let v0 = finish.velocity(x0, prev[i], true);
        prev[i] = x0;
        let xi = if STILL_AIR {
            predict.position_in_still_air(x0, v0)
        } else {
            predict.position(x0, v0)
        };
        x[i] = xi;
        base[i] = (xi - origin) as f32;
        disp[i] = 0.0;
    }
}

/// [`advance_body`] after a substep, adding the pending displacement to each position it reads
/// when `UNFOLDED`. One pass ending the previous substep and predicting the next: the
/// velocity update and damping (`Finish::velocity`) kept in a register, never written (the
/// next substep, or the frame's end, computes it again from the positions).
#[inline(always)]
fn advance_from<const UNFOLDED: bool>(dom: &mut Domain, step: &Integration<'_>, finish: Finish) {
    let n = dom.len();
    let fixed = &dom.fixed;
    for a in 0..3 {
        // The sweep's f32 state (see `Rebased`), relative to the first particle's position
        // at the substep's start.
        let mut axis = Axis::of(
            &mut dom.x[a],
            &mut dom.prev[a],
            &mut dom.work.base[a],
            &mut dom.work.disp[a],
            n,
        );
        let predict = Predict::along(step, a);
        let origin = match (n, UNFOLDED) {
            (0, _) => 0.0,
            (_, true) => axis.x[0] + f64::from(axis.disp[0]),
            (_, false) => axis.x[0],
        };
        dom.work.origin[a] = origin;
        // Every particle as a free one (no inverse mass read, no select), then the fixed ones
        // back.
        if predict.still_air() {
            predict_axis::<UNFOLDED, true>(&mut axis, finish, predict, origin);
        } else {
            predict_axis::<UNFOLDED, false>(&mut axis, finish, predict, origin);
        }
        put_back_fixed(fixed, &mut axis, origin);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rng;

    #[test]
    fn still_air_predicts_the_bits_of_the_full_form_for_finite_velocities() {
        let predict = |g: f64, drag: f64| Predict {
            g,
            wind: 3.0,
            drag,
            h: 1.0 / 600.0,
        };
        // Drag, or a gravity of −0 (−0 + (+0) = +0), keep the full form.
        assert!(predict(-9.81, 0.0).still_air() && predict(0.0, 0.0).still_air());
        assert!(!predict(-9.81, 0.2).still_air() && !predict(-9.81, -0.0).still_air());
        assert!(!predict(-0.0, 0.0).still_air());
        let mut r = rng(7);
        for g in [-9.81, 0.0, 1e-300, 4.5] {
            let p = predict(g, 0.0);
            for k in 0..2000 {
                // Velocities either side of the wind's, zeros of both signs among them.
                let v0 = match k {
                    0 => 0.0,
                    1 => -0.0,
                    2 => 3.0,
                    _ => r() * 10f64.powi(k % 9 - 4),
                };
                let x0 = r() * 4.0;
                assert_eq!(
                    p.position_in_still_air(x0, v0).to_bits(),
                    p.position(x0, v0).to_bits(),
                    "g {g}, x0 {x0}, v0 {v0}"
                );
            }
        }
    }
}
