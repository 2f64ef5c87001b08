//! Stability of explicit springs: a Gershgorin bound on the highest mode of the spring system
//! linearised at rest, and the largest substep semi-implicit Euler survives with it.
//!
//! Linearised about rest, the springs give M ẍ = −K x − D ẋ with K = Σ k ∇C ∇Cᵀ and
//! D = Σ c ∇C ∇Cᵀ over the constraints. Every eigenvalue ω² of M⁻¹K is one of the symmetric
//! M^{-1/2} K M^{-1/2}, so by Gershgorin's theorem (on its 3×3 blocks, ‖k ∇ᵢC ∇ⱼCᵀ‖ = k |∇ᵢC| |∇ⱼC|)
//!
//! ```text
//! ω² ≤ max over free particles i of  Σ_{constraints c ∋ i} k_c |∇ᵢC| Σⱼ |∇ⱼC| √(wᵢ wⱼ)
//! ```
//!
//! For a distance spring |∇C| = 1, so with equal masses this is the familiar wᵢ Σ 2k over the
//! particle's springs; pinned neighbours (w = 0) add nothing. The damping rate γ is bounded the
//! same way with c in place of k. Semi-implicit Euler on ẍ = −ω² x − γ ẋ has the amplification
//! matrix [[1 − hγ, −hω²], [h(1 − hγ), 1 − h²ω²]] (acting on (v, x)), of trace 2 − hγ − h²ω² and
//! determinant 1 − hγ; by the Jury criterion it is stable iff h²ω² + 2hγ < 4, i.e. h < 2/ω
//! without damping.
//!
//! Gershgorin's bound is sufficient, not sharp: at a light boundary particle (a grid corner
//! holds a sixth of an interior particle's mass) it can overstate ω by tens of percent. The
//! highest mode itself is therefore also estimated, by power iteration on the same matrix; a
//! substep between the two limits is past the guarantee but short of the mode that explodes.

use std::ops::Range;

use glam::DVec3;

use crate::constraints::{Block, ConstraintSet, Isometric, Seam, Shape, Tether};
use crate::params::FamilyParams;

/// How fast a cloth's springs can ring and how much their dampers can bite (all zero: no
/// springs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StabilityBound {
    /// Upper bound on the highest angular frequency ω of the springs linearised at rest (rad/s).
    pub omega: f64,
    /// Upper bound on the highest damping rate γ of the spring dampers (1/s).
    pub gamma: f64,
    /// The highest mode itself, ω, estimated by power iteration on M^{-1/2} K M^{-1/2}
    /// (a Rayleigh quotient: a lower bound on ω that converges to it); ≤ `omega`. Estimated
    /// for an explicit method only; otherwise `omega`.
    pub mode_omega: f64,
    /// That mode's damping rate (its Rayleigh quotient of M^{-1/2} D M^{-1/2}).
    pub mode_gamma: f64,
}

/// ∇C of an isometric hinge, kᵢ n with n = v/|v|; on a flat hinge (v = 0), where its stiffness
/// k kᵢ kⱼ I is the same in every direction, along z.
fn isometric_gradient(s: &Isometric, p: &[DVec3; 4]) -> Option<[DVec3; 4]> {
    let n = s.curvature(p).try_normalize().unwrap_or(DVec3::Z);
    Some(s.weights.map(|k| n * k))
}

/// Largest h with h²ω² + 2hγ < 4.
fn limit(omega: f64, gamma: f64) -> f64 {
    let (w2, g) = (omega * omega, gamma);
    if w2 > 0.0 {
        // The positive root of ω² h² + 2γ h − 4 = 0.
        4.0 / (g + (g * g + 4.0 * w2).sqrt())
    } else if g > 0.0 {
        2.0 / g
    } else {
        f64::INFINITY
    }
}

impl StabilityBound {
    /// Largest substep h (s) with h²ω² + 2hγ < 4 for the Gershgorin bounds: below it semi-implicit
    /// Euler is stable for certain (about the rest state); infinite without springs.
    pub fn max_substep(&self) -> f64 {
        limit(self.omega, self.gamma)
    }

    /// The same limit for the highest mode as estimated: above it the run explodes.
    pub fn mode_max_substep(&self) -> f64 {
        limit(self.mode_omega, self.mode_gamma)
    }

    /// Whether substep `h` (s) is inside the bound.
    pub fn allows(&self, h: f64) -> bool {
        h < self.max_substep()
    }

    /// Fewest substeps per frame of `dt` (s) that the bound allows.
    pub fn min_substeps(&self, dt: f64) -> u64 {
        let h = self.max_substep();
        if h.is_finite() {
            (dt / h).floor() as u64 + 1
        } else {
            1
        }
    }
}

