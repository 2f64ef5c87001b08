//! Preconditioned conjugate gradients on a filtered system (Baraff & Witkin 1998, §5.3,
//! "modified PCG", with z = 0 on the constrained rows): the operator and the preconditioner
//! are zero on the rows the filter fixes, so the iterates stay zero there.
//!
//! The solve stops once ‖r‖₂ ≤ tolerance · ‖b‖₂ (the plain residual of A x = b, so a caller
//! can check it independently), at the iteration cap, or when the frame is being abandoned. It
//! starts from the x it is given (warm start) and its residual r = b − A x.

use glam::DVec3;
use rayon::prelude::*;

use super::sym3::Sym3;
use super::vector::xpby;
use crate::chunk::CHUNK;

/// How far conjugate gradients go: at most `max_iterations`, down to ‖r‖ ≤ `tolerance` ‖b‖.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CgLimits {
    /// Iterations at most.
    pub max_iterations: u32,
    /// Relative residual ‖b − A x‖₂ / ‖b‖₂ to reach.
    pub tolerance: f64,
}

/// A symmetric positive (semi-)definite operator on particle vectors.
pub(crate) trait Operator {
    /// `q ← A p`; returns p·q summed in chunk order.
    fn apply(&mut self, p: &[DVec3], q: &mut [DVec3]) -> f64;
}

/// `p ← z + β p`, or `p ← z` without β.
pub(crate) fn direction(z: &[DVec3], beta: Option<f64>, p: &mut [DVec3]) {
    match beta {
        Some(beta) => xpby(z, beta, p),
        None => p.copy_from_slice(z),
    }
}

/// The passes of one preconditioned conjugate-gradient solve, over vectors a system holds
/// itself (x, r, z, p, q, the preconditioner P⁻¹), each sum taken in chunk order.
pub(crate) trait CgPasses {
    /// z = P⁻¹ r and p = z; returns (r·z, r·r).
    fn start(&mut self) -> (f64, f64);
    /// q ← A p; returns p·q.
    fn apply(&mut self) -> f64;
    /// x += α p, r −= α q, then z = P⁻¹ r; returns (r·z, r·r).
    fn step(&mut self, alpha: f64) -> (f64, f64);
    /// p ← z + β p.
    fn direction(&mut self, beta: f64);
}

/// What a solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Outcome {
    /// Iterations run.
    pub iterations: u32,
    /// ‖r‖₂ / ‖b‖₂ at the end, from the recurrence (0 when b = 0).
    pub residual: f64,
}

/// The solver's scratch vectors, kept between solves.
#[derive(Clone, Debug, Default)]
pub(crate) struct PcgScratch {
    z: Vec<DVec3>,
    p: Vec<DVec3>,
    q: Vec<DVec3>,
}

/// One row of z = P⁻¹ r: z = m r, with r·z and r·r added to `sums`.
#[inline(always)]
fn precondition_row(m: &Sym3, r: DVec3, z: &mut DVec3, sums: &mut (f64, f64)) {
    *z = m.mul(r);
    sums.0 += r.dot(*z);
    sums.1 += r.dot(r);
}

/// The chunks' (r·z, r·r) added in chunk order.
pub(crate) fn in_chunk_order(partials: Vec<(f64, f64)>) -> (f64, f64) {
    (partials.iter()).fold((0.0, 0.0), |(a, b), (c, d)| (a + c, b + d))
}

/// z = P⁻¹ r over the rows; returns (r·z, r·r), each summed in chunk order.
fn precondition(pinv: &[Sym3], r: &[DVec3], z: &mut [DVec3]) -> (f64, f64) {
    let partials = (z.par_chunks_mut(CHUNK))
        .zip(r.par_chunks(CHUNK))
        .zip(pinv.par_chunks(CHUNK))
        .map(|((z, r), m)| {
            let mut sums = (0.0, 0.0);
            for ((z, r), m) in z.iter_mut().zip(r).zip(m) {
                precondition_row(m, *r, z, &mut sums);
            }
            sums
        })
        .collect();
    in_chunk_order(partials)
}

