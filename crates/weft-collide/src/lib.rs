//! Weft's collisions: colliders (static, kinematic or deforming triangle meshes), Coulomb
//! friction and particle self-collision, plugged into the solver's substeps as a
//! [`weft_solver::SubstepHook`] ([`CollisionWorld`]).
#![warn(missing_docs)]

mod analytic;
#[cfg(test)]
mod analytic_vs_parry;
mod collider;
mod convert;
mod error;
mod friction;
mod mesh;
mod obj;
pub mod scenarios;
mod self_collision;
mod self_contact;
mod shape;
mod skin;
mod spatial_hash;
mod tessellate;
#[cfg(test)]
mod test_rand;
mod times;
mod trimesh;
mod world;

pub use collider::{Collider, ColliderDesc, SurfacePoint};
pub use error::{CollideError, MeshError, ShapeError};
pub use friction::Friction;
pub use mesh::TriangleMesh;
pub use obj::{load_obj, parse_obj};
pub use self_collision::SelfCollisionParams;
pub use shape::{CompoundPart, ShapeDesc};
pub use spatial_hash::SpatialHash;
pub use tessellate::{HALF_SPACE_EXTENT, Tessellation, tessellate_shape};
pub use times::SelfCollisionTimes;
pub use trimesh::deforming::{Keyframes, MeshAnimation};
pub use world::{CollisionWorld, ContactStats};

/// Re-export of parry, so users name the same shape types.
pub use parry3d;
