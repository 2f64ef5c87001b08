//! The strategy a method plugs into the shared substep loop.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::DVec3;

use super::spring_work::SpringWork;
use crate::constraints::{ConstraintSet, Rule};
use crate::params::FamilyParams;
use crate::particles::Particles;
use crate::sparse::CgLimits;
use weft_simd::SimdPath;

/// The substep a force pass is for: its length, the linear solve's limits, and the flag that
/// abandons the frame.
#[derive(Clone, Copy)]
pub(crate) struct ForcePass<'a> {
    /// The substep h (s).
    pub h: f64,
    /// How far an implicit method's linear solve goes.
    pub cg: CgLimits,
    /// Raised to abandon the frame: a long solve stops early (see `Solver::set_stop`).
    pub stop: Option<&'a AtomicBool>,
    /// The kernel path of the lane passes.
    pub simd: SimdPath,
}

impl ForcePass<'_> {
    /// Whether the frame is being abandoned.
    pub fn stopping(&self) -> bool {
        self.stop.is_some_and(|f| f.load(Ordering::Relaxed))
    }
}

/// What distinguishes one method inside the shared substep loop.
pub(crate) trait Strategy: Sync {
    /// Adds internal (constraint) accelerations for the substep of `pass` before integration,
    /// on top of the external ones in `accel`; `work` is the state and scratch a method keeps
    /// between substeps.
    fn add_internal_forces(
        &self,
        _constraints: &ConstraintSet,
        _particles: &Particles,
        _params: &[FamilyParams],
        _pass: ForcePass<'_>,
        _work: &mut SpringWork,
        _accel: &mut [DVec3],
    ) {
    }

    /// Whether [`Strategy::add_internal_forces`] adds anything (the mass-spring methods); without
    /// internal forces the general loop computes the external accelerations inside its
    /// integration pass.
    fn has_internal_forces(&self) -> bool {
        false
    }

    /// Starts a substep.
    fn begin_substep(&self, _constraints: &mut ConstraintSet) {}

    /// How constraints are projected with substep `h`, or `None` when they are not projected.
    fn rule(&self, h: f64) -> Option<Rule>;
}
