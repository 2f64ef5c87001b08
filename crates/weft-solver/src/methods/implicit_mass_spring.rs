//! Implicit mass-spring: backward Euler with one Newton step, solved by conjugate gradients
//! (Baraff & Witkin 1998, "Large steps in cloth simulation", §3 and §5).
//!
//! Each substep solves, for the velocity change Δv,
//!
//! ```text
//! (M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f + h ∂f/∂x v)          (Baraff & Witkin eq. 6)
//! ```
//!
//! with f the spring forces plus the external ones (gravity, wind; their Jacobians are left
//! out) and the spring Jacobians of [`crate::constraints::Springs`]. The system is solved by
//! preconditioned conjugate gradients (Jacobi), with Baraff & Witkin's constraint filter
//! (§5.3) fixing Δv = 0 at pinned, kinematic and grabbed particles (inverse mass 0). The shared
//! loop then applies v ← v + Δv, x ← x + h v. Every sum runs in particle or constraint order on
//! one thread, so the result does not depend on the thread count.

use glam::DVec3;

use super::{ForcePass, Strategy};
use crate::constraints::{ConstraintSet, Rule, Springs};
use crate::params::FamilyParams;
use crate::particles::Particles;

/// Conjugate-gradient iterations at most per substep.
pub(crate) const MAX_ITERATIONS: usize = 400;

/// Relative residual (in the preconditioned norm) at which conjugate gradients stop.
pub(crate) const TOLERANCE: f64 = 1e-8;

/// Springs integrated with backward Euler: unconditionally stable, numerically damped.
pub(crate) struct ImplicitMassSpring;

impl Strategy for ImplicitMassSpring {
    fn has_internal_forces(&self) -> bool {
        true
    }

    fn add_internal_forces(
        &self,
        constraints: &ConstraintSet,
        particles: &Particles,
        params: &[FamilyParams],
        pass: ForcePass<'_>,
        force: &mut [DVec3],
        accel: &mut [DVec3],
    ) {
        let h = pass.h;
        let n = particles.len();
        let (w, v) = (&particles.inv_masses, &particles.velocities);
        let mut springs = Springs::default();
        constraints.linearize(&particles.positions, v, params, &mut springs);
        force.fill(DVec3::ZERO);
        springs.add_forces(force);
        // b = h (f + h ∂f/∂x v) = h (M a_ext + f_springs) − h² K v, K = −∂f/∂x.
        let mut kv = vec![DVec3::ZERO; n];
        springs.add_product(1.0, 0.0, v, &mut kv);
        let free = |i: usize| w[i] > 0.0;
        let b: Vec<DVec3> = (0..n)
            .map(|i| {
                if free(i) {
                    (accel[i] / w[i] + force[i]) * h - kv[i] * (h * h)
                } else {
                    DVec3::ZERO
                }
            })
            .collect();
        // A = M + h D + h² K (D = −∂f/∂v); Jacobi preconditioner from its diagonal.
        let mut diag: Vec<f64> = (0..n)
            .map(|i| if free(i) { 1.0 / w[i] } else { 1.0 })
            .collect();
        springs.add_diagonal(h * h, h, &mut diag);
        let apply = |p: &[DVec3], out: &mut [DVec3]| {
            for i in 0..n {
                out[i] = if free(i) { p[i] / w[i] } else { DVec3::ZERO };
            }
            springs.add_product(h * h, h, p, out);
            filter(w, out);
        };
        let dv = conjugate_gradients(&apply, &b, &diag, w, &|| pass.stopping());
        for i in 0..n {
            if free(i) {
                accel[i] = dv[i] / h;
            }
        }
    }

    fn rule(&self, _h: f64) -> Option<Rule> {
        None
    }
}

/// Baraff & Witkin's filter S for fully constrained particles: zero where w = 0.
fn filter(w: &[f64], x: &mut [DVec3]) {
    for (x, &w) in x.iter_mut().zip(w) {
        if w <= 0.0 {
            *x = DVec3::ZERO;
        }
    }
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a.dot(*b)).sum()
}

/// Modified preconditioned conjugate gradients (Baraff & Witkin 1998, §5.3, with z = 0);
/// cut short once `stopping()` (the frame is being abandoned: a 1024² cloth's solve takes
/// seconds).
fn conjugate_gradients(
    apply: &dyn Fn(&[DVec3], &mut [DVec3]),
    b: &[DVec3],
    diag: &[f64],
    w: &[f64],
    stopping: &dyn Fn() -> bool,
) -> Vec<DVec3> {
    let n = b.len();
    let mut x = vec![DVec3::ZERO; n];
    let mut r = b.to_vec();
    filter(w, &mut r);
    let precondition = |r: &[DVec3], out: &mut [DVec3]| {
        for i in 0..n {
            out[i] = r[i] / diag[i];
        }
        filter(w, out);
    };
    let mut c = vec![DVec3::ZERO; n];
    precondition(&r, &mut c);
    let mut delta = dot(&r, &c);
    let target = TOLERANCE * TOLERANCE * delta;
    let mut q = vec![DVec3::ZERO; n];
    let mut s = vec![DVec3::ZERO; n];
    for _ in 0..MAX_ITERATIONS {
        if delta <= target || delta <= 0.0 || stopping() {
            break;
        }
        apply(&c, &mut q);
        let cq = dot(&c, &q);
        if cq <= 0.0 {
            break;
        }
        let alpha = delta / cq;
        for i in 0..n {
            x[i] += c[i] * alpha;
            r[i] -= q[i] * alpha;
        }
        precondition(&r, &mut s);
        let next = dot(&r, &s);
        let beta = next / delta;
        delta = next;
        for i in 0..n {
            c[i] = s[i] + c[i] * beta;
        }
        filter(w, &mut c);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_raised_stop_cuts_the_solve_short() {
        // A 1-D Laplacian-like system (diagonally dominant): CG needs many iterations.
        let n = 200;
        let apply = |p: &[DVec3], out: &mut [DVec3]| {
            for i in 0..n {
                let left = if i > 0 { p[i - 1] } else { DVec3::ZERO };
                let right = if i + 1 < n { p[i + 1] } else { DVec3::ZERO };
                out[i] = p[i] * 2.001 - left - right;
            }
        };
        let b = vec![DVec3::X; n];
        let (diag, w) = (vec![2.001; n], vec![1.0; n]);
        let polls = std::cell::Cell::new(0);
        let full = conjugate_gradients(&apply, &b, &diag, &w, &|| false);
        let cut = conjugate_gradients(&apply, &b, &diag, &w, &|| {
            polls.set(polls.get() + 1);
            polls.get() > 3
        });
        assert_eq!(
            polls.get(),
            4,
            "polled once per iteration, stopped at the fourth"
        );
        assert_ne!(full, cut, "three iterations do not solve it");
        let none = conjugate_gradients(&apply, &b, &diag, &w, &|| true);
        assert!(none.iter().all(|v| *v == DVec3::ZERO), "no iteration ran");
    }
}
