//! A hook that runs the collision world and checks the particles after every substep (shared
//! with weft-scene's and weft-character's tests, which include this file by path).

use weft_collide::CollisionWorld;
use weft_solver::{Particles, SubstepContext, SubstepHook};

/// Runs the world, then calls `check` after every substep with the final positions and the
/// world (whose colliders are then at the substep's end pose).
pub struct Watch<'a, F: FnMut(&SubstepContext, &Particles, &CollisionWorld) + Send> {
    /// The wrapped world.
    pub world: &'a mut CollisionWorld,
    /// Called at the end of every substep.
    pub check: F,
}

impl<F: FnMut(&SubstepContext, &Particles, &CollisionWorld) + Send> SubstepHook for Watch<'_, F> {
    fn begin_substep(&mut self, ctx: &SubstepContext, particles: &Particles) {
        self.world.begin_substep(ctx, particles);
    }

    fn project(&mut self, ctx: &SubstepContext, particles: &mut Particles) -> usize {
        self.world.project(ctx, particles)
    }

    fn end_substep(&mut self, ctx: &SubstepContext, particles: &mut Particles) {
        self.world.end_substep(ctx, particles);
        (self.check)(ctx, particles, self.world);
    }
}
