//! The dihedral-bending projection written over `L` independent lanes at once.
//!
//! As in [`super::lanes`], one generic function serves the SIMD chunks (`L` = the vector width)
//! and the scalar remainder (`L = 1`): every lane runs the same IEEE operations in the same
//! order, so a constraint gets bit-identical results whichever path projects it, and runs do
//! not depend on the thread count, the kernel path or how constraints fall into chunks.
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

use super::lanes::Coefs;

/// Positions of the four particles of `L` dihedrals, `[particle][axis][lane]`, in the
/// order `[wing_a, wing_b, edge_0, edge_1]` of [`super::Dihedral`].
pub(crate) type Quads<const L: usize> = [[[f64; L]; 3]; 4];

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

/// atan2(y, x) in every lane, without branches: Cephes' argument reduction of |y|/|x| to
/// |t| ≤ 0.66 (t = |y|/|x|, (|y| − |x|)/(|y| + |x|) around π/4 or −|x|/|y| near π/2, chosen
/// by comparing |y| with 0.66 |x| and tan(3π/8) |x|, so one division serves all three), the
/// rational approximation, then the quadrant from the signs. Within about 1 ulp of libm's
/// `atan2` (tested); atan2(0, 0) is 0, and the sign of a zero `x` is not looked at.
#[inline(always)]
pub(crate) fn atan2<const L: usize>(y: &[f64; L], x: &[f64; L]) -> [f64; L] {
    let mut out = [0.0; L];
    for l in 0..L {
        let (ay, ax) = (y[l].abs(), x[l].abs());
        let big = ay > TAN_3PI_8 * ax;
        let mid = ay > 0.66 * ax;
        let num = if big {
            -ax
        } else if mid {
            ay - ax
        } else {
            ay
        };
        let den = if big {
            ay
        } else if mid {
            ay + ax
        } else {
            ax
        };
        let (base, more) = if big {
            (FRAC_PI_2, MOREBITS)
        } else if mid {
            (FRAC_PI_4, 0.5 * MOREBITS)
        } else {
            (0.0, 0.0)
        };
        // 0/0 only when both are zero; a one there keeps the lane finite.
        let t = num / if den > 0.0 { den } else { 1.0 };
        let z = t * t;
        let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
        let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
        let r = base + ((t * (z * p / q) + t) + more);
        let r = if x[l] < 0.0 { PI - r } else { r };
        out[l] = if y[l] < 0.0 { -r } else { r };
    }
    out
}