/// Every enabled constraint of `block` with its particles, its parameters and ∇C from `grad`
/// at `x`; constraints whose gradient is undefined (degenerate) are left out.
fn enabled_gradients<'a, const N: usize, S: Shape<N>>(
    block: &'a Block<N, S>,
    x: &'a [DVec3],
    params: &'a [FamilyParams],
    grad: impl Fn(&S, &[DVec3; N]) -> Option<[DVec3; N]> + 'a,
) -> impl Iterator<Item = ([u32; N], &'a FamilyParams, [DVec3; N])> + 'a {
    let constraints = block.particles.iter().zip(&block.shapes).zip(&block.group);
    constraints.filter_map(move |((idx, shape), &g)| {
        let p = &params[g as usize];
        if !p.enabled {
            return None;
        }
        let gr = grad(shape, &idx.map(|i| x[i as usize]))?;
        Some((*idx, p, gr))
    })
}

/// Row sums of the scaled stiffness and damping matrices, per particle.
struct Rows {
    k: Vec<f64>,
    c: Vec<f64>,
}

impl Rows {
    /// Adds every enabled constraint of `block`, with ∇C from `grad` at `x`.
    fn add<const N: usize, S: Shape<N>>(
        &mut self,
        block: &Block<N, S>,
        x: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        grad: impl Fn(&S, &[DVec3; N]) -> Option<[DVec3; N]>,
    ) {
        for (idx, p, gr) in enabled_gradients(block, x, params, grad) {
            let norms = gr.map(|v| v.length());
            let ws = idx.map(|i| w[i as usize].sqrt());
            let sum: f64 = (0..N).map(|j| norms[j] * ws[j]).sum();
            for k in 0..N {
                let row = norms[k] * ws[k] * sum;
                self.k[idx[k] as usize] += p.spring_stiffness * row;
                self.c[idx[k] as usize] += p.spring_damping * row;
            }
        }
    }
}

/// The terms of M^{-1/2} K M^{-1/2} and M^{-1/2} D M^{-1/2} for constraints of `N`
/// particles, each evaluated once: the particles, aⱼ = ∇ⱼC √wⱼ, and the spring's k and c.
/// A power iteration then costs a pass over them, not a gradient per constraint per pass.
#[derive(Default)]
struct Terms<const N: usize> {
    idx: Vec<[u32; N]>,
    a: Vec<[DVec3; N]>,
    kc: Vec<[f64; 2]>,
}

impl<const N: usize> Terms<N> {
    /// The terms of every enabled constraint of `block` that touches a particle with
    /// √w > 0 in `sw` (the others add nothing), with ∇C from `grad` at `x`.
    fn new<S: Shape<N>>(
        block: &Block<N, S>,
        x: &[DVec3],
        sw: &[f64],
        params: &[FamilyParams],
        grad: impl Fn(&S, &[DVec3; N]) -> Option<[DVec3; N]>,
    ) -> Self {
        let mut t = Self::default();
        for (idx, p, gr) in enabled_gradients(block, x, params, grad) {
            let a: [DVec3; N] = std::array::from_fn(|j| gr[j] * sw[idx[j] as usize]);
            if a.iter().all(|v| *v == DVec3::ZERO) {
                continue;
            }
            t.idx.push(idx);
            t.a.push(a);
            t.kc.push([p.spring_stiffness, p.spring_damping]);
        }
        t
    }

    /// Adds M^{-1/2} K M^{-1/2} z into `out_k` and M^{-1/2} D M^{-1/2} z into `out_c`.
    fn product(&self, z: &[DVec3], out_k: &mut [DVec3], out_c: &mut [DVec3]) {
        for ((idx, a), [k, c]) in self.idx.iter().zip(&self.a).zip(&self.kc) {
            let s: f64 = (0..N).map(|j| a[j].dot(z[idx[j] as usize])).sum();
            for j in 0..N {
                let i = idx[j] as usize;
                out_k[i] += a[j] * (k * s);
                out_c[i] += a[j] * (c * s);
            }
        }
    }
}

/// Power iterations for the highest mode (at most).
const POWER_ITERATIONS: usize = 150;

/// The highest mode's (ω, γ) of the particles in `range`, by power iteration.
fn highest_mode(
    constraints: &ConstraintSet,
    x: &[DVec3],
    w: &[f64],
    params: &[FamilyParams],
    range: Range<usize>,
) -> (f64, f64) {
    let sw: Vec<f64> = w
        .iter()
        .enumerate()
        .map(|(i, &w)| {
            if range.contains(&i) {
                w.max(0.0).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let distance = Terms::new(&constraints.distance, x, &sw, params, |s, p| {
        s.evaluate(p).map(|(_, g)| g)
    });
    let dihedral = Terms::new(&constraints.dihedral, x, &sw, params, |s, p| {
        s.evaluate(p).map(|(_, g)| g)
    });
    let isometric = Terms::new(&constraints.isometric, x, &sw, params, isometric_gradient);
    let tethers = Terms::new(&constraints.tethers, x, &sw, params, |_: &Tether, p| {
        let d = p[0] - p[1];
        let len = d.length();
        (len > 1e-9).then(|| [d / len, -d / len])
    });
    let seams = Terms::new(
        &constraints.seams,
        x,
        &sw,
        &constraints.seam_params,
        |s: &Seam, p| s.evaluate(p).map(|(_, g)| g),
    );
    // A deterministic start with every sign pattern in it (the highest modes alternate).
    let mut z: Vec<DVec3> = (0..x.len())
        .map(|i| {
            let s = |k: usize| if (i / k) % 2 == 0 { 1.0 } else { -1.0 };
            DVec3::new(s(1), s(2) * 0.7, s(3) * 0.4) * if sw[i] > 0.0 { 1.0 } else { 0.0 }
        })
        .collect();
    let mut kz = vec![DVec3::ZERO; x.len()];
    let mut cz = vec![DVec3::ZERO; x.len()];
    let dot = |a: &[DVec3], b: &[DVec3]| a.iter().zip(b).map(|(a, b)| a.dot(*b)).sum::<f64>();
    let (mut lambda, mut damping) = (0.0, 0.0);
    for _ in 0..POWER_ITERATIONS {
        let norm = dot(&z, &z).sqrt();
        if norm == 0.0 {
            return (0.0, 0.0);
        }
        z.iter_mut().for_each(|v| *v /= norm);
        kz.fill(DVec3::ZERO);
        cz.fill(DVec3::ZERO);
        distance.product(&z, &mut kz, &mut cz);
        dihedral.product(&z, &mut kz, &mut cz);
        isometric.product(&z, &mut kz, &mut cz);
        tethers.product(&z, &mut kz, &mut cz);
        seams.product(&z, &mut kz, &mut cz);
        lambda = dot(&z, &kz);
        damping = dot(&z, &cz);
        std::mem::swap(&mut z, &mut kz);
    }
    (lambda.max(0.0).sqrt(), damping.max(0.0))
}

/// The bound for the particles in `range`, linearised at positions `x` with inverse masses `w`;
/// with `mode`, the highest mode estimated too (otherwise its fields repeat the bound).
pub(crate) fn bound(
    constraints: &ConstraintSet,
    x: &[DVec3],
    w: &[f64],
    params: &[FamilyParams],
    range: Range<usize>,
    mode: bool,
) -> StabilityBound {
    let mut rows = Rows {
        k: vec![0.0; x.len()],
        c: vec![0.0; x.len()],
    };
    rows.add(&constraints.distance, x, w, params, |s, p| {
        s.evaluate(p).map(|(_, g)| g)
    });
    rows.add(&constraints.dihedral, x, w, params, |s, p| {
        s.evaluate(p).map(|(_, g)| g)
    });
    rows.add(&constraints.isometric, x, w, params, isometric_gradient);
    // A tether pulls only once stretched; bound it as the spring it becomes then.
    rows.add(&constraints.tethers, x, w, params, |_, p| {
        let d = p[0] - p[1];
        let len = d.length();
        (len > 1e-9).then(|| [d / len, -d / len])
    });
    rows.add(
        &constraints.seams,
        x,
        w,
        &constraints.seam_params,
        |s, p| s.evaluate(p).map(|(_, g)| g),
    );
    let max = |v: &[f64]| v[range.clone()].iter().copied().fold(0.0, f64::max);
    let (omega, gamma) = (max(&rows.k).sqrt(), max(&rows.c));
    let (mode_omega, mode_gamma) = if mode {
        highest_mode(constraints, x, w, params, range.clone())
    } else {
        (omega, gamma)
    };
    StabilityBound {
        omega,
        gamma,
        mode_omega,
        mode_gamma,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undamped_limit_is_two_over_omega() {
        let b = StabilityBound {
            omega: 100.0,
            gamma: 0.0,
            mode_omega: 100.0,
            mode_gamma: 0.0,
        };
        assert!((b.max_substep() - 0.02).abs() < 1e-15);
        assert!(b.allows(0.0199) && !b.allows(0.0201));
        assert_eq!(b.min_substeps(0.1), 6);
    }

    #[test]
    fn damping_shortens_the_limit_as_the_jury_criterion_says() {
        let b = StabilityBound {
            omega: 100.0,
            gamma: 50.0,
            mode_omega: 100.0,
            mode_gamma: 50.0,
        };
        let h = b.max_substep();
        assert!(h < 0.02);
        let residual = h * h * 1e4 + 2.0 * h * 50.0 - 4.0;
        assert!(residual.abs() < 1e-12, "{residual}");
        // The amplification matrix of semi-implicit Euler has spectral radius 1 at the limit.
        let radius = |h: f64| {
            let (t, d) = (2.0 - h * 50.0 - h * h * 1e4, 1.0 - h * 50.0);
            let disc = t * t / 4.0 - d;
            if disc >= 0.0 {
                (t / 2.0).abs() + disc.sqrt()
            } else {
                d.sqrt()
            }
        };
        assert!(radius(h * 0.99) < 1.0 && radius(h * 1.01) > 1.0);
    }
}
