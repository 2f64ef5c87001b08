//! weft-scene's integration tests, one module a subject, linked into one test binary.
//!
//! One binary instead of one per file keeps the test build small on disk and quick to link.

mod common;

mod character;
mod cusick;
mod dressed;
mod friction;
mod fuzz;
mod garment_shape;
mod glb_character;
mod held_pins;
mod material_key;
mod memory_estimate;
mod mesh_drape;
mod self_fold;
mod shipped_scenes;
mod sphere_drop;
mod table_drape;
mod thickness;
