//! The isometric-bending projection written over `L` independent lanes at once, in explicit
//! vectors of any [`pulp::Simd`] (as [`super::dihedral_lanes`]): every lane runs the same IEEE
//! operations in the same order (no fused multiply-adds), so a constraint gets the same bits on
//! every kernel path and width, whichever thread projects it.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use pulp::{Scalar, Simd};

use super::lanes::Coefs;
use super::lanes::Quads;
use weft_simd::{load, store};

/// Projects `L` independent isometric-bending constraints in place, `L` being the f64 lanes
/// of `S`: the vector constraint C = v = Σᵢ kᵢ xᵢ, one row per axis with the same gradient
/// ∂C_a/∂xᵢ = kᵢ, so every row shares the denominator and the rows do not couple.
///
/// Per axis a: Δλ_a = (−k v_a − α̃ λ_a − γ Σᵢ kᵢ (xᵢ − x_prev,ᵢ)_a) / ((1 + γ) Σ wᵢkᵢ² + α̃) and
/// Δxᵢ = wᵢ kᵢ Δλ: Macklin et al. 2016 eq. (18) with the damping of eq. (26) for XPBD (k = 1),
/// Müller et al. 2007 eq. (10) for PBD (α̃ = γ = 0). The energy ½ |v|²/α is that of the scalar
/// C = |v| (the mass-spring methods' [`super::Isometric`]), but as a vector C is linear, so
/// no direction is taken from a vanishing v and λ stays consistent between sweeps: no square
/// root, one division. Lanes where the denominator vanishes or Σ wᵢkᵢ² ≤ 1e-12 Σ kᵢ² max wᵢ
/// (the free particles cannot bend the hinge) are left alone. `prev` is read only when
/// `DAMPED`.
#[inline(always)]
pub(crate) fn project<S: Simd, const L: usize, const DAMPED: bool>(
    s: S,
    x: &mut Quads<L>,
    prev: &Quads<L>,
    w: &[[f64; L]; 4],
    weights: &[[f64; L]; 4],
    coef: &Coefs<L>,
    lambda: &mut [[f64; L]; 3],
) {
    debug_assert_eq!(L, S::F64_LANES);
    let (steps, inv) = constants::<S, L>(s, w, weights, coef);
    apply::<S, L, DAMPED>(s, x, prev, weights, &steps, inv, coef, lambda);
}

/// The part of [`project`] that depends on the inverse masses and coefficients alone, not on
/// the positions: each particle's step wᵢkᵢ and the inverse of the denominator
/// (1 + γ) Σ wᵢkᵢ² + α̃, or 0 where the hinge is left alone.
#[inline(always)]
pub(crate) fn constants<S: Simd, const L: usize>(
    s: S,
    w: &[[f64; L]; 4],
    weights: &[[f64; L]; 4],
    coef: &Coefs<L>,
) -> ([S::f64s; 4], S::f64s) {
    let zero = s.splat_f64s(0.0);
    let kv: [_; 4] = std::array::from_fn(|v| load::<S, L>(weights[v]));
    let wv: [_; 4] = std::array::from_fn(|v| load::<S, L>(w[v]));
    let (mut w_grad2, mut k2_sum, mut w_max) = (zero, zero, zero);
    for v in 0..4 {
        let k2 = s.mul_f64s(kv[v], kv[v]);
        w_grad2 = s.add_f64s(w_grad2, s.mul_f64s(wv[v], k2));
        k2_sum = s.add_f64s(k2_sum, k2);
        w_max = s.select_f64s(s.greater_than_f64s(wv[v], w_max), wv[v], w_max);
    }
    let alpha = load::<S, L>(coef.alpha);
    let gamma = load::<S, L>(coef.gamma);
    let one = s.splat_f64s(1.0);
    let denom = s.add_f64s(s.mul_f64s(s.add_f64s(one, gamma), w_grad2), alpha);
    let singular = s.less_than_or_equal_f64s(
        w_grad2,
        s.mul_f64s(s.mul_f64s(s.splat_f64s(1e-12), k2_sum), w_max),
    );
    let live = s.and_m64s(
        s.greater_than_f64s(denom, s.splat_f64s(f64::MIN_POSITIVE)),
        s.not_m64s(singular),
    );
    let inv = s.select_f64s(live, s.div_f64s(one, s.select_f64s(live, denom, one)), zero);
    let steps = std::array::from_fn(|v| s.mul_f64s(wv[v], kv[v]));
    (steps, inv)
}

