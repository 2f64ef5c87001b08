//! Wires a scene's colliders and self-collision to `weft-collide`: one collision world per
//! solver, holding every collider (colliders are f64 here, rounded to f32 inside parry).

use std::sync::Arc;

use weft_collide::{
    ClothContactParams, CollideError, ColliderDesc, CollisionWorld, Friction, KinematicBody,
    MeshAnimation, SelfCollisionParams,
};
use weft_solver::Solver;

use crate::error::{Origin, SceneError};
use crate::scene::{ColliderSpec, Scene};
use crate::schema::ContactKind;

/// Self-collision to turn on once a garment's seams have closed.
#[derive(Clone, Debug)]
pub struct DelayedSelfCollision {
    /// Solver time at which to turn it on (s): the latest seam closing time.
    pub at: f64,
    /// The solver's cloths that take part.
    pub cloths: Vec<usize>,
    /// Its kind and parameters.
    pub contact: SelfContact,
}

/// What keeps a scene's cloths apart, with its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SelfContact {
    /// Particle–particle self-collision.
    Particles(SelfCollisionParams),
    /// Mesh-level cloth contact.
    Mesh(ClothContactParams),
}

impl SelfContact {
    /// Turns it on in `world` among `cloths` of `solver` (their present positions the rest
    /// state).
    pub fn enable(
        &self,
        world: &mut CollisionWorld,
        solver: &Solver,
        cloths: &[usize],
    ) -> Result<(), CollideError> {
        match *self {
            Self::Particles(p) => world.enable_self_collision(solver, cloths, p),
            Self::Mesh(p) => world.enable_cloth_contact(solver, cloths, p),
        }
    }
}

/// The collision crate's description of a collider (the shape is already in its form).
pub fn collider_desc(c: &ColliderSpec) -> ColliderDesc {
    ColliderDesc::new(c.shape.clone())
        .at(c.position)
        .rotated(c.rotation)
        .moving(c.motion)
        .with_friction(Friction::new(c.static_friction, c.dynamic_friction))
}

impl Scene {
    fn collide_error(&self, key: String, message: String) -> SceneError {
        SceneError {
            origin: Origin::File {
                path: self.name.clone(),
                line: None,
            },
            key,
            message,
        }
    }

    /// The collision world for `solver`, whose cloths are scene cloths `members`; `None`
    /// when the scene has no collider, no character (skeleton or model) and no self-collision
    /// among these cloths.
    ///
    /// When one of the self-colliding cloths is a garment whose seams are still closing,
    /// particle self-collision is not turned on here: it is returned, to be turned on once the
    /// seams have closed (see [`crate::SolverGroup::step`]), with the sewn garment as its rest
    /// state, so that the two sides of a seam are not held a thickness apart. Mesh contact is
    /// turned on at once: elements that share a seam's vertex are adjacent to it, so the seams
    /// close freely while the rest of the cloth is kept apart from the first substep (turned
    /// on after the sewing, it would find the crossings the sewing made and could not undo
    /// them).
    pub fn collision_world(
        &self,
        solver: &Solver,
        members: &[usize],
    ) -> Result<(Option<CollisionWorld>, Option<DelayedSelfCollision>), SceneError> {
        let self_cloths: Vec<usize> = match &self.self_collision {
            Some(sc) => members
                .iter()
                .enumerate()
                .filter(|(_, i)| sc.cloths.contains(&self.cloths[**i].name))
                .map(|(j, _)| j)
                .collect(),
            None => Vec::new(),
        };
        if self.colliders.is_empty()
            && self_cloths.is_empty()
            && self.character.is_none()
            && self.model.is_none()
        {
            return Ok((None, None));
        }
        let mut world = CollisionWorld::new(solver);
        for (i, c) in self.colliders.iter().enumerate() {
            let key = format!("collider[{i}]");
            world
                .add_collider(&collider_desc(c))
                .map_err(|e| self.collide_error(key, e.to_string()))?;
        }
        self.add_character(&mut world)?;
        let mut delayed = None;
        if let Some(sc) = &self.self_collision
            && !self_cloths.is_empty()
        {
            let friction = Friction::new(sc.static_friction, sc.dynamic_friction);
            let contact = match sc.contact {
                ContactKind::Particles => SelfContact::Particles(SelfCollisionParams {
                    friction,
                    max_displacement: sc.max_displacement,
                    search_margin: sc.search_margin,
                    adaptive_margin: sc.adaptive_search_margin,
                }),
                ContactKind::Mesh => SelfContact::Mesh(ClothContactParams {
                    friction,
                    ..ClothContactParams::default()
                }),
            };
            let sewn_at = self_cloths
                .iter()
                .map(|&j| &self.cloths[members[j]])
                .filter(|c| !c.seams.is_empty())
                .map(|c| c.seam_time)
                .fold(None, |a: Option<f64>, t| Some(a.map_or(t, |a| a.max(t))));
            match sewn_at {
                // Mesh contact holds the seams' two sides as one vertex from the start.
                Some(at) if at > 0.0 && matches!(contact, SelfContact::Particles(_)) => {
                    delayed = Some(DelayedSelfCollision {
                        at,
                        cloths: self_cloths,
                        contact,
                    })
                }
                _ => contact
                    .enable(&mut world, solver, &self_cloths)
                    .map_err(|e| self.collide_error("self_collision".into(), e.to_string()))?,
            }
        }
        Ok((Some(world), delayed))
    }
}

impl Scene {
    /// Adds the scene's character to `world`: a skeleton's body moving with the clip, or a
    /// glTF model's skinned mesh as a deforming mesh collider.
    fn add_character(&self, world: &mut CollisionWorld) -> Result<(), SceneError> {
        if let Some(ch) = &self.character {
            let body: Arc<dyn KinematicBody> = ch.character.clone();
            world
                .add_body(body, Friction::new(ch.static_friction, ch.dynamic_friction))
                .map_err(|e| self.collide_error("character".into(), e.to_string()))?;
        }
        if let Some(m) = &self.model {
            let err = |e: &dyn std::fmt::Display| {
                self.collide_error("character.model".into(), format!("`{}`: {e}", m.path))
            };
            let desc = m
                .skin
                .desc()
                .map_err(|e| err(&e))?
                .with_friction(Friction::new(m.static_friction, m.dynamic_friction));
            let animation: Arc<dyn MeshAnimation> = m.skin.clone();
            world
                .add_deforming_mesh(&desc, animation)
                .map_err(|e| err(&e))?;
        }
        Ok(())
    }
}
