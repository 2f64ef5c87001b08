//! The dihedral-bending projection written over `L` independent lanes at once, in explicit
//! vectors of any [`pulp::Simd`] (eight lanes of AVX-512, four of AVX2, portable or one-lane
//! forms for the rest).
//!
//! One generic function serves the SIMD chunks (`L` = the vector width) and the scalar
//! remainder (`L = 1`): every lane runs the same IEEE operations in the same order (no fused
//! multiply-adds), so a constraint gets bit-identical results whichever path projects it, and
//! runs do not depend on the thread count, the kernel path or how constraints fall into chunks.
//!
//! Against the scalar [`super::Dihedral::evaluate`] (the reference, used by the mass-spring
//! methods), the angle here skips the normalisations, θ = atan2((N₁ × N₂)·E, (N₁·N₂)|E|) (both
//! arguments scaled by the same positive |N₁||N₂||E|, which atan2 ignores), the gradient uses
//! three reciprocals instead of eleven divisions, and atan2 is a branch-free form of Cephes'
//! rational approximation, so that the whole projection vectorises: 6 divisions and 1 square
//! root per constraint instead of about 20 divisions, 3 square roots and a libm call.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use pulp::Simd;

use super::lanes::Coefs;
use super::lanes::Quads;
use weft_simd::{Ops, V3, load, store};

/// tan(3π/8).
const TAN_3PI_8: f64 = 2.414_213_562_373_095;
/// π/2 − fl(π/2): the bits of π/2 that `FRAC_PI_2` leaves out (Cephes' MOREBITS).
const MOREBITS: f64 = 6.123_233_995_736_766e-17;
/// Numerator of atan(t) = t + t z P(z)/Q(z), z = t², |t| ≤ 0.66 (Cephes `atan.c`, S. L.
/// Moshier, Cephes Math Library 2.8, 2000; peak relative error 2.6e-18 on its interval).
const P: [f64; 5] = [
    -8.750_608_600_031_904e-1,
    -1.615_753_718_733_365e1,
    -7.500_855_792_314_705e1,
    -1.228_866_684_490_136e2,
    -6.485_021_904_942_025e1,
];
/// Denominator of the same approximation (leading coefficient 1).
const Q: [f64; 5] = [
    2.485_846_490_142_306e1,
    1.650_270_098_316_988e2,
    4.328_810_604_912_903e2,
    4.853_903_996_359_137e2,
    1.945_506_571_482_614e2,
];

/// A 3-vector of lanes.
type V<S> = V3<S>;

/// atan2(y, x) in every lane, without branches: Cephes' argument reduction of |y|/|x| to
/// |t| ≤ 0.66 (t = |y|/|x|, (|y| − |x|)/(|y| + |x|) around π/4 or −|x|/|y| near π/2, chosen
/// by comparing |y| with 0.66 |x| and tan(3π/8) |x|, so one division serves all three), the
/// rational approximation, then the quadrant from the signs. Within about 1 ulp of libm's
/// `atan2` (tested); atan2(0, 0) is 0, and the sign of a zero `x` is not looked at.
#[inline(always)]
pub(crate) fn atan2<S: Simd>(s: S, y: S::f64s, x: S::f64s) -> S::f64s {
    let o = Ops(s);
    let (ay, ax) = (s.abs_f64s(y), s.abs_f64s(x));
    let big = o.gt(ay, o.mul(o.c(TAN_3PI_8), ax));
    let mid = o.gt(ay, o.mul(o.c(0.66), ax));
    let num = o.sel(big, o.neg(ax), o.sel(mid, o.sub(ay, ax), ay));
    let den = o.sel(big, ay, o.sel(mid, o.add(ay, ax), ax));
    let base = o.sel(big, o.c(FRAC_PI_2), o.sel(mid, o.c(FRAC_PI_4), o.c(0.0)));
    let more = o.sel(
        big,
        o.c(MOREBITS),
        o.sel(mid, o.c(0.5 * MOREBITS), o.c(0.0)),
    );
    // 0/0 only when both are zero; a one there keeps the lane finite.
    let t = o.div(num, o.sel(o.gt(den, o.c(0.0)), den, o.c(1.0)));
    let z = o.mul(t, t);
    let mut p = o.c(P[0]);
    for coef in &P[1..] {
        p = o.add(o.mul(p, z), o.c(*coef));
    }
    let mut q = z;
    for (i, coef) in Q.iter().enumerate() {
        q = o.add(q, o.c(*coef));
        if i + 1 < Q.len() {
            q = o.mul(q, z);
        }
    }
    let r = o.add(base, o.add(o.add(o.mul(t, o.div(o.mul(z, p), q)), t), more));
    let r = o.sel(o.lt(x, o.c(0.0)), o.sub(o.c(PI), r), r);
    o.sel(o.lt(y, o.c(0.0)), o.neg(r), r)
}

