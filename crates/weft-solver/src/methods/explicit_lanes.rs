//! Explicit mass-spring's substep in lanes, one part of the particles at a time: the part's
//! spring forces from the stencil, `W` particles at a time ([`SpringStencil::group_forces`],
//! f32), then its integration in f64 with semi-implicit Euler, v ← v + h a, x ← x + h v, then
//! v ← (x − x_prev)/h and the global damping, the general loop's operations in its order
//! (`solver/frame.rs`), in one loop per axis over the part.

use glam::DVec3;
use multiversion::multiversion;
use rayon::prelude::*;

use crate::air::still_air;
use crate::chunk::CHUNK;
use crate::constraints::{Mirror, Ring, SpringStencil, WIDEST};
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
    /// Loads the particles' positions, velocities and inverse masses, padded to `stride`
    /// (one parallel pass over the particles).
    pub fn load(&mut self, stride: usize, x: &[DVec3], v: &[DVec3], w: &[f64]) {
        let n = x.len().min(v.len());
        for a in 0..3 {
            for s in [&mut self.x[a], &mut self.v[a], &mut self.prev[a]] {
                s.resize(stride, 0.0);
                s[n..].fill(0.0);
            }
        }
        let [x0, x1, x2] = self.x.each_mut().map(|s| s[..n].par_chunks_mut(CHUNK));
        let [v0, v1, v2] = self.v.each_mut().map(|s| s[..n].par_chunks_mut(CHUNK));
        let (x, v) = (x[..n].par_chunks(CHUNK), v[..n].par_chunks(CHUNK));
        (x0, x1, x2, v0, v1, v2, x, v).into_par_iter().for_each(
            |(x0, x1, x2, v0, v1, v2, x, v)| {
                for (i, (x, v)) in x.iter().zip(v).enumerate() {
                    (x0[i], x1[i], x2[i]) = (x.x, x.y, x.z);
                    (v0[i], v1[i], v2[i]) = (v.x, v.y, v.z);
                }
            },
        );
        self.w.clear();
        self.w.extend_from_slice(w);
        self.w.resize(stride, 0.0);
    }

    /// Writes the particles from `start` on back: positions, velocities and positions at the
    /// last substep's start (one pass, the arrays cut to the particles first so that no index
    /// is checked in the loop).
    pub fn store(&self, start: usize, x: &mut [DVec3], v: &mut [DVec3], prev: &mut [DVec3]) {
        let n = x.len().min(v.len()).min(prev.len());
        let (sx, sv, sp) = (
            cut(&self.x, start, n),
            cut(&self.v, start, n),
            cut(&self.prev, start, n),
        );
        let at = |s: &[&[f64]; 3], i: usize| DVec3::new(s[0][i], s[1][i], s[2][i]);
        for (i, ((x, v), prev)) in x.iter_mut().zip(v).zip(prev).enumerate() {
            *x = at(&sx, i);
            *v = at(&sv, i);
            *prev = at(&sp, i);
        }
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

/// Values `start .. start + n` of each axis.
fn cut(s: &[Vec<f64>; 3], start: usize, n: usize) -> [&[f64]; 3] {
    let r = start..start + n;
    [&s[0][r.clone()], &s[1][r.clone()], &s[2][r]]
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

impl Step {
    /// Whether the air is still ([`still_air`] along every axis: a = g to the bit for finite
    /// velocities) and undamped (e^(−c h) = 1: a product by 1 changes no bit).
    pub fn still(&self) -> bool {
        let drag = self.drag;
        self.keep == 1.0
            && (self.gravity.to_array())
                .into_iter()
                .all(|g| still_air(drag, g))
    }
}

/// One task's particles: `start` (a multiple of [`WIDEST`]) and, from there, its share of the
/// state and of the next mirror (x then v, per axis), all of one length, a multiple of
/// [`WIDEST`].
pub(crate) struct Part<'a> {
    /// Index of the first particle.
    pub start: usize,
    /// Positions per axis.
    pub x: [&'a mut [f64]; 3],
    /// Velocities per axis.
    pub v: [&'a mut [f64]; 3],
    /// Positions at the substep's start per axis (written on the frame's last substep).
    pub prev: [&'a mut [f64]; 3],
    /// Inverse masses.
    pub w: &'a [f64],
    /// The next mirror's x − origin, then v, per axis (written).
    pub next: [&'a mut [f32]; 6],
    /// The task's working memory.
    pub scratch: &'a mut Scratch,
    /// Whether this is the frame's last substep (the only one whose start is kept in `prev`).
    pub last: bool,
}

/// A task's working memory, kept from substep to substep (its content is rewritten by each).
#[derive(Clone, Debug)]
pub(crate) struct Scratch {
    /// The ring of spring forces.
    ring: Ring,
    /// The part's spring forces per axis (N).
    force: [Vec<f32>; 3],
}

impl Scratch {
    /// Working memory for `stencil`'s parts.
    pub fn new(stencil: &SpringStencil) -> Self {
        Self {
            ring: stencil.ring(),
            force: Default::default(),
        }
    }
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
    assert!(part.start % WIDEST == 0 && part.w.len() % WIDEST == 0);
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
    step_in::<16>(st, coef, from, s, p);
}

/// [`step_part`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn step_avx2(st: &SpringStencil, coef: &[[f32; 2]], from: &Mirror, s: &Step, p: &mut Part) {
    step_in::<16>(st, coef, from, s, p);
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

/// [`step_part`] at `W` lanes: spring forces for the part, then its integration.
#[inline(always)]
fn step_in<const W: usize>(
    st: &SpringStencil,
    coef: &[[f32; 2]],
    from: &Mirror,
    s: &Step,
    p: &mut Part<'_>,
) {
    // Without damping the springs need no velocities: the mirror's are neither read nor
    // written.
    let damped = coef.iter().any(|&[_, c]| c != 0.0);
    match damped {
        true => forces::<W, true>(st, coef, from, p),
        false => forces::<W, false>(st, coef, from, p),
    }
    match (damped, s.still()) {
        (true, true) => integrate::<true, true>(s, from, p),
        (true, false) => integrate::<true, false>(s, from, p),
        (false, true) => integrate::<false, true>(s, from, p),
        (false, false) => integrate::<false, false>(s, from, p),
    }
}

/// The part's spring forces into its scratch.
#[inline(always)]
fn forces<const W: usize, const DAMPED: bool>(
    st: &SpringStencil,
    coef: &[[f32; 2]],
    from: &Mirror,
    p: &mut Part<'_>,
) {
    let len = p.w.len();
    let Scratch { ring, force } = &mut *p.scratch;
    st.warm_ring::<W, DAMPED>(coef, from, ring, p.start);
    for f in force.iter_mut() {
        f.resize(len, 0.0);
    }
    for j in (0..len).step_by(W) {
        let f = st.group_forces::<W, DAMPED>(coef, from, ring, p.start + j);
        for a in 0..3 {
            force[a][j..j + W].copy_from_slice(&f[a]);
        }
    }
}

/// The part's integration from the forces in its scratch, one loop per axis over the part
/// (the compiler vectorizes it, selects included); the next mirror's velocities only where
/// `DAMPED` springs read them; in `STILL` air ([`Step::still`]) without the drag and the
/// global damping, which would change no bit there.
#[inline(always)]
fn integrate<const DAMPED: bool, const STILL: bool>(s: &Step, from: &Mirror, p: &mut Part<'_>) {
    let (h, inv_h, keep) = (s.h, s.inv_h, s.keep);
    let (g, drag, wind) = (s.gravity.to_array(), s.drag, s.wind.to_array());
    let origin = from.origin.to_array();
    for a in 0..3 {
        let (nx, nv) = {
            let (nx, rest) = p.next.split_at_mut(3);
            (&mut *nx[a], &mut *rest[a])
        };
        let (x, v) = (&mut *p.x[a], &mut *p.v[a]);
        if p.last {
            p.prev[a].copy_from_slice(x);
        }
        let (g, wind, origin) = (g[a], wind[a], origin[a]);
        let state = x.iter_mut().zip(v.iter_mut());
        let next = nx.iter_mut().zip(nv.iter_mut());
        let given = p.w.iter().zip(&p.scratch.force[a]);
        for ((x, v), ((nx, nv), (&w, &f))) in state.zip(next.zip(given)) {
            let (x0, v0) = (*x, *v);
            // a = g + c_d (v_wind − v) + f w (`Forces::acceleration_of`, then the springs).
            let air = if STILL { g } else { g + drag * (wind - v0) };
            let acc = air + f64::from(f) * w;
            let free = w > 0.0;
            let x1 = if free { x0 + (v0 + acc * h) * h } else { x0 };
            let v1 = (x1 - x0) * inv_h;
            let v1 = if !STILL && free { v1 * keep } else { v1 };
            *x = x1;
            *v = v1;
            *nx = (x1 - origin) as f32;
            if DAMPED {
                *nv = v1 as f32;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One part's integration of `n` particles (every fifth pinned) from a fixed pseudo-random
    /// state, by `integrate::<false, STILL>`: the bits of x, v, prev and the next mirror.
    fn integrated<const STILL: bool>(s: &Step, n: usize) -> Vec<u64> {
        let wave = |k: usize, f: f64| (k as f64 * f).sin();
        let axes = |f: f64| -> [Vec<f64>; 3] {
            std::array::from_fn(|a| (0..n).map(|k| wave(k, f + a as f64)).collect())
        };
        let (mut x, mut v, mut prev) = (axes(0.37), axes(1.1), axes(0.0));
        let w: Vec<f64> = (0..n)
            .map(|k| {
                if k % 5 == 0 {
                    0.0
                } else {
                    1.0 + wave(k, 0.3).abs()
                }
            })
            .collect();
        let mut next: [Vec<f32>; 6] = std::array::from_fn(|_| vec![0.0; n]);
        let mut scratch = Scratch {
            ring: Ring::default(),
            force: std::array::from_fn(|a| {
                (0..n).map(|k| wave(k, 2.3 + a as f64) as f32).collect()
            }),
        };
        let from = Mirror {
            origin: DVec3::new(0.1, 0.9, -0.2),
            ..Mirror::default()
        };
        let [x0, x1, x2] = &mut x;
        let [v0, v1, v2] = &mut v;
        let [p0, p1, p2] = &mut prev;
        let [n0, n1, n2, n3, n4, n5] = &mut next;
        let mut part = Part {
            start: 0,
            x: [x0, x1, x2],
            v: [v0, v1, v2],
            prev: [p0, p1, p2],
            w: &w,
            next: [n0, n1, n2, n3, n4, n5],
            scratch: &mut scratch,
            last: true,
        };
        integrate::<false, STILL>(s, &from, &mut part);
        let f64s = x
            .iter()
            .chain(&v)
            .chain(&prev)
            .flatten()
            .map(|e| e.to_bits());
        let f32s = next.iter().flatten().map(|e| u64::from(e.to_bits()));
        f64s.chain(f32s).collect()
    }

    #[test]
    fn still_air_skips_only_what_changes_no_bit() {
        let still = Step {
            h: 1.0 / 600.0,
            inv_h: 600.0,
            keep: 1.0,
            gravity: DVec3::new(0.0, -9.81, 0.0),
            drag: 0.0,
            wind: DVec3::new(0.0, 0.0, 3.0),
        };
        assert!(still.still());
        let n = 3 * WIDEST;
        assert!(integrated::<true>(&still, n) == integrated::<false>(&still, n));
        // Damping or drag is not still air: skipping them would change bits.
        for s in [
            Step {
                keep: 0.999,
                ..still
            },
            Step { drag: 0.1, ..still },
        ] {
            assert!(!s.still(), "{s:?}");
            assert!(
                integrated::<true>(&s, n) != integrated::<false>(&s, n),
                "{s:?}"
            );
        }
        // Nor is a −0 in g (−0 + 0 is +0).
        let signed = DVec3::new(-0.0, -9.81, 0.0);
        assert!(
            !Step {
                gravity: signed,
                ..still
            }
            .still()
        );
    }
}
