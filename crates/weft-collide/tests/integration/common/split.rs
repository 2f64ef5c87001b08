//! A scene's collisions as two hooks, self-collision timed from outside: shared by the
//! self-collision timing test and the `self_collision_cost` example (included there by path).

use std::time::{Duration, Instant};

use weft_collide::{CollideError, CollisionWorld, SelfCollisionParams};
use weft_solver::{Particles, Solver, SubstepContext, SubstepHook};

/// Self-collision and colliders as two hooks, self-collision first (as inside one world),
/// with the time spent in the self-collision one.
pub struct Split {
    /// A world holding only self-collision (of cloth 0).
    pub own: CollisionWorld,
    /// The scene's colliders, without self-collision.
    pub colliders: CollisionWorld,
    /// Time spent inside `own`.
    pub spent: Duration,
}

impl Split {
    /// Splits a scene's world: `colliders` keeps its colliders, and self-collision with
    /// `params` moves to a world of its own.
    pub fn new(
        solver: &Solver,
        mut colliders: CollisionWorld,
        params: SelfCollisionParams,
    ) -> Result<Self, CollideError> {
        colliders.disable_self_collision();
        let mut own = CollisionWorld::new(solver);
        own.enable_self_collision(solver, &[0], params)?;
        Ok(Self {
            own,
            colliders,
            spent: Duration::ZERO,
        })
    }
}

impl SubstepHook for Split {
    fn begin_substep(&mut self, ctx: &SubstepContext, p: &Particles) {
        let t = Instant::now();
        self.own.begin_substep(ctx, p);
        self.spent += t.elapsed();
        self.colliders.begin_substep(ctx, p);
    }

    fn project(&mut self, ctx: &SubstepContext, p: &mut Particles) -> usize {
        let t = Instant::now();
        let own = self.own.project(ctx, p);
        self.spent += t.elapsed();
        own + self.colliders.project(ctx, p)
    }

    fn end_substep(&mut self, ctx: &SubstepContext, p: &mut Particles) {
        let t = Instant::now();
        self.own.end_substep(ctx, p);
        self.spent += t.elapsed();
        self.colliders.end_substep(ctx, p);
    }
}