/// One pass of an iteration: x += α p, r −= α q, then z = P⁻¹ r; returns (r·z, r·r), each
/// summed in chunk order (the bits of the update followed by [`precondition`]).
fn step(
    alpha: f64,
    [p, q]: [&[DVec3]; 2],
    x: &mut [DVec3],
    r: &mut [DVec3],
    pinv: &[Sym3],
    z: &mut [DVec3],
) -> (f64, f64) {
    let partials = (x.par_chunks_mut(CHUNK))
        .zip(r.par_chunks_mut(CHUNK))
        .zip(z.par_chunks_mut(CHUNK))
        .zip(p.par_chunks(CHUNK).zip(q.par_chunks(CHUNK)))
        .zip(pinv.par_chunks(CHUNK))
        .map(|((((x, r), z), (p, q)), m)| {
            let mut sums = (0.0, 0.0);
            for j in 0..x.len() {
                x[j] += p[j] * alpha;
                r[j] -= q[j] * alpha;
                precondition_row(&m[j], r[j], &mut z[j], &mut sums);
            }
            sums
        })
        .collect();
    in_chunk_order(partials)
}

/// Solves A x = b by PCG with the block preconditioner `pinv` (zero on the filtered rows),
/// from the given `x` and its residual `r` = b − A x (filtered); `b_norm2` = ‖b‖₂². Polls
/// `stopping` once per iteration.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve(
    op: &mut dyn Operator,
    pinv: &[Sym3],
    b_norm2: f64,
    x: &mut [DVec3],
    r: &mut [DVec3],
    limits: CgLimits,
    scratch: &mut PcgScratch,
    stopping: &dyn Fn() -> bool,
) -> Outcome {
    let n = x.len();
    let PcgScratch { z, p, q } = scratch;
    // Each is written whole before it is read (z by the preconditioner, p from z, q by the
    // operator): only the length is set.
    for v in [&mut *z, &mut *p, &mut *q] {
        v.resize(n, DVec3::ZERO);
    }
    let mut passes = Vectors {
        op,
        pinv,
        x,
        r,
        z,
        p,
        q,
    };
    iterate(&mut passes, b_norm2, limits, stopping)
}

/// The general system's vectors, one 3-vector a particle, and its operator.
struct Vectors<'a> {
    op: &'a mut dyn Operator,
    pinv: &'a [Sym3],
    x: &'a mut [DVec3],
    r: &'a mut [DVec3],
    z: &'a mut [DVec3],
    p: &'a mut [DVec3],
    q: &'a mut [DVec3],
}

impl CgPasses for Vectors<'_> {
    fn start(&mut self) -> (f64, f64) {
        let sums = precondition(self.pinv, self.r, self.z);
        direction(self.z, None, self.p);
        sums
    }

    fn apply(&mut self) -> f64 {
        self.op.apply(self.p, self.q)
    }

    fn step(&mut self, alpha: f64) -> (f64, f64) {
        let pq = [&*self.p, &*self.q];
        step(alpha, pq, self.x, self.r, self.pinv, self.z)
    }

    fn direction(&mut self, beta: f64) {
        direction(self.z, Some(beta), self.p);
    }
}

/// Conjugate gradients over `passes` (Baraff & Witkin's modified PCG): from their x and
/// r = b − A x, down to ‖r‖ ≤ tolerance · ‖b‖ (`b_norm2` = ‖b‖₂²), at most the cap; polls
/// `stopping` once per iteration.
pub(crate) fn iterate(
    passes: &mut dyn CgPasses,
    b_norm2: f64,
    limits: CgLimits,
    stopping: &dyn Fn() -> bool,
) -> Outcome {
    let (mut delta, mut rr) = passes.start();
    let target = limits.tolerance * limits.tolerance * b_norm2;
    let go_on = |rr: f64, iterations: u32| rr > target && iterations < limits.max_iterations;
    let mut iterations = 0;
    while go_on(rr, iterations) && !stopping() {
        let pq = passes.apply();
        if pq.is_nan() || pq <= 0.0 {
            break;
        }
        let alpha = delta / pq;
        let (next, next_rr) = passes.step(alpha);
        rr = next_rr;
        iterations += 1;
        if !go_on(rr, iterations) {
            // Done: the next direction would go unused.
            break;
        }
        let beta = next / delta;
        delta = next;
        passes.direction(beta);
    }
    let residual = if b_norm2 > 0.0 {
        (rr / b_norm2).sqrt()
    } else {
        0.0
    };
    Outcome {
        iterations,
        residual,
    }
}

#[cfg(test)]
mod tests {
    use super::super::vector::dot;
    use super::*;

    /// A 1-D Laplacian-like chain (diagonally dominant), row 0 filtered.
    struct Chain(usize);

    impl Operator for Chain {
        fn apply(&mut self, p: &[DVec3], q: &mut [DVec3]) -> f64 {
            let n = self.0;
            for i in 0..n {
                let left = if i > 0 { p[i - 1] } else { DVec3::ZERO };
                let right = if i + 1 < n { p[i + 1] } else { DVec3::ZERO };
                q[i] = if i == 0 {
                    DVec3::ZERO
                } else {
                    p[i] * 2.001 - left - right
                };
            }
            dot(p, q)
        }
    }

