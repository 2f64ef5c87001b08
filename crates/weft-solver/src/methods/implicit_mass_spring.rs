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
//! conjugate gradients preconditioned by A's 3×3 diagonal blocks (block Jacobi), from the last
//! substep's Δv (warm start), down to ‖b − A Δv‖ ≤ `Settings::cg_tolerance` ‖b‖ or
//! `Settings::cg_max_iterations`. Baraff & Witkin's constraint filter (§5.3) fixes Δv = 0 at
//! pinned, kinematic and grabbed particles (inverse mass 0). The shared loop then applies
//! v ← v + Δv, x ← x + h v.
//!
//! A is never assembled: each product starts from M p and adds every spring's term to its
//! particles, part by part in parallel, each particle's terms in a fixed order (see
//! `constraints/linear.rs`); every sum across tasks is taken in a fixed order, so the result
//! does not depend on the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::{ForcePass, SpringWork, Strategy};
use crate::chunk::CHUNK;
use crate::constraints::{ConstraintSet, LinearState, RowSums, Rule, Springs};
use crate::params::FamilyParams;
use crate::particles::Particles;
use crate::sparse::{Operator, Sym3, solve};

/// Springs integrated with backward Euler: unconditionally stable, numerically damped.
pub(crate) struct ImplicitMassSpring;

/// A = M + h D + h² K, filtered: zero on the rows of particles with inverse mass 0.
struct System<'a> {
    constraints: &'a ConstraintSet,
    springs: &'a Springs,
    w: &'a [f64],
}

impl Operator for System<'_> {
    fn apply(&mut self, p: &[DVec3], q: &mut [DVec3]) -> f64 {
        let w = self.w;
        q.par_chunks_mut(CHUNK).enumerate().for_each(|(c, q)| {
            for (j, q) in q.iter_mut().enumerate() {
                let i = c * CHUNK + j;
                *q = if w[i] > 0.0 { p[i] / w[i] } else { DVec3::ZERO };
            }
        });
        self.constraints.spring_product(self.springs, p, q);
        let partials: Vec<f64> = q
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, q)| {
                let mut pq = 0.0;
                for (j, q) in q.iter_mut().enumerate() {
                    let i = c * CHUNK + j;
                    if w[i] > 0.0 {
                        pq += p[i].dot(*q);
                    } else {
                        *q = DVec3::ZERO;
                    }
                }
                pq
            })
            .collect();
        partials.iter().sum()
    }
}

impl Strategy for ImplicitMassSpring {
    fn has_internal_forces(&self) -> bool {
        true
    }

    /// About twenty short passes a substep, each a futex wake if the workers slept between.
    fn keeps_workers_awake(&self) -> bool {
        true
    }

