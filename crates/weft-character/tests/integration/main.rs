//! weft-character's integration tests, one module a subject, linked into one test binary.
//!
//! One binary instead of one per file keeps the test build small on disk and quick to link.

mod common;

mod assets;
mod attach;
mod body;
mod body_contact;
mod bvh;
mod dress;
mod garment;
mod garments;
mod round_cone;
mod sampling;
mod sew;
mod skin;
mod skin_collider;
mod skin_glb;
mod walk;
