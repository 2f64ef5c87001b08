//! Shared test helpers: a hook that wraps the collision world and checks every substep, and
//! (`split`) a scene's self-collision timed in a world of its own.
#![allow(dead_code)]

pub mod split;

use weft_collide::CollisionWorld;
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothMesh, Edge, GridDesc, Mass, Orientation, Particles, Pin, Solver, SubstepContext,
    SubstepHook,
};

/// A 0.8 m, 0.2 kg curtain of `n` × `n` particles hanging in the x–y plane (z = 0) from its
/// pinned top edge at y = 1.
pub fn hanging_curtain(n: usize) -> ClothMesh {
    GridDesc {
        resolution: (n, n),
        size: (0.8, 0.8),
        center: DVec3::new(0.0, 0.6, 0.0),
        orientation: Orientation::Vertical,
        mass: Mass::Total(0.2),
        pins: vec![Pin::Edge(Edge::Top)],
    }
    .build()
    .expect("grid")
}

/// Runs the world, then calls `check` after every substep with the final positions.
pub struct Watch<'a, F: FnMut(&SubstepContext, &Particles) + Send> {
    /// The wrapped world.
    pub world: &'a mut CollisionWorld,
    /// Called at the end of every substep.
    pub check: F,
}

impl<F: FnMut(&SubstepContext, &Particles) + Send> SubstepHook for Watch<'_, F> {
    fn begin_substep(&mut self, ctx: &SubstepContext, particles: &Particles) {
        self.world.begin_substep(ctx, particles);
    }

    fn project(&mut self, ctx: &SubstepContext, particles: &mut Particles) -> usize {
        self.world.project(ctx, particles)
    }

    fn end_substep(&mut self, ctx: &SubstepContext, particles: &mut Particles) {
        self.world.end_substep(ctx, particles);
        (self.check)(ctx, particles);
    }
}

/// Steps `frames` frames, checking every substep.
pub fn run(
    solver: &mut Solver,
    world: &mut CollisionWorld,
    frames: usize,
    check: impl FnMut(&SubstepContext, &Particles) + Send,
) {
    let mut hook = Watch { world, check };
    for frame in 0..frames {
        if let Err(e) = solver.step_with(&mut hook) {
            panic!("frame {frame}: {e}");
        }
    }
}

/// Largest particle speed (m/s).
pub fn max_speed(p: &Particles) -> f64 {
    p.velocities.iter().map(|v| v.length()).fold(0.0, f64::max)
}