/// Projects `L` independent dihedral constraints C = θ − θ₀ in place, `L` being the f64 lanes
/// of `S` (one vector per coordinate; every lane runs the same IEEE operations, so any `S`
/// gives the same bits per constraint).
///
/// θ and ∇C are those of [`super::Dihedral`] (Bridson et al. 2003, §4): with N₁ = (x₁ − x₃) ×
/// (x₁ − x₄), N₂ = (x₂ − x₄) × (x₂ − x₃) and E = x₄ − x₃, ∇₁C = −|E| N₁/|N₁|²,
/// ∇₂C = −|E| N₂/|N₂|², ∇₃C = −((x₁ − x₄)·Ê N₁/|N₁|² + (x₂ − x₄)·Ê N₂/|N₂|²),
/// ∇₄C = (x₁ − x₃)·Ê N₁/|N₁|² + (x₂ − x₃)·Ê N₂/|N₂|²; C is wrapped into (−π, π].
/// Then Δλ = (−k C − α̃ λ − γ ∇C·(x − x_prev)) / ((1 + γ) Σ wᵢ|∇ᵢC|² + α̃) and Δxᵢ = wᵢ ∇ᵢC Δλ:
/// Macklin et al. 2016 eq. (18) with the damping of eq. (26) for XPBD (k = 1), Müller et al.
/// 2007 eq. (10) for PBD (α̃ = γ = 0). Degenerate lanes (|N₁|² or |N₂|² < 1e-24, |E| < 1e-9,
/// a zero denominator, or Σ wᵢ|∇ᵢC|² ≤ 1e-12 Σ|∇ᵢC|² max wᵢ: the free particles cannot turn
/// the hinge) are left alone. `prev` is read only when `DAMPED`.
#[inline(always)]
pub(crate) fn project<S: Simd, const L: usize, const DAMPED: bool>(
    s: S,
    x: &mut Quads<L>,
    prev: &Quads<L>,
    w: &[[f64; L]; 4],
    rest: &[f64; L],
    coef: &Coefs<L>,
    lambda: &mut [f64; L],
) {
    debug_assert_eq!(L, S::F64_LANES);
    let o = Ops(s);
    let zero = o.c(0.0);
    let mut xs: [V<S>; 4] = [[zero; 3]; 4];
    for v in 0..4 {
        for k in 0..3 {
            xs[v][k] = load::<S, L>(x[v][k]);
        }
    }
    let (a1, b1) = (o.dif(&xs[0], &xs[2]), o.dif(&xs[0], &xs[3])); // x₁ − x₃, x₁ − x₄
    let (a2, b2) = (o.dif(&xs[1], &xs[3]), o.dif(&xs[1], &xs[2])); // x₂ − x₄, x₂ − x₃
    let e = o.dif(&xs[3], &xs[2]);
    let (n1, n2) = (o.cross(&a1, &b1), o.cross(&a2, &b2));
    let (q1, q2, ee) = (o.dot(&n1, &n1), o.dot(&n2, &n2), o.dot(&e, &e));
    let le = s.sqrt_f64s(ee);
    let tiny = o.c(1e-24);
    let ok = o.and(o.and(o.ge(q1, tiny), o.ge(q2, tiny)), o.ge(le, o.c(1e-9)));
    // θ = atan2((N₁ × N₂)·E, (N₁·N₂)|E|), C = θ − θ₀ wrapped into (−π, π].
    let sin_part = o.dot(&o.cross(&n1, &n2), &e);
    let cos_part = o.mul(o.dot(&n1, &n2), le);
    let d = o.sub(atan2(s, sin_part, cos_part), load::<S, L>(*rest));
    let wrapped = o.sel(o.le(d, o.c(-PI)), o.add(d, o.c(2.0 * PI)), d);
    let c = o.sel(o.gt(d, o.c(PI)), o.sub(d, o.c(2.0 * PI)), wrapped);
    // m₁ = N₁/|N₁|², m₂ = N₂/|N₂|²; degenerate lanes divide by one instead.
    let one = o.c(1.0);
    let inv_q1 = o.div(one, o.sel(ok, q1, one));
    let inv_q2 = o.div(one, o.sel(ok, q2, one));
    let inv_le = o.div(one, o.sel(ok, le, one));
    let s13 = o.mul(o.dot(&b1, &e), inv_le); // (x₁ − x₄)·Ê
    let s23 = o.mul(o.dot(&a2, &e), inv_le); // (x₂ − x₄)·Ê
    let t13 = o.mul(o.dot(&a1, &e), inv_le); // (x₁ − x₃)·Ê
    let t23 = o.mul(o.dot(&b2, &e), inv_le); // (x₂ − x₃)·Ê
    let mut g: [V<S>; 4] = [[zero; 3]; 4];
    for k in 0..3 {
        let m1 = o.mul(n1[k], inv_q1);
        let m2 = o.mul(n2[k], inv_q2);
        g[0][k] = o.neg(o.mul(le, m1));
        g[1][k] = o.neg(o.mul(le, m2));
        g[2][k] = o.neg(o.add(o.mul(s13, m1), o.mul(s23, m2)));
        g[3][k] = o.add(o.mul(t13, m1), o.mul(t23, m2));
    }
    let mut wv = [zero; 4];
    let (mut w_grad2, mut grad_dx) = (zero, zero);
    // Σ |∇ᵢC|² max wᵢ: what Σ wᵢ|∇ᵢC|² would be if every particle moved freely.
    let (mut g2_sum, mut w_max) = (zero, zero);
    for v in 0..4 {
        wv[v] = load::<S, L>(w[v]);
        let g2 = o.dot(&g[v], &g[v]);
        w_grad2 = o.add(w_grad2, o.mul(wv[v], g2));
        g2_sum = o.add(g2_sum, g2);
        w_max = o.sel(o.gt(wv[v], w_max), wv[v], w_max);
        if DAMPED {
            for k in 0..3 {
                let moved = o.sub(xs[v][k], load::<S, L>(prev[v][k]));
                grad_dx = o.add(grad_dx, o.mul(g[v][k], moved));
            }
        }
    }
    let (k, alpha) = (load::<S, L>(coef.k), load::<S, L>(coef.alpha));
    let gamma = load::<S, L>(coef.gamma);
    let lam = load::<S, L>(*lambda);
    let denom = o.add(o.mul(o.add(one, gamma), w_grad2), alpha);
    let mut num = o.sub(o.mul(o.neg(k), c), o.mul(alpha, lam));
    if DAMPED {
        num = o.sub(num, o.mul(gamma, grad_dx));
    }
    // A constraint whose free particles barely move its angle (a free hinge particle level
    // with its pinned wings: ∇C there is ~0) would take a step of C/|∇C_free|, far beyond the
    // element, and shake a stiff pinned strip chaotically: it is left alone.
    let singular = o.le(w_grad2, o.mul(o.mul(o.c(1e-12), g2_sum), w_max));
    let live = o.and(
        o.and(ok, o.gt(denom, o.c(f64::MIN_POSITIVE))),
        s.not_m64s(singular),
    );
    // Divided in every lane; a dead lane's quotient is discarded.
    let dl = o.sel(live, o.div(num, denom), zero);
    *lambda = store::<S, L>(o.add(lam, dl));
    for v in 0..4 {
        let step = o.mul(wv[v], dl);
        for k in 0..3 {
            x[v][k] = store::<S, L>(o.add(xs[v][k], o.mul(g[v][k], step)));
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use pulp::{Scalar, Scalar128b, Scalar256b, Scalar512b};

    use super::*;
    use crate::constraints::lanes::Coef;
    use crate::constraints::{Dihedral, Shape};
    use crate::test_rand::rng;

    fn quads<const L: usize>(p: &[[DVec3; 4]; L]) -> Quads<L> {
        std::array::from_fn(|v| std::array::from_fn(|k| std::array::from_fn(|l| p[l][v][k])))
    }

    #[test]
    fn atan2_is_within_two_ulps_of_libm_in_every_octant() {
        let mut rnd = rng(0x51f1_5eed);
        let mut worst = 0.0f64;
        for i in 0..200_000 {
            // Magnitudes from 1e-6 to 1e6, both signs, and exact octant boundaries.
            let s = 10f64.powf(12.0 * rnd());
            let (y, x) = match i % 5 {
                0 => (rnd() * s, rnd()),
                1 => (rnd(), rnd() * s),
                2 => (rnd(), rnd().signum() * rnd().abs() * TAN_3PI_8),
                3 => (rnd().signum(), rnd().signum() * (0.66 + 1e-3 * rnd())),
                _ => (rnd(), rnd()),
            };
            let got = atan2(Scalar, y, x);
            let want = y.atan2(x);
            let ulp = (want.abs().max(f64::MIN_POSITIVE) * f64::EPSILON).max(1e-300);
            worst = worst.max((got - want).abs() / ulp);
        }
        assert!(worst <= 2.0, "worst error {worst} ulp");
        assert_eq!(atan2(Scalar, 0.0, 0.0), 0.0);
        assert_eq!(atan2(Scalar, 0.0, -1.0), PI);
        assert_eq!(atan2(Scalar, 1.0, 0.0), FRAC_PI_2);
        assert_eq!(atan2(Scalar, -1.0, 0.0), -FRAC_PI_2);
    }

    /// The scalar reference: [`Dihedral::evaluate`] and the multiplier step of XPBD.
    fn reference(
        p: &mut [DVec3; 4],
        prev: &[DVec3; 4],
        w: &[f64; 4],
        rest: f64,
        coef: Coef,
        lambda: &mut f64,
    ) {
        let Some((c, g)) = (Dihedral { rest }).evaluate(p) else {
            return;
        };
        let w_grad2: f64 = (0..4).map(|k| w[k] * g[k].length_squared()).sum();
        let grad_dx: f64 = (0..4).map(|k| g[k].dot(p[k] - prev[k])).sum();
        let denom = (1.0 + coef.gamma) * w_grad2 + coef.alpha;
        let dl = (-coef.k * c - coef.alpha * *lambda - coef.gamma * grad_dx) / denom;
        *lambda += dl;
        for k in 0..4 {
            p[k] += g[k] * (w[k] * dl);
        }
    }

    fn random_quad(rnd: &mut impl FnMut() -> f64) -> [DVec3; 4] {
        // A hinge along x and two wings at random fold angles, jittered.
        let fold = |a: f64, s: f64| DVec3::new(0.3 * s, a.cos() * s.abs(), a.sin() * s.abs());
        let j = |r: &mut dyn FnMut() -> f64| DVec3::new(r(), r(), r()) * 0.1;
        [
            fold(3.0 * rnd(), 1.0) + j(rnd),
            fold(3.0 * rnd() + PI, -1.0) + j(rnd),
            DVec3::new(-0.5, 0.0, 0.0) + j(rnd),
            DVec3::new(0.5, 0.0, 0.0) + j(rnd),
        ]
    }

    #[test]
    fn lanes_match_the_scalar_reference_and_one_lane_at_a_time_bit_for_bit() {
        lanes_match::<Scalar512b, 8>(Scalar512b);
        lanes_match::<Scalar256b, 4>(Scalar256b);
    }

    /// The AVX2 vectors the sweep runs on x86-64 (every x86-64 machine Weft is tested on has
    /// AVX2 and FMA: the test fails, not skips, on one without).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_lanes_match_one_lane_at_a_time_bit_for_bit() {
        let v3 = pulp::x86::V3::try_new().expect("a CPU with AVX2 and FMA");
        lanes_match::<pulp::x86::V3, 4>(v3);
    }

    /// `S`'s `L` lanes against one lane at a time (same bits) and the scalar reference.
    fn lanes_match<S: Simd, const L: usize>(s: S) {
        let mut rnd = rng(0xd1ed_4a11);
        for round in 0..200 {
            let p: [[DVec3; 4]; L] = std::array::from_fn(|_| random_quad(&mut rnd));
            let prev: [[DVec3; 4]; L] =
                std::array::from_fn(|l| p[l].map(|v| v + DVec3::splat(0.01 * rnd())));
            let w: [[f64; 4]; L] = std::array::from_fn(|l| {
                std::array::from_fn(|v| if (l + v) % 7 == 3 { 0.0 } else { rnd() + 1.0 })
            });
            let rest: [f64; L] = std::array::from_fn(|_| 2.0 * rnd());
            let coef: [Coef; L] = std::array::from_fn(|_| Coef {
                k: if round % 3 == 0 { rnd() + 0.5 } else { 1.0 },
                alpha: if round % 2 == 0 { 0.0 } else { rnd().abs() },
                gamma: if round % 4 < 2 { 0.0 } else { rnd().abs() },
            });
            let lambda0: [f64; L] = std::array::from_fn(|_| rnd());
            let mut wide = quads(&p);
            let mut lambda = lambda0;
            let wl: [[f64; L]; 4] = std::array::from_fn(|v| std::array::from_fn(|l| w[l][v]));
            project::<S, L, true>(
                s,
                &mut wide,
                &quads(&prev),
                &wl,
                &rest,
                &Coefs::from_fn(|l| coef[l]),
                &mut lambda,
            );
            for l in 0..L {
                let mut one = quads(&[p[l]]);
                let mut lam = [lambda0[l]];
                project::<Scalar, 1, true>(
                    Scalar,
                    &mut one,
                    &quads(&[prev[l]]),
                    &std::array::from_fn(|v| [w[l][v]]),
                    &[rest[l]],
                    &Coefs::splat(coef[l]),
                    &mut lam,
                );
                assert_eq!(
                    lam[0].to_bits(),
                    lambda[l].to_bits(),
                    "round {round} lane {l}"
                );
                let mut r = p[l];
                let mut lr = lambda0[l];
                reference(&mut r, &prev[l], &w[l], rest[l], coef[l], &mut lr);
                assert!(
                    (lr - lam[0]).abs() <= 1e-9 * (1.0 + lr.abs()),
                    "λ {lr} vs {}",
                    lam[0]
                );
                for v in 0..4 {
                    for k in 0..3 {
                        assert_eq!(one[v][k][0].to_bits(), wide[v][k][l].to_bits());
                        let moved = (r[v][k] - p[l][v][k]).abs();
                        assert!(
                            (one[v][k][0] - r[v][k]).abs() <= 1e-9 * (1e-3 + moved),
                            "round {round} lane {l} particle {v} axis {k}: {} vs {}",
                            one[v][k][0],
                            r[v][k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn an_undamped_form_gives_the_damped_bits_when_gamma_is_zero() {
        const L: usize = 4;
        let mut rnd = rng(0x00dd_ba11);
        let p: [[DVec3; 4]; L] = std::array::from_fn(|_| random_quad(&mut rnd));
        let alpha = rnd().abs();
        let coef = Coefs::splat(Coef {
            k: 1.0,
            alpha,
            gamma: 0.0,
        });
        let w = [[1.0; L]; 4];
        let rest = [0.3; L];
        let run = |damped: bool| {
            let mut x = quads(&p);
            let mut lambda = [0.0; L];
            type Kernel = fn(
                Scalar256b,
                &mut Quads<L>,
                &Quads<L>,
                &[[f64; L]; 4],
                &[f64; L],
                &Coefs<L>,
                &mut [f64; L],
            );
            let kernel: Kernel = if damped {
                project::<Scalar256b, L, true>
            } else {
                project::<Scalar256b, L, false>
            };
            kernel(
                Scalar256b,
                &mut x,
                &quads(&p),
                &w,
                &rest,
                &coef,
                &mut lambda,
            );
            (
                x.map(|a| a.map(|b| b.map(f64::to_bits))),
                lambda.map(f64::to_bits),
            )
        };
        assert_eq!(run(false), run(true));
    }

    #[test]
    fn a_free_particle_that_cannot_turn_the_hinge_is_not_flung_away() {
        // Wings and one hinge end pinned; the free hinge end sees its wings (almost) level
        // with the other end, so ∂θ/∂x₄ ≈ 1e-9: a plain projection would move it ~1e9 × C.
        let fold = 0.4f64;
        let p = [
            DVec3::new(-0.5 + 1e-9, 1.0, 0.0),
            DVec3::new(-0.5, -fold.cos(), fold.sin()),
            DVec3::new(-0.5, 0.0, 0.0),
            DVec3::new(0.5, 0.0, 0.0),
        ];
        let mut x = quads(&[p]);
        let before = x;
        let mut lambda = [0.0];
        project::<Scalar, 1, false>(
            Scalar,
            &mut x,
            &before,
            &[[0.0], [0.0], [0.0], [1.0]],
            &[0.0],
            &Coefs::splat(Coef {
                k: 1.0,
                alpha: 0.0,
                gamma: 0.0,
            }),
            &mut lambda,
        );
        for k in 0..3 {
            assert_eq!(x[3][k][0].to_bits(), before[3][k][0].to_bits(), "axis {k}");
        }
        // With the wing moved off level the same particle turns the hinge and is projected.
        let mut q = p;
        q[0].x = -0.2;
        let mut x = quads(&[q]);
        project::<Scalar, 1, false>(
            Scalar,
            &mut x,
            &quads(&[q]),
            &[[0.0], [0.0], [0.0], [1.0]],
            &[0.0],
            &Coefs::splat(Coef {
                k: 1.0,
                alpha: 0.0,
                gamma: 0.0,
            }),
            &mut lambda,
        );
        let moved = (0..3)
            .map(|k| (x[3][k][0] - q[3][k]).abs())
            .fold(0.0, f64::max);
        assert!(moved > 0.1 && moved < 2.0, "{moved}");
    }

    #[test]
    fn a_degenerate_lane_is_left_alone_and_its_neighbours_are_not() {
        let mut rnd = rng(7);
        let mut p: [[DVec3; 4]; 2] = std::array::from_fn(|_| random_quad(&mut rnd));
        p[0][3] = p[0][2]; // zero-length hinge
        let mut x = quads(&p);
        let before = x;
        let mut lambda = [0.0; 2];
        project::<Scalar128b, 2, false>(
            Scalar128b,
            &mut x,
            &before,
            &[[1.0; 2]; 4],
            &[1.0; 2],
            &Coefs::splat(Coef {
                k: 1.0,
                alpha: 0.0,
                gamma: 0.0,
            }),
            &mut lambda,
        );
        for v in 0..4 {
            for k in 0..3 {
                assert_eq!(x[v][k][0].to_bits(), before[v][k][0].to_bits());
            }
        }
        assert_eq!(lambda[0], 0.0);
        assert!(lambda[1] != 0.0);
    }
}
