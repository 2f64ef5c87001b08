//! Explicit mass-spring's substep in lanes: each group of particles takes its spring forces
//! from the stencil ([`SpringStencil::group_forces`], f32) and integrates in f64 with
//! semi-implicit Euler, v ← v + h a, x ← x + h v, then v ← (x − x_prev)/h and the global
//! damping, the general loop's operations in its order (`solver/frame.rs`), one particle per
//! lane.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use multiversion::multiversion;

use crate::constraints::lanes::LANES;
use crate::constraints::{Mirror, SpringStencil};
use weft_simd::SimdPath;

/// The particles' f64 state as struct-of-arrays, padded to the stencil's stride (the padding
/// has no inverse mass and never moves).
#[derive(Clone, Debug, Default)]
pub(crate) struct LaneState {
    /// Positions per axis (m).
    pub x: [Vec<f64>; 3],
    /// Velocities per axis (m/s).
    pub v: [Vec<f64>; 3],
    /// Positions at the start of the last substep per axis (m).
    pub prev: [Vec<f64>; 3],
    /// Inverse masses (1/kg).
    pub w: Vec<f64>,
}

impl LaneState {
    /// Loads the particles' positions, velocities and inverse masses, padded to `stride`.
    pub fn load(&mut self, stride: usize, x: &[DVec3], v: &[DVec3], w: &[f64]) {
        for a in 0..3 {
            for (dst, src) in [(&mut self.x[a], x), (&mut self.v[a], v)] {
                dst.clear();
                dst.extend(src.iter().map(|p| p[a]));
                dst.resize(stride, 0.0);
            }
            self.prev[a].resize(stride, 0.0);
        }
        self.w.clear();
        self.w.extend_from_slice(w);
        self.w.resize(stride, 0.0);
    }

    /// Particle `i`'s position, velocity and position at the last substep's start.
    pub fn get(&self, i: usize) -> [DVec3; 3] {
        let at = |s: &[Vec<f64>; 3]| DVec3::new(s[0][i], s[1][i], s[2][i]);
        [at(&self.x), at(&self.v), at(&self.prev)]
    }

    /// Sets particle `i`'s position and velocity.
    pub fn set(&mut self, i: usize, x: DVec3, v: DVec3) {
        for a in 0..3 {
            self.x[a][i] = x[a];
            self.v[a][i] = v[a];
        }
    }
}

/// What a substep's integration needs besides the particles.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Step {
    /// The substep h (s).
    pub h: f64,
    /// 1/h (1/s).
    pub inv_h: f64,
    /// e^(−c h), the global damping of a free particle's velocity (1 without damping: exact).
    pub keep: f64,
    /// Gravity g (m/s²).
    pub gravity: DVec3,
    /// Linear drag rate c_d (1/s) towards the wind (no aerodynamics).
    pub drag: f64,
    /// The wind's velocity (m/s).
    pub wind: DVec3,
}

/// One task's particles: `start` (a multiple of [`LANES`]) and, from there, its share of the
/// state and of the next mirror (x then v, per axis), all of one length, a multiple of
/// [`LANES`].
pub(crate) struct Part<'a> {
    /// Index of the first particle.
    pub start: usize,
    /// Positions per axis.
    pub x: [&'a mut [f64]; 3],
    /// Velocities per axis.
    pub v: [&'a mut [f64]; 3],
    /// Positions at the substep's start per axis (written).
    pub prev: [&'a mut [f64]; 3],
    /// Inverse masses.
    pub w: &'a [f64],
    /// The next mirror's x − origin, then v, per axis (written).
    pub next: [&'a mut [f32]; 6],
}

/// One substep for `part`: forces from the mirror `from`, integration, the next mirror's
/// entries (positions relative to `from.origin`).
pub(crate) fn step_part(
    path: SimdPath,
    stencil: &SpringStencil,
    coef: &[[f32; 2]],
    from: &Mirror,
    step: &Step,
    part: &mut Part<'_>,
) {
    assert!(part.start % LANES == 0 && part.w.len() % LANES == 0);
    match path {
        SimdPath::Avx512 => step_avx512(stencil, coef, from, step, part),
        SimdPath::Avx2 => step_avx2(stencil, coef, from, step, part),
        SimdPath::Neon => step_neon(stencil, coef, from, step, part),
        SimdPath::Scalar => step_scalar(stencil, coef, from, step, part),
    }
}

/// [`step_part`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn step_avx512(st: &SpringStencil, coef: &[[f32; 2]], from: &Mirror, s: &Step, p: &mut Part) {
    step_in::<LANES>(st, coef, from, s, p);
}

/// [`step_part`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn step_avx2(st: &SpringStencil, coef: &[[f32; 2]], from: &Mirror, s: &Step, p: &mut Part) {
    step_in::<8>(st, coef, from, s, p);
}

/// [`step_part`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn step_neon(st: &SpringStencil, coef: &[[f32; 2]], from: &Mirror, s: &Step, p: &mut Part) {
    step_in::<4>(st, coef, from, s, p);
}

/// [`step_part`] compiled for the baseline target.
#[inline(never)]
fn step_scalar(st: &SpringStencil, coef: &[[f32; 2]], from: &Mirror, s: &Step, p: &mut Part) {
    step_in::<4>(st, coef, from, s, p);
}

#[inline(always)]
fn step_in<const W: usize>(
    st: &SpringStencil,
    coef: &[[f32; 2]],
    from: &Mirror,
    s: &Step,
    p: &mut Part<'_>,
) {
    let (h, inv_h, keep) = (s.h, s.inv_h, s.keep);
    let (g, drag, wind) = (s.gravity, s.drag, s.wind);
    let origin = from.origin;
    let len = p.w.len();
    for j in (0..len).step_by(W) {
        let f = st.group_forces::<W>(coef, from, p.start + j);
        let w = &p.w[j..j + W];
        for a in 0..3 {
            let x = &mut p.x[a][j..j + W];
            let v = &mut p.v[a][j..j + W];
            let prev = &mut p.prev[a][j..j + W];
            let (nx, nv) = {
                let (nx, rest) = p.next.split_at_mut(3);
                (&mut nx[a][j..j + W], &mut rest[a][j..j + W])
            };
            for l in 0..W {
                let (x0, v0) = (x[l], v[l]);
                // a = g + c_d (v_wind − v) + f w (`Forces::acceleration_of`, then the springs).
                let acc = (g[a] + drag * (wind[a] - v0)) + f64::from(f[a][l]) * w[l];
                let free = w[l] > 0.0;
                let x1 = if free { x0 + (v0 + acc * h) * h } else { x0 };
                let v1 = (x1 - x0) * inv_h;
                let v1 = if free { v1 * keep } else { v1 };
                prev[l] = x0;
                x[l] = x1;
                v[l] = v1;
                nx[l] = (x1 - origin[a]) as f32;
                nv[l] = v1 as f32;
            }
        }
    }
}
