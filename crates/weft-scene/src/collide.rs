//! Wires a scene's colliders and self-collision to `weft-collide`: one collision world per
//! solver, holding every collider (colliders are f64 here, f32 inside parry).

use std::sync::Arc;

use weft_collide::{
    ColliderDesc, CollisionWorld, CompoundPart, Friction, KinematicBody, SelfCollisionParams,
    ShapeDesc, TriangleMesh,
};
use weft_solver::Solver;
use weft_solver::glam::{DQuat, DVec3, Quat, Vec3};

use crate::error::{Origin, SceneError};

/// Self-collision to turn on once a garment's seams have closed.
#[derive(Clone, Debug)]
pub struct DelayedSelfCollision {
    /// Solver time at which to turn it on (s): the latest seam closing time.
    pub at: f64,
    /// The solver's cloths that take part.
    pub cloths: Vec<usize>,
    /// Its parameters.
    pub params: SelfCollisionParams,
}
use crate::scene::{ColliderSpec, Scene, ShapeSpec};

fn v(p: DVec3) -> Vec3 {
    p.as_vec3()
}

fn q(r: DQuat) -> Quat {
    Quat::from_xyzw(r.x as f32, r.y as f32, r.z as f32, r.w as f32)
}

fn shape_desc(s: &ShapeSpec) -> Result<ShapeDesc, String> {
    Ok(match s {
        ShapeSpec::Sphere { radius } => ShapeDesc::Sphere {
            radius: *radius as f32,
        },
        ShapeSpec::Cuboid { half_extents } => ShapeDesc::Cuboid {
            half_extents: v(*half_extents),
        },
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => ShapeDesc::Capsule {
            half_height: *half_height as f32,
            radius: *radius as f32,
        },
        ShapeSpec::Plane { normal } => ShapeDesc::HalfSpace { normal: v(*normal) },
        ShapeSpec::ConvexHull { points } => ShapeDesc::ConvexHull {
            points: points.iter().map(|p| v(*p)).collect(),
        },
        ShapeSpec::Mesh {
            positions,
            triangles,
        } => ShapeDesc::TriMesh(
            TriangleMesh::new(positions.iter().map(|p| v(*p)).collect(), triangles.clone())
                .map_err(|e| e.to_string())?,
        ),
        ShapeSpec::Compound(parts) => ShapeDesc::Compound(
            parts
                .iter()
                .map(|(p, r, s)| {
                    Ok(CompoundPart {
                        position: v(*p),
                        rotation: q(*r),
                        shape: shape_desc(s)?,
                    })
                })
                .collect::<Result<_, String>>()?,
        ),
    })
}

/// The collision crate's description of a collider.
pub fn collider_desc(c: &ColliderSpec) -> Result<ColliderDesc, String> {
    Ok(ColliderDesc::new(shape_desc(&c.shape)?)
        .at(v(c.position))
        .rotated(q(c.rotation))
        .moving(c.motion)
        .with_friction(Friction::new(c.static_friction, c.dynamic_friction)))
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
    /// when the scene has no collider, no character and no self-collision among these cloths.
    ///
    /// When one of the self-colliding cloths is a garment whose seams are still closing,
    /// self-collision is not turned on here: it is returned, to be turned on once the seams
    /// have closed (see [`crate::SolverGroup::step`]), with the sewn garment as its rest state,
    /// so that the two sides of a seam are not held a thickness apart.
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
        if self.colliders.is_empty() && self_cloths.is_empty() && self.character.is_none() {
            return Ok((None, None));
        }
        let mut world = CollisionWorld::new(solver);
        for (i, c) in self.colliders.iter().enumerate() {
            let key = format!("collider[{i}]");
            let desc = collider_desc(c).map_err(|m| self.collide_error(key.clone(), m))?;
            world
                .add_collider(&desc)
                .map_err(|e| self.collide_error(key, e.to_string()))?;
        }
        self.add_character(&mut world)?;
        let mut delayed = None;
        if let Some(sc) = &self.self_collision
            && !self_cloths.is_empty()
        {
            let params = SelfCollisionParams {
                friction: Friction::new(sc.static_friction, sc.dynamic_friction),
                max_displacement: sc.max_displacement,
                search_margin: sc.search_margin,
                adaptive_margin: sc.adaptive_search_margin,
            };
            let sewn_at = self_cloths
                .iter()
                .map(|&j| &self.cloths[members[j]])
                .filter(|c| !c.seams.is_empty())
                .map(|c| c.seam_time)
                .fold(None, |a: Option<f64>, t| Some(a.map_or(t, |a| a.max(t))));
            match sewn_at {
                Some(at) if at > 0.0 => {
                    delayed = Some(DelayedSelfCollision {
                        at,
                        cloths: self_cloths,
                        params,
                    })
                }
                _ => world
                    .enable_self_collision(solver, &self_cloths, params)
                    .map_err(|e| self.collide_error("self_collision".into(), e.to_string()))?,
            }
        }
        Ok((Some(world), delayed))
    }
}

impl Scene {
    /// Adds the scene's character (its body, moving with the clip) to `world`.
    fn add_character(&self, world: &mut CollisionWorld) -> Result<(), SceneError> {
        if let Some(ch) = &self.character {
            let body: Arc<dyn KinematicBody> = ch.character.clone();
            world
                .add_body(body, Friction::new(ch.static_friction, ch.dynamic_friction))
                .map_err(|e| self.collide_error("character".into(), e.to_string()))?;
        }
        Ok(())
    }
}
