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
use crate::constraints::{ConstraintSet, LinearState, RowSums, Rule, Springs, SystemIo};
use crate::params::FamilyParams;
use crate::particles::Particles;
use crate::sparse::{Operator, Outcome, Sym3, solve};
use weft_simd::SimdPath;

/// Springs integrated with backward Euler: unconditionally stable, numerically damped.
pub(crate) struct ImplicitMassSpring;

/// A = M + h D + h² K, filtered: zero on the rows of particles with inverse mass 0. M p is
/// formed as p (1/w), as the lanes of `constraints/ray_system.rs` form it from their masses.
struct System<'a> {
    constraints: &'a ConstraintSet,
    springs: &'a mut Springs,
    w: &'a [f64],
    simd: SimdPath,
}

impl Operator for System<'_> {
    fn apply(&mut self, p: &[DVec3], q: &mut [DVec3]) -> f64 {
        let w = self.w;
        q.par_chunks_mut(CHUNK).enumerate().for_each(|(c, q)| {
            for (j, q) in q.iter_mut().enumerate() {
                let i = c * CHUNK + j;
                *q = if w[i] > 0.0 {
                    p[i] * (1.0 / w[i])
                } else {
                    DVec3::ZERO
                };
            }
        });
        self.constraints
            .spring_product(self.springs, p, q, self.simd);
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
        let state = (particles, h, warm);
        let stopping = || pass.stopping();
        let SpringWork {
            springs,
            sums,
            pinv,
            r,
            dv,
            scratch,
            ..
        } = work;
        let outcome = match springs.sole_stencil() {
            // The stencil's springs alone: the whole solve in lanes.
            Some(stencil) => {
                stencil.load_state(params, linear_state(state, dv));
                let io = SystemIo { w, accel, dv };
                stencil.solve_system(io, warm, pass.cg, &stopping, pass.simd)
            }
            None => {
                pinv.resize(n, Sym3::default());
                r.resize(n, DVec3::ZERO);
                let system = (constraints, params, &mut *springs, pass.simd);
                let b_norm2 = general_rows(system, state, sums, (dv, r, pinv), accel);
                let mut system = System {
                    constraints,
                    springs,
                    w,
                    simd: pass.simd,
                };
                let outcome = solve(
                    &mut system,
                    pinv,
                    b_norm2,
                    dv,
                    r,
                    pass.cg,
                    scratch,
                    &stopping,
                );
                (accel.par_chunks_mut(CHUNK))
                    .zip(dv.par_chunks(CHUNK).zip(w.par_chunks(CHUNK)))
                    .for_each(|(a, (dv, w))| {
                        for ((a, dv), &w) in a.iter_mut().zip(dv).zip(w) {
                            if w > 0.0 {
                                *a = *dv / h;
                            }
                        }
                    });
                outcome
            }
        };
        record(work, outcome);
    }

    fn rule(&self, _h: f64) -> Option<Rule> {
        None
    }
}

/// Adds a solve's `outcome` to the frame's iterations and worst residual.
fn record(work: &mut SpringWork, outcome: Outcome) {
    work.iterations += outcome.iterations;
    work.worst = work.worst.max(outcome.residual);
    work.last = outcome;
}

/// The linearisation's state: the particles' positions and velocities, the substep and, when
/// `warm`, the warm start `x0`.
fn linear_state<'a>(
    (particles, h, warm): (&'a Particles, f64, bool),
    x0: &'a [DVec3],
) -> LinearState<'a> {
    LinearState {
        x: &particles.positions,
        v: &particles.velocities,
        h,
        x0: warm.then_some(x0),
    }
}