/// The part of [`project`] that moves the particles, given [`constants`]' steps and inverse
/// denominator.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn apply<S: Simd, const L: usize, const DAMPED: bool>(
    s: S,
    x: &mut Quads<L>,
    prev: &Quads<L>,
    weights: &[[f64; L]; 4],
    steps: &[S::f64s; 4],
    inv: S::f64s,
    coef: &Coefs<L>,
    lambda: &mut [[f64; L]; 3],
) {
    let zero = s.splat_f64s(0.0);
    let mut xs = [[zero; 3]; 4];
    let mut kv = [zero; 4];
    for v in 0..4 {
        kv[v] = load::<S, L>(weights[v]);
        for a in 0..3 {
            xs[v][a] = load::<S, L>(x[v][a]);
        }
    }
    let (k, alpha) = (load::<S, L>(coef.k), load::<S, L>(coef.alpha));
    let gamma = load::<S, L>(coef.gamma);
    for a in 0..3 {
        let term = |v: usize, p: S::f64s| s.mul_f64s(kv[v], p);
        let curv = s.add_f64s(
            s.add_f64s(term(0, xs[0][a]), term(1, xs[1][a])),
            s.add_f64s(term(2, xs[2][a]), term(3, xs[3][a])),
        );
        let lam = load::<S, L>(lambda[a]);
        let mut num = s.sub_f64s(s.mul_f64s(s.neg_f64s(k), curv), s.mul_f64s(alpha, lam));
        if DAMPED {
            let moved = |v: usize| term(v, s.sub_f64s(xs[v][a], load::<S, L>(prev[v][a])));
            let along = s.add_f64s(
                s.add_f64s(moved(0), moved(1)),
                s.add_f64s(moved(2), moved(3)),
            );
            num = s.sub_f64s(num, s.mul_f64s(gamma, along));
        }
        let dl = s.mul_f64s(num, inv);
        lambda[a] = store::<S, L>(s.add_f64s(lam, dl));
        for v in 0..4 {
            x[v][a] = store::<S, L>(s.add_f64s(xs[v][a], s.mul_f64s(steps[v], dl)));
        }
    }
}

/// An isometric hinge's [`constants`] for a frame, on one lane: kept while the inverse masses
/// and coefficients stay the same, they leave the sweep the positions' part of the projection.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Prepared {
    /// wᵢkᵢ per particle.
    pub steps: [f64; 4],
    /// 1 / ((1 + γ) Σ wᵢkᵢ² + α̃), or 0 where the hinge is left alone.
    pub inv: f64,
}

impl Prepared {
    /// The constants of a hinge of weights `k` on particles of inverse masses `w`.
    pub fn new(w: [f64; 4], k: [f64; 4], coef: &Coefs<1>) -> Self {
        let (steps, inv) = constants::<Scalar, 1>(Scalar, &w.map(|v| [v]), &k.map(|v| [v]), coef);
        Self {
            steps: steps.map(|v| v),
            inv,
        }
    }

