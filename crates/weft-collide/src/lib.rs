//! Weft's collisions: colliders (static, kinematic or deforming triangle meshes), kinematic
//! bodies of round cones (animated characters, [`body`]), Coulomb friction and particle
//! self-collision, plugged into the solver's substeps as a [`weft_solver::SubstepHook`]
//! ([`CollisionWorld`]).
#![warn(missing_docs)]

mod analytic;
#[cfg(test)]
mod analytic_vs_parry;
pub mod body;
mod closed_run;
mod collider;
mod convert;
mod error;
mod friction;
mod grid;
mod mesh;
mod obj;
mod reach;
mod run_lists;
pub mod scenarios;
mod self_collision;
mod shape;
mod surface;
mod tessellate;
#[cfg(test)]
mod test_rand;
mod trimesh;
mod world;

pub use body::{BodyPart, KinematicBody, RoundCone};
pub use collider::{Collider, ColliderDesc};
pub use error::{CollideError, MeshError, ShapeError};
pub use friction::Friction;
pub use mesh::TriangleMesh;
pub use obj::{load_obj, parse_obj};
pub use self_collision::{SelfCollisionParams, SelfCollisionTimes};
pub use shape::{CompoundPart, ShapeDesc};
pub use surface::SurfacePoint;
pub use tessellate::{HALF_SPACE_EXTENT, Tessellation, tessellate_shape};
pub use trimesh::deforming::{Keyframes, MeshAnimation};
pub use world::{CollisionWorld, ContactStats};

/// Re-export of parry, so users name the same shape types.
pub use parry3d;
