//! The distance-constraint projection written over `L` independent lanes at once.
//!
//! One generic step ([`scale`]) serves the SIMD chunks of a domain's sweep (f32 lanes on rebased
//! positions, loaded with unit-stride, paired or gathered loads), its scalar remainder (`L = 1`)
//! and the links between domains ([`project`], f64). Every lane runs the same IEEE operations
//! in the same order, so a constraint gets bit-identical results whichever path projects it;
//! that is what keeps runs independent of the thread count and of how constraints fall into
//! chunks.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use super::Rule;
use crate::params::FamilyParams;

/// Constraints per SIMD chunk (8 × f32: one AVX2 register, two SSE2 or NEON ones).
pub(crate) const LANES: usize = 8;

/// Positions of the four particles of `L` constraints, `[particle][axis][lane]`, in the
/// order `[wing_a, wing_b, edge_0, edge_1]` of [`Dihedral`] and [`Isometric`].
pub(crate) type Quads<const L: usize> = [[[f64; L]; 3]; 4];

/// Per-group coefficients of the unified multiplier step (see [`project`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Coef {
    /// Stiffness factor k on C: 1 for XPBD, the family's stiffness for PBD, 0 when disabled.
    pub k: f64,
    /// Time-step compliance α̃ = α/h² (XPBD; 0 for PBD, 1 when disabled).
    pub alpha: f64,
    /// Damping γ = α β / h (XPBD, Macklin et al. 2016 eq. 26; 0 for PBD).
    pub gamma: f64,
}

impl Coef {
    /// The coefficients of a family with parameters `p` under `rule`. A disabled family gets
    /// k = 0, α̃ = 1, γ = 0, which leaves its constraints (whose λ stays 0) where they are.
    pub fn of(p: &FamilyParams, rule: Rule) -> Self {
        match (p.enabled, rule) {
            (false, _) => Self {
                k: 0.0,
                alpha: 1.0,
                gamma: 0.0,
            },
            (true, Rule::Xpbd { h }) => {
                let (alpha, gamma) = Rule::xpbd_terms(p, h);
                Self {
                    k: 1.0,
                    alpha,
                    gamma,
                }
            }
            (true, Rule::Pbd) => Self {
                k: p.pbd_stiffness,
                alpha: 0.0,
                gamma: 0.0,
            },
        }
    }
}

/// The lane type of the distance kernel: f64 (global positions, links) or f32 (a domain's
/// rebased positions, see `domains::sweep`). Both are IEEE types whose `+ − × ÷ √` round
/// correctly, so every vector width gives the same bits.
pub(crate) trait Real:
    Copy
    + Default
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// Lengths below this (1e-9 m) leave a constraint alone.
    const MIN_LEN: Self;
    /// The smallest positive normal value.
    const MIN_POSITIVE: Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// The nearest value to `v`.
    fn of(v: f64) -> Self;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const MIN_LEN: Self = 1e-9;
    const MIN_POSITIVE: Self = f64::MIN_POSITIVE;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn of(v: f64) -> Self {
        v
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const MIN_LEN: Self = 1e-9;
    const MIN_POSITIVE: Self = f32::MIN_POSITIVE;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn of(v: f64) -> Self {
        v as f32
    }
}

/// [`Coef`] for `L` lanes, struct-of-arrays, in lane type `T`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Coefs<const L: usize, T = f64> {
    /// k per lane.
    pub k: [T; L],
    /// α̃ per lane.
    pub alpha: [T; L],
    /// γ per lane.
    pub gamma: [T; L],
}

impl<const L: usize, T: Real> Coefs<L, T> {
    /// The same coefficients in every lane.
    #[inline(always)]
    pub fn splat(c: Coef) -> Self {
        Self {
            k: [T::of(c.k); L],
            alpha: [T::of(c.alpha); L],
            gamma: [T::of(c.gamma); L],
        }
    }

    /// Lane `l` gets `f(l)`.
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> Coef) -> Self {
        let c: [Coef; L] = std::array::from_fn(f);
        Self {
            k: std::array::from_fn(|l| T::of(c[l].k)),
            alpha: std::array::from_fn(|l| T::of(c[l].alpha)),
            gamma: std::array::from_fn(|l| T::of(c[l].gamma)),
        }
    }
}

