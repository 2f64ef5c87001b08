//! Mass-spring: constraint forces −(k C + c Ċ)∇C integrated with semi-implicit Euler.

use glam::DVec3;

use super::{ForcePass, SpringWork, Strategy};
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
        _work: &mut SpringWork,
        force: &mut [DVec3],
        accel: &mut [DVec3],
    ) {
        force.fill(DVec3::ZERO);
        constraints.spring_forces(&particles.positions, &particles.velocities, params, force);
        for ((a, f), w) in accel
            .iter_mut()
            .zip(force.iter())
            .zip(&particles.inv_masses)
        {
            *a += *f * *w;
        }
    }

    fn rule(&self, _h: f64) -> Option<Rule> {
        None
    }
}