    fn add_internal_forces(
        &self,
        constraints: &ConstraintSet,
        particles: &Particles,
        params: &[FamilyParams],
        pass: ForcePass<'_>,
        work: &mut SpringWork,
        accel: &mut [DVec3],
    ) {
        let h = pass.h;
        let n = particles.len();
        let w = &particles.inv_masses;
        work.prepare_implicit(constraints, n);
        let warm = work.dv.len() == n;
        if !warm {
            work.dv.clear();
            work.dv.resize(n, DVec3::ZERO);
        }
        let SpringWork {
            springs,
            sums,
            pinv,
            r,
            dv,
            scratch,
            ..
        } = work;
        // Each row starts with M's share: b = h M a_ext, M x₀ and M; the springs add theirs.
        sums.resize(n, RowSums::default());
        sums.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, sums)| {
                for (j, row) in sums.iter_mut().enumerate() {
                    let i = c * CHUNK + j;
                    let m = if w[i] > 0.0 { 1.0 / w[i] } else { 0.0 };
                    *row = RowSums {
                        b: accel[i] * (m * h),
                        ax: dv[i] * m,
                        d: Sym3::scaled_identity(m),
                    };
                }
            });
        let st = LinearState {
            x: &particles.positions,
            v: &particles.velocities,
            h,
            x0: warm.then_some(&dv[..]),
        };
        constraints.linearize(params, st, springs, sums);
        pinv.resize(n, Sym3::default());
        r.resize(n, DVec3::ZERO);
        // Per particle: r = b − A x₀ and the block-Jacobi inverse; filtered particles get zeros
        // (Baraff & Witkin's S).
        let sums_ref = &*sums;
        let partials: Vec<f64> = r
            .par_chunks_mut(CHUNK)
            .zip(pinv.par_chunks_mut(CHUNK))
            .zip(dv.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, ((r, pinv), dv))| {
                let mut bb = 0.0;
                for j in 0..r.len() {
                    let i = c * CHUNK + j;
                    if w[i] <= 0.0 {
                        (r[j], pinv[j], dv[j]) = (DVec3::ZERO, Sym3::default(), DVec3::ZERO);
                        continue;
                    }
                    let row = &sums_ref[i];
                    r[j] = row.b - row.ax;
                    pinv[j] = row.d.inverse();
                    bb += row.b.dot(row.b);
                }
                bb
            })
            .collect();
        let b_norm2: f64 = partials.iter().sum();
        let mut system = System {
            constraints,
            springs,
            w,
        };
        let outcome = solve(&mut system, pinv, b_norm2, dv, r, pass.cg, scratch, &|| {
            pass.stopping()
        });
        for ((a, dv), &w) in accel.iter_mut().zip(dv.iter()).zip(w) {
            if w > 0.0 {
                *a = *dv / h;
            }
        }
        work.iterations += outcome.iterations;
        work.worst = work.worst.max(outcome.residual);
        work.last = outcome;
    }

    fn rule(&self, _h: f64) -> Option<Rule> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::linear_tests::{crumpled, reference_all};
    use crate::params::Family;
    use crate::sparse::CgLimits;

    /// ‖b − A Δv‖ / ‖b‖ over the free particles, A and b from the serial reference springs.
    fn true_residual(
        cs: &ConstraintSet,
        params: &[FamilyParams],
        p: &Particles,
        g: DVec3,
        h: f64,
        dv: &[DVec3],
    ) -> f64 {
        let (x, v, w) = (&p.positions, &p.velocities, &p.inv_masses);
        let (adv, f) = reference_all(cs, params, x, v, (h * h, h), dv);
        let (kv, _) = reference_all(cs, params, x, v, (h * h, 0.0), v);
        let (mut rr, mut bb) = (0.0, 0.0);
        for i in 0..x.len() {
            if w[i] > 0.0 {
                let b = (g / w[i] + f[i]) * h - kv[i];
                let r = b - (dv[i] / w[i] + adv[i]);
                rr += r.dot(r);
                bb += b.dot(b);
            }
        }
        (rr / bb).sqrt()
    }

    #[test]
    fn each_solve_reaches_its_tolerance_and_the_warm_start_pays() {
        let (cs, params, x, v) = crumpled(Family::BendIsometric);
        let n = x.len();
        let mut w = vec![100.0; n];
        w[0] = 0.0;
        w[9] = 0.0;
        let p = Particles {
            prev_positions: x.clone(),
            positions: x,
            velocities: v,
            inv_masses: w,
        };
        let (h, g) = (1.0 / 600.0, DVec3::new(0.0, -9.81, 0.0));
        let mut work = SpringWork::default();
        let mut iterations = Vec::new();
        for tolerance in [1e-4, 1e-8, 1e-8] {
            let mut accel = vec![g; n];
            let pass = ForcePass {
                h,
                cg: CgLimits {
                    max_iterations: 500,
                    tolerance,
                },
                stop: None,
            };
            ImplicitMassSpring.add_internal_forces(&cs, &p, &params, pass, &mut work, &mut accel);
            let dv: Vec<DVec3> = (0..n)
                .map(|i| {
                    if p.inv_masses[i] > 0.0 {
                        accel[i] * h
                    } else {
                        DVec3::ZERO
                    }
                })
                .collect();
            let r = true_residual(&cs, &params, &p, g, h, &dv);
            assert!(
                r <= tolerance * 1.001,
                "tolerance {tolerance}: residual {r}"
            );
            assert!(work.last.residual <= tolerance, "{:?}", work.last);
            assert_eq!(
                accel[0], g,
                "a pinned particle's acceleration is left alone"
            );
            iterations.push(work.last.iterations);
        }
        assert!(iterations[1] > 3, "a real solve: {iterations:?}");
        assert!(
            iterations[2] < iterations[1],
            "the same system from its own solution: {iterations:?}"
        );
    }
}