/// Positions (and previous positions) of the two ends of `L` constraints, per axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ends<const L: usize> {
    /// First end, `[axis][lane]`.
    pub p: [[f64; L]; 3],
    /// Second end, `[axis][lane]`.
    pub q: [[f64; L]; 3],
}

/// Projects `L` independent distance constraints C = |p − q| − d in place (f64 positions:
/// links and single constraints); see [`scale`] for the step.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project<
    const L: usize,
    const DAMPED: bool,
    const LAMBDA: bool,
    const UNIT_K: bool,
>(
    x: &mut Ends<L>,
    prev: &Ends<L>,
    wp: &[f64; L],
    wq: &[f64; L],
    rest: &[f64; L],
    coef: &Coefs<L>,
    lambda: &mut [f64; L],
) {
    let mut d = [[0.0; L]; 3];
    let mut motion = [[0.0; L]; 3];
    for a in 0..3 {
        for l in 0..L {
            d[a][l] = x.p[a][l] - x.q[a][l];
        }
        if DAMPED {
            for l in 0..L {
                motion[a][l] = (x.p[a][l] - prev.p[a][l]) - (x.q[a][l] - prev.q[a][l]);
            }
        }
    }
    let s = scale::<f64, L, DAMPED, LAMBDA, UNIT_K>(&d, &motion, wp, wq, rest, coef, lambda);
    for a in 0..3 {
        for l in 0..L {
            x.p[a][l] += d[a][l] * (wp[l] * s[l]);
            x.q[a][l] -= d[a][l] * (wq[l] * s[l]);
        }
    }
}

/// The multiplier step of `L` independent distance constraints C = |p − q| − d, given each
/// lane's difference `d` = p − q and (read only when `DAMPED`) its relative motion
/// (x_p − x_p,prev) − (x_q − x_q,prev); updates λ and returns the factor s of the corrections
/// Δp = +w_p s (p − q), Δq = −w_q s (p − q).
///
/// Δλ = (−k C − α̃ λ − γ ∇C·(x − x_prev)) / ((1 + γ)(w_p + w_q) + α̃) and s = Δλ/|p − q|.
/// For XPBD (k = 1) this is Macklin et al. 2016 eq. (18) with the damping of eq. (26); for
/// PBD (α̃ = γ = 0) it is Müller et al. 2007 eq. (10), −k C / (w_p + w_q). Degenerate lanes
/// (|p − q| < 1e-9 or a zero denominator) get s = 0.
///
/// Every step is a straight loop over lanes with selects instead of branches, so that it
/// compiles to vector instructions; without damping the two divisions (by |p − q| and by the
/// denominator) are folded into one, s = num / (denom |p − q|).
///
/// Two terms can be left out where they cannot change a bit: without `LAMBDA` the caller
/// passes λ = +0 in every lane and every α̃ is finite, so α̃ λ = +0 and −k C − (+0) = −k C for
/// every value; with `UNIT_K` every lane has k = 1 (XPBD), and −1 · C = −C exactly. The
/// general form (`LAMBDA`, not `UNIT_K`) is right for any coefficients.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn scale<
    T: Real,
    const L: usize,
    const DAMPED: bool,
    const LAMBDA: bool,
    const UNIT_K: bool,