    /// [`project`] of one hinge of weights `k` with these constants: the same operations, so
    /// the same bits.
    #[inline(always)]
    pub fn project<const DAMPED: bool>(
        &self,
        x: &mut Quads<1>,
        prev: &Quads<1>,
        k: [f64; 4],
        coef: &Coefs<1>,
        lambda: &mut [[f64; 1]; 3],
    ) {
        apply::<Scalar, 1, DAMPED>(
            Scalar,
            x,
            prev,
            &k.map(|v| [v]),
            &self.steps,
            self.inv,
            coef,
            lambda,
        );
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;
    use pulp::{Scalar, Scalar128b, Scalar256b, Scalar512b};

    use super::*;
    use crate::constraints::Isometric;
    use crate::constraints::lanes::Coef;
    use crate::test_rand::rng;

    /// The projection written per axis on the shape's weights.
    fn reference(
        p: &mut [DVec3; 4],
        prev: &[DVec3; 4],
        w: &[f64; 4],
        shape: &Isometric,
        coef: Coef,
        lambda: &mut DVec3,
    ) {
        let k = shape.weights;
        let w_grad2: f64 = (0..4).map(|i| w[i] * k[i] * k[i]).sum();
        let k2: f64 = k.iter().map(|k| k * k).sum();
        if w_grad2 <= 1e-12 * k2 * w.iter().copied().fold(0.0, f64::max) {
            return;
        }
        let v = shape.curvature(p);
        let moved: DVec3 = (0..4).map(|i| (p[i] - prev[i]) * k[i]).sum();
        let denom = (1.0 + coef.gamma) * w_grad2 + coef.alpha;
        let dl = (-v * coef.k - *lambda * coef.alpha - moved * coef.gamma) * (1.0 / denom);
        *lambda += dl;
        for i in 0..4 {
            p[i] += dl * (w[i] * k[i]);
        }
    }

    fn quads<const L: usize>(p: &[[DVec3; 4]; L]) -> Quads<L> {
        std::array::from_fn(|v| std::array::from_fn(|k| std::array::from_fn(|l| p[l][v][k])))
    }

    /// `L` random bent hinges, their shapes at a flat rest, inverse masses (some pinned) and
    /// coefficients; then each lane projected by the kernel on `S` against the reference.
    fn check<S: Simd + Copy, const L: usize>(s: S, damped: bool) {
        let mut rnd = rng(0x150_3e71c);
        for _ in 0..200 {
            let rest: [[DVec3; 4]; L] = std::array::from_fn(|_| {
                let mut j = || DVec3::new(rnd(), rnd(), 0.0) * 0.2;
                [
                    DVec3::new(0.0, 1.0, 0.0) + j(),
                    DVec3::new(0.0, -1.0, 0.0) + j(),
                    DVec3::new(-1.0, 0.0, 0.0) + j(),
                    DVec3::new(1.0, 0.0, 0.0) + j(),
                ]
            });
            let shapes: [Isometric; L] =
                std::array::from_fn(|l| Isometric::at_rest(&rest[l]).expect("not degenerate"));
            let p: [[DVec3; 4]; L] =
                std::array::from_fn(|l| rest[l].map(|q| q + DVec3::new(rnd(), rnd(), rnd()) * 0.3));
            let prev: [[DVec3; 4]; L] =
                std::array::from_fn(|l| p[l].map(|q| q + DVec3::new(rnd(), rnd(), rnd()) * 0.01));
            let w: [[f64; 4]; L] = std::array::from_fn(|_| {
                std::array::from_fn(|_| if rnd() < -0.3 { 0.0 } else { 1.0 + rnd() })
            });
            let coef: [Coef; L] = std::array::from_fn(|_| Coef {
                k: 1.0,
                alpha: 0.5 + rnd(),
                gamma: if damped { 0.1 + 0.05 * rnd() } else { 0.0 },
            });
            let lam0: [DVec3; L] = std::array::from_fn(|_| DVec3::new(rnd(), rnd(), rnd()) * 0.1);
            let mut x = quads(&p);
            let old = quads(&prev);
            let wl: [[f64; L]; 4] = std::array::from_fn(|v| std::array::from_fn(|l| w[l][v]));
            let kl: [[f64; L]; 4] =
                std::array::from_fn(|v| std::array::from_fn(|l| shapes[l].weights[v]));
            let mut lam: [[f64; L]; 3] =
                std::array::from_fn(|a| std::array::from_fn(|l| lam0[l][a]));
            let coefs = Coefs::from_fn(|l| coef[l]);
            if damped {
                project::<S, L, true>(s, &mut x, &old, &wl, &kl, &coefs, &mut lam);
            } else {
                project::<S, L, false>(s, &mut x, &old, &wl, &kl, &coefs, &mut lam);
            }
            for l in 0..L {
                let (mut q, mut lr) = (p[l], lam0[l]);
                reference(&mut q, &prev[l], &w[l], &shapes[l], coef[l], &mut lr);
                let got = DVec3::new(lam[0][l], lam[1][l], lam[2][l]);
                assert!(
                    (got - lr).length() <= 1e-12 * (1.0 + lr.length()),
                    "{got} vs {lr}"
                );
                for v in 0..4 {
                    let got = DVec3::new(x[v][0][l], x[v][1][l], x[v][2][l]);
                    assert!(
                        (got - q[v]).length() < 1e-12,
                        "lane {l} vertex {v}: {got} vs {}",
                        q[v]
                    );
                }
            }
        }
    }

    #[test]
    fn every_width_projects_as_the_scalar_shape() {
        for damped in [false, true] {
            check::<Scalar, 1>(Scalar, damped);
            check::<Scalar128b, 2>(Scalar128b, damped);
            check::<Scalar256b, 4>(Scalar256b, damped);
            check::<Scalar512b, 8>(Scalar512b, damped);
        }
    }

    #[test]
    fn a_flat_hinge_stays_put_a_bent_one_flattens_and_a_pinned_one_is_left_alone() {
        let rest = [
            DVec3::new(0.1, 1.0, 0.0),
            DVec3::new(-0.1, -1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.1, 0.0),
        ];
        let shape = Isometric::at_rest(&rest).expect("not degenerate");
        let kl: [[f64; 1]; 4] = std::array::from_fn(|v| [shape.weights[v]]);
        let coefs = Coefs::<1>::splat(Coef {
            k: 1.0,
            alpha: 0.0,
            gamma: 0.0,
        });
        let mut bent = rest;
        bent[0].z = 0.2;
        let run = |p: [DVec3; 4], w: [f64; 4]| {
            let mut x = quads(&[p]);
            let mut lam = [[0.0]; 3];
            let wl: [[f64; 1]; 4] = std::array::from_fn(|v| [w[v]]);
            project::<Scalar, 1, false>(Scalar, &mut x, &quads(&[p]), &wl, &kl, &coefs, &mut lam);
            let moved: [DVec3; 4] =
                std::array::from_fn(|v| DVec3::new(x[v][0][0], x[v][1][0], x[v][2][0]));
            (moved, lam)
        };
        // Flat: C is zero up to rounding, and so is the move.
        let (flat, _) = run(rest, [1.0; 4]);
        for v in 0..4 {
            assert!((flat[v] - rest[v]).length() < 1e-15, "{flat:?}");
        }
        // Bent, at compliance 0: one projection flattens it (C is linear).
        let (flattened, lam) = run(bent, [1.0, 2.0, 0.5, 1.0]);
        assert!(shape.curvature(&flattened).length() < 1e-14);
        assert!(lam[2][0] != 0.0);
        // Every particle pinned: nothing moves, λ stays zero.
        let (pinned, lam) = run(bent, [0.0; 4]);
        assert_eq!((pinned, lam), (bent, [[0.0]; 3]));
    }
}
