//! Wires a scene's colliders and self-collision to `weft-collide`: one collision world per
//! solver, holding every collider (colliders are f64 here, f32 inside parry).

use weft_collide::{
    ColliderDesc, CollisionWorld, CompoundPart, Friction, SelfCollisionParams, ShapeDesc,
    TriangleMesh,
};
use weft_solver::Solver;
use weft_solver::glam::{DQuat, DVec3, Quat, Vec3};

use crate::error::{Origin, SceneError};
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
            let desc = collider_desc(c).map_err(|m| self.collide_error(key.clone(), m))?;
            world
                .add_collider(&desc)
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
