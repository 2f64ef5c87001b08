//! Mass-spring: constraint forces −(k C + c Ċ)∇C integrated with semi-implicit Euler.
//!
//! The forces are taken by slots ([`ConstraintSet::spring_force_slots`]): each spring's share
//! at each of its particles in parallel, then each particle's sum in parallel, in the serial
//! loop's order, so the result is the same whatever the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::{ForcePass, SpringWork, Strategy};
use crate::chunk::CHUNK;
use crate::constraints::{ConstraintSet, Rule};
use crate::params::FamilyParams;
use crate::particles::Particles;

/// Springs with stiffness in N/m, integrated explicitly: conditionally stable.
pub(crate) struct MassSpring;

impl Strategy for MassSpring {
    fn has_internal_forces(&self) -> bool {
        true
    }

    fn add_internal_forces(
        &self,
        constraints: &ConstraintSet,
        particles: &Particles,
        params: &[FamilyParams],
        _pass: ForcePass<'_>,
        work: &mut SpringWork,
        accel: &mut [DVec3],
    ) {
        let (x, v, w) = (
            &particles.positions,
            &particles.velocities,
            &particles.inv_masses,
        );
        work.ensure_rows(constraints, particles.len());
        constraints.spring_force_slots(x, v, params, &mut work.y);
        let (rows, y) = (&work.rows, &work.y);
        // a += f w with f the sum of the particle's slots (from zero, in ascending order).
        accel.par_chunks_mut(CHUNK).enumerate().for_each(|(c, a)| {
            for (j, a) in a.iter_mut().enumerate() {
                let i = c * CHUNK + j;
                *a += rows.sum(i, y, DVec3::ZERO) * w[i];
            }
        });
    }

    fn rule(&self, _h: f64) -> Option<Rule> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::linear_tests::crumpled;
    use crate::params::Family;
    use crate::sparse::CgLimits;
    use weft_simd::SimdPath;

    /// The slot pass's accelerations under a pool of `threads` threads.
    fn slot_accelerations(
        cs: &ConstraintSet,
        params: &[FamilyParams],
        p: &Particles,
        threads: usize,
    ) -> Vec<DVec3> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut accel = vec![DVec3::new(0.0, -9.81, 0.0); p.len()];
        let pass = ForcePass {
            h: 1e-3,
            cg: CgLimits {
                max_iterations: 1,
                tolerance: 1e-3,
            },
            stop: None,
            simd: SimdPath::widest(),
        };
        let mut work = SpringWork::default();
        pool.install(|| MassSpring.add_internal_forces(cs, p, params, pass, &mut work, &mut accel));
        accel
    }

    #[test]
    fn the_slot_pass_gives_the_serial_loops_bits_on_any_thread_count() {
        for bending in [Family::BendDihedral, Family::BendIsometric] {
            let (cs, mut params, x, v) = crumpled(bending);
            // A disabled family contributes nothing, in either pass.
            params[Family::Shear as usize].enabled = false;
            let w: Vec<f64> = (0..x.len()).map(|i| [0.0, 2.0, 0.5][i % 3]).collect();
            let p = Particles {
                prev_positions: x.clone(),
                positions: x,
                velocities: v,
                inv_masses: w,
            };
            let mut force = vec![DVec3::ZERO; p.len()];
            cs.spring_forces(&p.positions, &p.velocities, &params, &mut force);
            let serial: Vec<DVec3> = force
                .iter()
                .zip(&p.inv_masses)
                .map(|(f, w)| DVec3::new(0.0, -9.81, 0.0) + *f * *w)
                .collect();
            assert!(serial.iter().any(|a| (a.y + 9.81).abs() > 1.0));
            for threads in [1, 2, 4] {
                let slots = slot_accelerations(&cs, &params, &p, threads);
                let bits = |a: &[DVec3]| -> Vec<[u64; 3]> {
                    a.iter().map(|a| a.to_array().map(f64::to_bits)).collect()
                };
                assert_eq!(
                    bits(&slots),
                    bits(&serial),
                    "{bending:?}, {threads} threads"
                );
            }
        }
    }
}
