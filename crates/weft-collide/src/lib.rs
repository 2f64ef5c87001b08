//! Weft's collisions: colliders (static, kinematic or deforming triangle meshes), kinematic
//! bodies of round cones (animated characters, [`body`]), Coulomb friction and particle
//! self-collision, plugged into the solver's substeps as a [`weft_solver::SubstepHook`]
//! ([`CollisionWorld`]). The crate uses the solver's public API only; its explicit-vector
//! kernels build on `weft-simd`.
//!
//! The crate's modules:
//!
//! - `world`: the collision world, the solver's hook, and the contacts of a run of particles.
//! - `collider`: a parry shape with a pose that follows a prescribed motion, and friction.
//! - `shape`: collider shapes as descriptions in f64, and their parry shapes in f32.
//! - `mesh`: triangle meshes, and the checks that make them safe to collide with.
//! - `surface`: the answer of a closest-point query.
//! - `convert`: the one seam between weft's types and parry's.
//! - `crossings`: an independent count of cloth crossings and the closest approach, to check contact.
//! - `analytic`: spheres, half-spaces, cuboids and capsules in closed form in f64.
//! - `closed_run`: a still half-space or ball against a run of particles, a block at a time.
//! - `reach`: which particles a collider can touch in one projection.
//! - `trimesh`: particle–triangle-mesh contact for still, moving and deforming meshes.
//! - `run_lists`: meshes' candidate lists kept per run of particles of the fused frame.
//! - `chunk`: the fixed split of the particles into parallel tasks.
//! - `friction`: Coulomb friction for position-based contacts.
//! - `body`: kinematic bodies of round cones (an animated character's limbs).
//! - `cloth_contact`: mesh-level cloth contact (vertex–triangle, edge–edge) that creates no crossing.
//! - `self_collision`: particle–particle self-collision (and between cloths) with friction.
//! - `grid`: points sorted by grid cell, for close pairs and neighbour searches.
//! - `obj`: a tiny Wavefront OBJ reader.
//! - `tessellate`: colliders as triangle meshes for drawing.
//! - `layered`: scenes of thin cloth layers as code, for cloth contact's tests and benches.
//! - `scenarios`: scenes as code, sized by parameter, for benches, examples and tests.
//! - `error`: the crate's errors.
//! - `analytic_vs_parry` (tests only): the closed-form queries against parry's answers.
//! - `test_rand` (tests only): a deterministic pseudo-random source for the tests.
#![warn(missing_docs)]

mod analytic;
#[cfg(test)]
mod analytic_vs_parry;
pub mod body;
mod chunk;
mod closed_run;
mod cloth_contact;
mod collider;
mod convert;
pub mod crossings;
mod error;
mod friction;
mod grid;
pub mod layered;
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
pub use cloth_contact::{ClothContactParams, ClothContactStats, FailSafeStats};
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