>(
    d: &[[T; L]; 3],
    motion: &[[T; L]; 3],
    wp: &[T; L],
    wq: &[T; L],
    rest: &[T; L],
    coef: &Coefs<L, T>,
    lambda: &mut [T; L],
) -> [T; L] {
    let mut len = [T::ZERO; L];
    for l in 0..L {
        len[l] = (d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l]).sqrt();
    }
    let mut scale = [T::ZERO; L];
    if DAMPED {
        let mut grad_dx = [T::ZERO; L];
        for a in 0..3 {
            for l in 0..L {
                grad_dx[l] += d[a][l] * motion[a][l];
            }
        }
        for l in 0..L {
            let inv = T::ONE / len[l];
            let c = len[l] - rest[l];
            let denom = (T::ONE + coef.gamma[l]) * (wp[l] + wq[l]) + coef.alpha[l];
            let num = stiffness_term::<T, LAMBDA, UNIT_K>(c, coef.k[l], coef.alpha[l], lambda[l])
                - coef.gamma[l] * (grad_dx[l] * inv);
            let ok = (len[l] >= T::MIN_LEN) & (denom > T::MIN_POSITIVE);
            let dl = if ok { num / denom } else { T::ZERO };
            lambda[l] += dl;
            scale[l] = if ok { dl * inv } else { T::ZERO };
        }
    } else {
        for l in 0..L {
            let c = len[l] - rest[l];
            let denom = (wp[l] + wq[l]) + coef.alpha[l];
            let num = stiffness_term::<T, LAMBDA, UNIT_K>(c, coef.k[l], coef.alpha[l], lambda[l]);
            let ok = (len[l] >= T::MIN_LEN) & (denom > T::MIN_POSITIVE);
            let s = num / (denom * len[l]);
            scale[l] = if ok { s } else { T::ZERO };
            lambda[l] += scale[l] * len[l];
        }
    }
    scale
}

