//! Wires a scene's colliders and self-collision to `weft-collide`: one collision world per
//! solver, holding every collider (colliders are f64 here, rounded to f32 inside parry).

use weft_collide::{ColliderDesc, CollisionWorld, Friction, SelfCollisionParams};
use weft_solver::Solver;

use crate::error::{Origin, SceneError};
use crate::scene::{ColliderSpec, Scene};

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
    /// when the scene has no collider and no self-collision among these cloths.
    pub fn collision_world(
        &self,
        solver: &Solver,
        members: &[usize],
    ) -> Result<Option<CollisionWorld>, SceneError> {
        let self_cloths: Vec<usize> = match &self.self_collision {
            Some(sc) => members
                .iter()
                .enumerate()
                .filter(|(_, i)| sc.cloths.contains(&self.cloths[**i].name))
                .map(|(j, _)| j)
                .collect(),
            None => Vec::new(),
        };
        if self.colliders.is_empty() && self_cloths.is_empty() {
            return Ok(None);
        }
        let mut world = CollisionWorld::new(solver);
        for (i, c) in self.colliders.iter().enumerate() {
            let key = format!("collider[{i}]");
            world
                .add_collider(&collider_desc(c))
                .map_err(|e| self.collide_error(key, e.to_string()))?;
        }
        if let Some(sc) = &self.self_collision
            && !self_cloths.is_empty()
        {
            let params = SelfCollisionParams {
                friction: Friction::new(sc.static_friction, sc.dynamic_friction),
                max_displacement: sc.max_displacement,
                search_margin: sc.search_margin,
                adaptive_margin: sc.adaptive_search_margin,
            };
            world
                .enable_self_collision(solver, &self_cloths, params)
                .map_err(|e| self.collide_error("self_collision".into(), e.to_string()))?;
        }
        Ok(Some(world))
    }
}