/// The implicit system's rows by the general passes: each particle's row sums (M's share, then
/// every spring's), then r = b − A x₀ and the block-Jacobi inverse, zeros at filtered
/// particles (Baraff & Witkin's S). Returns ‖b‖², the chunks' sums added in order.
fn general_rows(
    (constraints, params, springs, simd): (&ConstraintSet, &[FamilyParams], &mut Springs, SimdPath),
    state: (&Particles, f64, bool),
    sums: &mut Vec<RowSums>,
    (dv, r, pinv): (&mut [DVec3], &mut [DVec3], &mut [Sym3]),
    accel: &[DVec3],
) -> f64 {
    let (particles, h, _) = state;
    let (n, w) = (particles.len(), &particles.inv_masses[..]);
    // Each row starts with M's share: b = h M a_ext, M x₀ and M; the springs add theirs.
    sums.resize(n, RowSums::default());
    sums.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, sums)| {
            for (j, row) in sums.iter_mut().enumerate() {
                let i = c * CHUNK + j;
                *row = RowSums::of_mass(w[i], accel[i], dv[i], h);
            }
        });
    constraints.linearize(params, linear_state(state, dv), springs, sums, simd);
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
                bb += sums_ref[i].finish(w[i], &mut r[j], &mut pinv[j], &mut dv[j]);
            }
            bb
        })
        .collect();
    partials.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::linear_tests::{crumpled, reference_all, stretched};
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

    /// The grid's distance springs alone: a stencil that holds every spring.
    fn distance_only(cs: &ConstraintSet) -> ConstraintSet {
        ConstraintSet {
            distance: cs.distance.clone(),
            ..ConstraintSet::default()
        }
    }

    /// The crumpled grid's particles, two of them pinned.
    fn pinned(x: Vec<DVec3>, v: Vec<DVec3>) -> Particles {
        let mut w = vec![100.0; x.len()];
        w[0] = 0.0;
        w[9] = 0.0;
        Particles {
            prev_positions: x.clone(),
            positions: x,
            velocities: v,
            inv_masses: w,
        }
    }

    /// A substep of 1/600 s solved down to `tolerance`.
    fn pass(tolerance: f64) -> ForcePass<'static> {
        ForcePass {
            h: 1.0 / 600.0,
            cg: CgLimits {
                max_iterations: 500,
                tolerance,
            },
            stop: None,
            simd: SimdPath::widest(),
        }
    }

    #[test]
    fn each_solve_reaches_its_tolerance_and_the_warm_start_pays() {
        let (all, params, x, v) = crumpled(Family::BendIsometric);
        // Every family (the distance springs by stencil, the rest by the general passes), and
        // the distance springs alone (the system in one pass).
        for (cs, sole) in [(all.clone(), false), (distance_only(&all), true)] {
            let p = pinned(x.clone(), v.clone());
            solves_reach_their_tolerance(&cs, &params, &p, sole);
        }
    }

    /// Three solves of one system, to 10⁻⁴, 10⁻⁸ and again 10⁻⁸ from its own solution.
    fn solves_reach_their_tolerance(
        cs: &ConstraintSet,
        params: &[FamilyParams],
        p: &Particles,
        sole: bool,
    ) {
        let n = p.len();
        let (h, g) = (1.0 / 600.0, DVec3::new(0.0, -9.81, 0.0));
        let mut work = SpringWork::default();
        let mut iterations = Vec::new();
        for tolerance in [1e-4, 1e-8, 1e-8] {
            let mut accel = vec![g; n];
            let pass = pass(tolerance);
            ImplicitMassSpring.add_internal_forces(cs, p, params, pass, &mut work, &mut accel);
            assert_eq!(work.springs.sole_stencil().is_some(), sole);
            let dv: Vec<DVec3> = (0..n)
                .map(|i| {
                    if p.inv_masses[i] > 0.0 {
                        accel[i] * h
                    } else {
                        DVec3::ZERO
                    }
                })
                .collect();
            let r = true_residual(cs, params, p, g, h, &dv);
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

    #[test]
    fn the_one_pass_system_gives_the_composed_passes_bits_on_any_thread_count() {
        // Three chunks of particles, so that the chunks' windows overlap.
        let (all, params, x, v) = stretched(Family::BendIsometric, 0.02, 48);
        let (cs, mut p) = (distance_only(&all), pinned(x, v));
        // A pinned particle in a later chunk, inside a lane group.
        p.inv_masses[2053] = 0.0;
        let g = DVec3::new(0.0, -9.81, 0.0);
        let run = |threads: usize, composed: bool| -> Vec<u64> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| {
                let mut work = SpringWork::default();
                if composed {
                    work.springs.without_system_passes();
                }
                // A cold solve, then two warm ones under other loads.
                let mut bits = Vec::new();
                for k in 0..3 {
                    let mut accel = vec![g * (1.0 + k as f64); p.len()];
                    let pass = pass(1e-8);
                    ImplicitMassSpring
                        .add_internal_forces(&cs, &p, &params, pass, &mut work, &mut accel);
                    assert!(work.last.iterations > 2, "{:?}", work.last);
                    bits.extend(accel.iter().flat_map(|a| a.to_array().map(f64::to_bits)));
                }
                assert_eq!(work.springs.sole_stencil().is_none(), composed);
                bits
            })
        };
        let one_pass = run(1, false);
        assert_eq!(one_pass, run(2, false), "1 and 2 threads");
        assert_eq!(
            one_pass,
            run(1, true),
            "the one-pass system and the composed passes"
        );
    }
}