/// −k C − α̃ λ, the numerator of Δλ before damping, with the terms [`project`]'s `LAMBDA`
/// and `UNIT_K` leave out.
#[inline(always)]
fn stiffness_term<T: Real, const LAMBDA: bool, const UNIT_K: bool>(
    c: T,
    k: T,
    alpha: T,
    lambda: T,
) -> T {
    let kc = if UNIT_K { -c } else { -k * c };
    if LAMBDA { kc - alpha * lambda } else { kc }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rng;

    fn ends<const L: usize>(p: [[f64; 3]; L], q: [[f64; 3]; L]) -> Ends<L> {
        Ends {
            p: std::array::from_fn(|a| std::array::from_fn(|l| p[l][a])),
            q: std::array::from_fn(|a| std::array::from_fn(|l| q[l][a])),
        }
    }

    #[test]
    fn a_rigid_pair_of_equal_masses_meets_its_rest_length_symmetrically() {
        let mut x = ends([[0.0, 0.0, 0.0]], [[2.0, 0.0, 0.0]]);
        let prev = x;
        let coef = Coefs::splat(Coef {
            k: 1.0,
            alpha: 0.0,
            gamma: 0.0,
        });
        let mut lambda = [0.0];
        project::<1, false, true, false>(&mut x, &prev, &[1.0], &[1.0], &[1.0], &coef, &mut lambda);
        assert!((x.p[0][0] - 0.5).abs() < 1e-15);
        assert!((x.q[0][0] - 1.5).abs() < 1e-15);
        // λ = −C/(w_p + w_q) = −1/2.
        assert!((lambda[0] + 0.5).abs() < 1e-15);
    }

    #[test]
    fn a_compliant_pair_moves_by_c_over_w_plus_alpha() {
        // Δλ = −C/(w + α̃): C = 1, w = 1 (q pinned), α̃ = 1 → p moves 0.5 toward q.
        let mut x = ends([[0.0, 0.0, 0.0]], [[0.0, 2.0, 0.0]]);
        let prev = x;
        let coef = Coefs::splat(Coef {
            k: 1.0,
            alpha: 1.0,
            gamma: 0.0,
        });
        let mut lambda = [0.0];
        project::<1, false, true, false>(&mut x, &prev, &[1.0], &[0.0], &[1.0], &coef, &mut lambda);
        assert!((x.p[1][0] - 0.5).abs() < 1e-15);
        assert_eq!(x.q[1][0], 2.0);
    }

    #[test]
    fn lanes_agree_bit_for_bit_with_one_lane_at_a_time() {
        let mut rnd = rng(0x2545_f491_4f6c_dd1du64);
        let p: [[f64; 3]; LANES] = std::array::from_fn(|_| [rnd(), rnd(), rnd()]);
        let q: [[f64; 3]; LANES] = std::array::from_fn(|_| [rnd(), rnd(), rnd()]);
        let prev = ends(q, p);
        let wp: [f64; LANES] = std::array::from_fn(|_| rnd() + 0.5);
        let wq: [f64; LANES] = std::array::from_fn(|l| if l == 3 { 0.0 } else { rnd() + 0.5 });
        let rest: [f64; LANES] = std::array::from_fn(|_| rnd() + 0.5);
        let coef: [Coef; LANES] = std::array::from_fn(|_| Coef {
            k: 1.0,
            alpha: rnd().abs(),
            gamma: rnd().abs(),
        });
        let coefs = Coefs::from_fn(|l| coef[l]);
        let mut wide = ends(p, q);
        let mut lambda: [f64; LANES] = std::array::from_fn(|_| rnd());
        let lambda0 = lambda;
        project::<LANES, true, true, false>(&mut wide, &prev, &wp, &wq, &rest, &coefs, &mut lambda);
        for l in 0..LANES {
            let mut one = ends([p[l]], [q[l]]);
            let prev1 = ends([q[l]], [p[l]]);
            let mut lam = [lambda0[l]];
            project::<1, true, true, false>(
                &mut one,
                &prev1,
                &[wp[l]],
                &[wq[l]],
                &[rest[l]],
                &Coefs::splat(coef[l]),
                &mut lam,
            );
            for a in 0..3 {
                assert_eq!(one.p[a][0].to_bits(), wide.p[a][l].to_bits());
                assert_eq!(one.q[a][0].to_bits(), wide.q[a][l].to_bits());
            }
            assert_eq!(lam[0].to_bits(), lambda[l].to_bits());
        }
    }

    /// A [`project`] instance over [`LANES`] lanes.
    type Kernel = fn(
        &mut Ends<LANES>,
        &Ends<LANES>,
        &[f64; LANES],
        &[f64; LANES],
        &[f64; LANES],
        &Coefs<LANES>,
        &mut [f64; LANES],
    );

    /// Runs every specialised form on the same random lanes as the general one, with λ = +0
    /// (what a sweep without multipliers passes) and k = 1 (XPBD), and compares bits.
    #[test]
    fn the_forms_without_lambda_or_k_give_the_general_bits() {
        let mut rnd = rng(0x9e37_79b9_7f4a_7c15u64);
        for round in 0..64 {
            let p: [[f64; 3]; LANES] = std::array::from_fn(|_| [rnd(), rnd(), rnd()]);
            let q: [[f64; 3]; LANES] = std::array::from_fn(|_| [rnd(), rnd(), rnd()]);
            let prev = ends(q, p);
            let wp: [f64; LANES] = std::array::from_fn(|l| if l == 2 { 0.0 } else { rnd() + 0.5 });
            let wq: [f64; LANES] = std::array::from_fn(|l| if l == 5 { 0.0 } else { rnd() + 0.5 });
            let rest: [f64; LANES] = std::array::from_fn(|_| rnd() + 0.5);
            // Half the rounds stiff (α̃ = 0, as a sweep without multipliers has), half not.
            let coef: [Coef; LANES] = std::array::from_fn(|l| Coef {
                k: 1.0,
                alpha: if round % 2 == 0 {
                    0.0
                } else {
                    (rnd() + 0.5) * l as f64
                },
                gamma: if round % 4 < 2 { 0.0 } else { rnd().abs() },
            });
            let coefs = Coefs::from_fn(|l| coef[l]);
            let run = |f: Kernel| {
                let mut x = ends(p, q);
                let mut lambda = [0.0; LANES];
                f(&mut x, &prev, &wp, &wq, &rest, &coefs, &mut lambda);
                let bits = |v: &[[f64; LANES]; 3]| v.map(|a| a.map(f64::to_bits));
                (bits(&x.p), bits(&x.q), lambda.map(f64::to_bits))
            };
            let general = run(project::<LANES, true, true, false>);
            assert_eq!(
                run(project::<LANES, true, false, false>),
                general,
                "round {round}"
            );
            assert_eq!(
                run(project::<LANES, true, true, true>),
                general,
                "round {round}"
            );
            assert_eq!(
                run(project::<LANES, true, false, true>),
                general,
                "round {round}"
            );
            if round % 4 < 2 {
                // γ = 0: the undamped forms too.
                let undamped = run(project::<LANES, false, true, false>);
                assert_eq!(run(project::<LANES, false, false, false>), undamped);
                assert_eq!(run(project::<LANES, false, true, true>), undamped);
                assert_eq!(run(project::<LANES, false, false, true>), undamped);
            }
        }
    }
}
