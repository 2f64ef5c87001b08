//! Builds the solvers of a scene: one per method, cloths in name order.

use std::sync::Arc;

use weft_character::AttachmentDriver;
use weft_character::skin::SkinAttachmentDriver;
use weft_collide::CollisionWorld;
use weft_solver::{
    Family, FamilyParams, Method, Motion, PinDriver, Settings, Solver, SolverBuilder, SolverError,
    StepStats,
};

use crate::collide::DelayedSelfCollision;
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
    /// Colliders, the character's body and self-collision acting on this solver, if any.
    pub world: Option<CollisionWorld>,
    /// Self-collision waiting for garment seams to close, if any.
    pub delayed_self_collision: Option<DelayedSelfCollision>,
}

impl SolverGroup {
    /// Steps the solver one frame through its collision world (if any); turns on delayed
    /// self-collision after the frame in which the seams closed.
    pub fn step(&mut self) -> Result<StepStats, SolverError> {
        let stats = match self.world.as_mut() {
            Some(w) => self.solver.step_with(w),
            None => self.solver.step(),
        }?;
        self.sew_done();
        Ok(stats)
    }

    /// Turns on delayed self-collision if its time has come (the current positions become
    /// its rest state).
    pub fn sew_done(&mut self) {
        if let Some(d) = &self.delayed_self_collision
            && self.solver.time() >= d.at - 1e-9
            && let Some(w) = self.world.as_mut()
        {
            // The cloths and parameters were checked when the scene was built.
            if d.contact.enable(w, &self.solver, &d.cloths).is_ok() {
                self.delayed_self_collision = None;
            }
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
                    .add_cloth_with_topology(
                        c.name.clone(),
                        &c.mesh,
                        &c.topology,
                        c.params,
                        c.thickness,
                    )
                    .map_err(|e| err(key.clone(), &e))?;
                if !c.seams.is_empty() {
                    let stretch = c.params.get(Family::Stretch);
                    let seam = FamilyParams {
                        spring_stiffness: stretch.spring_stiffness,
                        spring_damping: stretch.spring_damping,
                        damping: stretch.damping,
                        ..FamilyParams::seam_default()
                    };
                    b.add_seams(idx, &c.seams, c.seam_time, seam)
                        .map_err(|e| err(format!("{key}.seam_time"), &e))?;
                }
                if c.motion != Motion::Static {
                    for &v in &c.mesh.pinned {
                        if c.held.binary_search(&v).is_ok() {
                            continue;
                        }
                        b.add_kinematic_pin(idx, v, c.motion)
                            .map_err(|e| err(key.clone(), &e))?;
                    }
                }
                members.push(i);
            }
            let mut solver = b.build();
            self.attach(&mut solver, &members)?;
            let (world, delayed_self_collision) = self.collision_world(&solver, &members)?;
            groups.push(SolverGroup {
                method,
                solver,
                cloths: members,
                world,
                delayed_self_collision,
            });
        }
        Ok(groups)
    }
}

impl Scene {
    /// Drives each garment's attached vertices with its bones, or with the joints of a glTF
    /// model (one driver per cloth), bound at the solver's present time.
    fn attach(&self, solver: &mut Solver, members: &[usize]) -> Result<(), SceneError> {
        for (j, &i) in members.iter().enumerate() {
            let c = &self.cloths[i];
            if c.attachments.is_empty() {
                continue;
            }
            let err = |e: &dyn std::fmt::Display| SceneError {
                origin: Origin::File {
                    path: self.name.clone(),
                    line: None,
                },
                key: format!("cloth.{}.attach", c.name),
                message: e.to_string(),
            };
            let first = solver.cloths()[j].particles.start;
            let time = solver.time();
            let driver: Arc<dyn PinDriver> = if let Some(m) = &self.model {
                let attachments = m.bind(c, time).map_err(|e| err(&e))?;
                Arc::new(
                    SkinAttachmentDriver::new(m.skin.clone(), first, attachments)
                        .map_err(|e| err(&e))?,
                )
            } else if let Some(ch) = &self.character {
                let attachments = ch.bind(c, time).map_err(|e| err(&e))?;
                Arc::new(
                    AttachmentDriver::new(ch.character.clone(), first, attachments)
                        .map_err(|e| err(&e))?,
                )
            } else {
                continue;
            };
            solver.add_pin_driver(driver).map_err(|e| err(&e))?;
        }
        Ok(())
    }
}