    fn pinv(n: usize) -> Vec<Sym3> {
        (0..n)
            .map(|i| {
                if i == 0 {
                    Sym3::default()
                } else {
                    Sym3::scaled_identity(1.0 / 2.001)
                }
            })
            .collect()
    }

    fn run(limits: CgLimits, stop: &dyn Fn() -> bool) -> (Vec<DVec3>, Outcome) {
        let n = 200;
        let mut b = vec![DVec3::new(1.0, -0.5, 0.25); n];
        b[0] = DVec3::ZERO;
        let mut x = vec![DVec3::ZERO; n];
        let mut r = b.clone();
        let b2 = dot(&b, &b);
        let out = solve(
            &mut Chain(n),
            &pinv(n),
            b2,
            &mut x,
            &mut r,
            limits,
            &mut PcgScratch::default(),
            stop,
        );
        (x, out)
    }

    #[test]
    fn the_residual_reaches_the_tolerance_and_the_filter_holds() {
        let limits = CgLimits {
            max_iterations: 1000,
            tolerance: 1e-9,
        };
        let (x, out) = run(limits, &|| false);
        assert!(out.residual <= 1e-9, "{out:?}");
        assert!(out.iterations > 10, "a chain of 200 needs many: {out:?}");
        assert_eq!(x[0], DVec3::ZERO, "the filtered row stays zero");
        // The true residual, computed afresh.
        let n = x.len();
        let mut ax = vec![DVec3::ZERO; n];
        Chain(n).apply(&x, &mut ax);
        let worst = (ax[1..].iter())
            .map(|a| (DVec3::new(1.0, -0.5, 0.25) - *a).length())
            .fold(0.0, f64::max);
        assert!(worst < 1e-7, "true residual {worst}");
    }

    #[test]
    fn the_fused_step_gives_the_update_and_preconditioner_bits() {
        // Over several chunks, with a filtered (zero) block among them.
        let n = 3 * CHUNK + 17;
        let v = |k: usize, s: f64| {
            let t = k as f64 * s;
            DVec3::new(t.sin(), (1.3 * t).cos(), (0.7 * t).sin() - 0.2)
        };
        let (p, q): (Vec<DVec3>, Vec<DVec3>) = (0..n).map(|k| (v(k, 0.31), v(k, 0.17))).unzip();
        let pinv: Vec<Sym3> = (0..n)
            .map(|k| match k % 97 {
                0 => Sym3::default(),
                _ => Sym3::scaled_identity(1.0 + (k % 5) as f64)
                    .add(Sym3::outer(v(k, 0.05), 0.3))
                    .inverse(),
            })
            .collect();
        let alpha = 0.37;
        let (mut x, mut r) = ((0..n).map(|k| v(k, 0.11)).collect::<Vec<_>>(), q.clone());
        r.iter_mut().enumerate().for_each(|(k, r)| *r += v(k, 0.23));
        let (mut x2, mut r2, mut z, mut z2) = (
            x.clone(),
            r.clone(),
            vec![DVec3::ZERO; n],
            vec![DVec3::ZERO; n],
        );
        let fused = step(alpha, [&p, &q], &mut x, &mut r, &pinv, &mut z);
        for k in 0..n {
            x2[k] += p[k] * alpha;
            r2[k] -= q[k] * alpha;
        }
        let apart = precondition(&pinv, &r2, &mut z2);
        assert_eq!(fused.0.to_bits(), apart.0.to_bits());
        assert_eq!(fused.1.to_bits(), apart.1.to_bits());
        assert_eq!((x, r, z), (x2, r2, z2));
    }

    #[test]
    fn the_cap_and_a_raised_stop_cut_the_solve_short() {
        let capped = CgLimits {
            max_iterations: 3,
            tolerance: 1e-12,
        };
        let (_, out) = run(capped, &|| false);
        assert_eq!(out.iterations, 3);
        assert!(out.residual > 1e-3);
        let polls = std::cell::Cell::new(0);
        let (_, out) = run(
            CgLimits {
                max_iterations: 1000,
                tolerance: 1e-12,
            },
            &|| {
                polls.set(polls.get() + 1);
                polls.get() > 4
            },
        );
        assert_eq!(out.iterations, 4, "polled once per iteration");
        let (x, out) = run(capped, &|| true);
        assert_eq!(out.iterations, 0);
        assert!(x.iter().all(|v| *v == DVec3::ZERO), "no iteration ran");
    }
}
