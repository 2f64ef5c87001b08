//! Builds the solvers of a scene: one per method, cloths in name order.

use weft_collide::CollisionWorld;
use weft_solver::{Method, Motion, Settings, Solver, SolverBuilder, SolverError, StepStats};

use crate::error::{Origin, SceneError};
use crate::scene::Scene;

/// One solver of a scene and the cloths it holds.
#[derive(Debug)]
pub struct SolverGroup {
    /// The method of every cloth in it.
    pub method: Method,
    /// The solver.
    pub solver: Solver,
    /// Indices into [`Scene::cloths`], in the solver's cloth order.
    pub cloths: Vec<usize>,
    /// Colliders and self-collision acting on this solver, if any.
    pub world: Option<CollisionWorld>,
}

impl SolverGroup {
    /// Steps the solver one frame through its collision world (if any).
    pub fn step(&mut self) -> Result<StepStats, SolverError> {
        match self.world.as_mut() {
            Some(w) => self.solver.step_with(w),
            None => self.solver.step(),
        }
    }
}

impl Scene {
    /// Builds one solver per method (in [`Scene::methods`] order), each with its collision
    /// world, to be stepped in lockstep.
    pub fn build(&self) -> Result<Vec<SolverGroup>, SceneError> {
        let err = |key: String, e: &dyn std::fmt::Display| SceneError {
            origin: Origin::File {
                path: self.name.clone(),
                line: None,
            },
            key,
            message: e.to_string(),
        };
        let mut groups = Vec::new();
        for method in self.methods() {
            let settings = Settings {
                method,
                ..self.settings
            };
            let mut b =
                SolverBuilder::new(settings, self.forces).map_err(|e| err("sim".into(), &e))?;
            let mut members = Vec::new();
            for (i, c) in self.cloths.iter().enumerate() {
                if c.method != method {
                    continue;
                }
                let key = format!("cloth.{}", c.name);
                let idx = b
                    .add_cloth(c.name.clone(), &c.mesh, c.params, c.thickness)
                    .map_err(|e| err(key.clone(), &e))?;
                if c.motion != Motion::Static {
                    for &v in &c.mesh.pinned {
                        b.add_kinematic_pin(idx, v, c.motion)
                            .map_err(|e| err(key.clone(), &e))?;
                    }
                }
                members.push(i);
            }
            let solver = b.build();
            let world = self.collision_world(&solver, &members)?;
            groups.push(SolverGroup {
                method,
                solver,
                cloths: members,
                world,
            });
        }
        Ok(groups)
    }
}
