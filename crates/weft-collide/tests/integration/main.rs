//! weft-collide's integration tests, one module a subject, linked into one test binary.
//!
//! One binary instead of one per file keeps the test build small on disk and quick to link.

mod common;

mod bad_meshes;
mod body;
mod cloth_contact;
mod determinism;
mod dihedral_drape;
mod friction_slope;
mod fused_contacts;
mod kinematic;
mod mesh_collider;
mod mesh_contact;
mod self_collision_times;
