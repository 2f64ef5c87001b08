//! Shared test helpers: a hook that wraps the collision world and checks every substep, and
//! (`split`) a scene's self-collision timed in a world of its own.
//!
//! - `split`: a scene's collisions as two hooks, self-collision timed from outside.
//! - `watch`: a hook that runs the collision world and checks the particles after every substep.
#![allow(dead_code)]

pub mod split;
mod watch;

pub use watch::Watch;

use weft_collide::CollisionWorld;
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothMesh, Edge, GridDesc, Mass, Orientation, Particles, Pin, Solver, SubstepContext,
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

/// Steps `frames` frames, checking every substep.
pub fn run(
    solver: &mut Solver,
    world: &mut CollisionWorld,
    frames: usize,
    mut check: impl FnMut(&SubstepContext, &Particles) + Send,
) {
    let check = |ctx: &SubstepContext, p: &Particles, _: &CollisionWorld| check(ctx, p);
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