/// Projects `L` independent dihedral constraints C = θ − θ₀ in place.
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
pub(crate) fn project<const L: usize, const DAMPED: bool>(
    x: &mut Quads<L>,
    prev: &Quads<L>,
    w: &[[f64; L]; 4],
    rest: &[f64; L],
    coef: &Coefs<L>,
    lambda: &mut [f64; L],
) {
    let sub = |a: usize, b: usize| -> [[f64; L]; 3] {
        std::array::from_fn(|k| std::array::from_fn(|l| x[a][k][l] - x[b][k][l]))
    };
    let cross = |u: &[[f64; L]; 3], v: &[[f64; L]; 3]| -> [[f64; L]; 3] {
        let mut c = [[0.0; L]; 3];
        for l in 0..L {
            c[0][l] = u[1][l] * v[2][l] - u[2][l] * v[1][l];
            c[1][l] = u[2][l] * v[0][l] - u[0][l] * v[2][l];
            c[2][l] = u[0][l] * v[1][l] - u[1][l] * v[0][l];
        }
        c
    };
    let dot = |u: &[[f64; L]; 3], v: &[[f64; L]; 3]| -> [f64; L] {
        std::array::from_fn(|l| u[0][l] * v[0][l] + u[1][l] * v[1][l] + u[2][l] * v[2][l])
    };
    let (a1, b1) = (sub(0, 2), sub(0, 3)); // x₁ − x₃, x₁ − x₄
    let (a2, b2) = (sub(1, 3), sub(1, 2)); // x₂ − x₄, x₂ − x₃
    let e = sub(3, 2);
    let (n1, n2) = (cross(&a1, &b1), cross(&a2, &b2));
    let (q1, q2, ee) = (dot(&n1, &n1), dot(&n2, &n2), dot(&e, &e));
    let mut ok = [false; L];
    let mut le = [0.0; L];
    for l in 0..L {
        le[l] = ee[l].sqrt();
        ok[l] = (q1[l] >= 1e-24) & (q2[l] >= 1e-24) & (le[l] >= 1e-9);
    }
    // θ = atan2((N₁ × N₂)·E, (N₁·N₂)|E|).
    let sin_part = dot(&cross(&n1, &n2), &e);
    let n12 = dot(&n1, &n2);
    let cos_part: [f64; L] = std::array::from_fn(|l| n12[l] * le[l]);
    let theta = atan2(&sin_part, &cos_part);
    let mut c = [0.0; L];
    for l in 0..L {
        let d = theta[l] - rest[l];
        c[l] = if d > PI {
            d - 2.0 * PI
        } else if d <= -PI {
            d + 2.0 * PI
        } else {
            d
        };
    }
    // m₁ = N₁/|N₁|², m₂ = N₂/|N₂|²; degenerate lanes divide by one instead.
    let mut inv_q1 = [0.0; L];
    let mut inv_q2 = [0.0; L];
    let mut inv_le = [0.0; L];
    for l in 0..L {
        inv_q1[l] = 1.0 / if ok[l] { q1[l] } else { 1.0 };
        inv_q2[l] = 1.0 / if ok[l] { q2[l] } else { 1.0 };
        inv_le[l] = 1.0 / if ok[l] { le[l] } else { 1.0 };
    }
    let (s13, s23) = (dot(&b1, &e), dot(&a2, &e)); // (x₁ − x₄)·E, (x₂ − x₄)·E
    let (t13, t23) = (dot(&a1, &e), dot(&b2, &e)); // (x₁ − x₃)·E, (x₂ − x₃)·E
    let mut g = [[[0.0; L]; 3]; 4];
    for k in 0..3 {
        for l in 0..L {
            let m1 = n1[k][l] * inv_q1[l];
            let m2 = n2[k][l] * inv_q2[l];
            g[0][k][l] = -(le[l] * m1);
            g[1][k][l] = -(le[l] * m2);
            g[2][k][l] = -((s13[l] * inv_le[l]) * m1 + (s23[l] * inv_le[l]) * m2);
            g[3][k][l] = (t13[l] * inv_le[l]) * m1 + (t23[l] * inv_le[l]) * m2;
        }
    }
    let mut w_grad2 = [0.0; L];
    let mut grad_dx = [0.0; L];
    // Σ |∇ᵢC|² max wᵢ: what Σ wᵢ|∇ᵢC|² would be if every particle moved freely.
    let mut g2_wmax = [[0.0; L]; 2];
    for v in 0..4 {
        for l in 0..L {
            let g2 = g[v][0][l] * g[v][0][l] + g[v][1][l] * g[v][1][l] + g[v][2][l] * g[v][2][l];
            w_grad2[l] += w[v][l] * g2;
            g2_wmax[0][l] += g2;
            g2_wmax[1][l] = g2_wmax[1][l].max(w[v][l]);
        }
        if DAMPED {
            for k in 0..3 {
                for l in 0..L {
                    grad_dx[l] += g[v][k][l] * (x[v][k][l] - prev[v][k][l]);
                }
            }
        }
    }
    let mut dl = [0.0; L];
    for l in 0..L {
        let gamma = coef.gamma[l];
        let denom = (1.0 + gamma) * w_grad2[l] + coef.alpha[l];
        let mut num = -coef.k[l] * c[l] - coef.alpha[l] * lambda[l];
        if DAMPED {
            num -= gamma * grad_dx[l];
        }
        // A constraint whose free particles barely move its angle (a free hinge particle
        // level with its pinned wings: ∇C there is ~0) would take a step of C/|∇C_free|, far
        // beyond the element, and shake a stiff pinned strip chaotically: it is left alone.
        let singular = w_grad2[l] <= 1e-12 * g2_wmax[0][l] * g2_wmax[1][l];
        let live = ok[l] & (denom > f64::MIN_POSITIVE) & !singular;
        dl[l] = if live { num / denom } else { 0.0 };
        lambda[l] += dl[l];
    }
    for v in 0..4 {
        for k in 0..3 {
            for l in 0..L {
                x[v][k][l] += g[v][k][l] * (w[v][l] * dl[l]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

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
            let got = atan2(&[y], &[x])[0];
            let want = y.atan2(x);
            let ulp = (want.abs().max(f64::MIN_POSITIVE) * f64::EPSILON).max(1e-300);
            worst = worst.max((got - want).abs() / ulp);
        }
        assert!(worst <= 2.0, "worst error {worst} ulp");
        assert_eq!(atan2(&[0.0], &[0.0]), [0.0]);
        assert_eq!(atan2(&[0.0], &[-1.0]), [PI]);
        assert_eq!(atan2(&[1.0], &[0.0]), [FRAC_PI_2]);
        assert_eq!(atan2(&[-1.0], &[0.0]), [-FRAC_PI_2]);
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
        const L: usize = 8;
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
            project::<L, true>(
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
                project::<1, true>(
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
            if damped {
                project::<L, true>(&mut x, &quads(&p), &w, &rest, &coef, &mut lambda);
            } else {
                project::<L, false>(&mut x, &quads(&p), &w, &rest, &coef, &mut lambda);
            }
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
        project::<1, false>(
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
        project::<1, false>(
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
        project::<2, false>(
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
