//! The seam through which collisions (or anything else) act inside each substep.

use crate::method::Method;
use crate::particles::Particles;

/// Where in the step loop a hook is being called.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubstepContext {
    /// The running method.
    pub method: Method,
    /// Simulated time at the end of this substep (s).
    pub time: f64,
    /// Substep length h (s).
    pub h: f64,
    /// Substep number inside the frame, from 0.
    pub substep: u32,
}

/// Acts on the particles inside every substep; the collision crate implements it.
///
/// Order in one substep: integrate (predict) → kinematic pins, driven pins
/// ([`crate::PinDriver`], evaluated at the substep's end time) and the grabbed particle placed
/// → [`SubstepHook::begin_substep`] → for each iteration: project constraints, then
/// [`SubstepHook::project`] → velocities from positions (driven pins: the driver's velocities)
/// → [`SubstepHook::end_substep`]. Mass-spring projects no constraints but still calls `project`
/// once, so contacts are handled by projection for every method.
///
/// A hook is `Send`: the whole frame, hook calls included, runs on one of rayon's threads.
pub trait SubstepHook: Send {
    /// After prediction: find contact candidates for this substep.
    fn begin_substep(&mut self, _ctx: &SubstepContext, _particles: &Particles) {}

    /// After each constraint sweep: move particles out of obstacles; returns the contact count.
    fn project(&mut self, _ctx: &SubstepContext, _particles: &mut Particles) -> usize {
        0
    }

    /// After velocities are derived from positions: velocity-level corrections.
    fn end_substep(&mut self, _ctx: &SubstepContext, _particles: &mut Particles) {}

    /// Whether the hook does anything; an inactive hook lets the solver fuse a substep's phases.
    fn is_active(&self) -> bool {
        true
    }
}

/// No hook: nothing but the cloth's own constraints.
impl SubstepHook for () {
    fn is_active(&self) -> bool {
        false
    }
}
