//! Weft's scene files: the TOML format (`[sim]`, `[cloth.<name>]`, `[wind]`, `[[collider]]`,
//! `[self_collision]`, `[character]`), `--set` overrides, validation with file/line/key errors, and the
//! solvers a scene yields (one per method, stepped in lockstep).
#![warn(missing_docs)]

mod build;
mod collide;
mod duplicate;
mod error;
pub mod family;
mod limits;
mod load;
pub mod material;
mod overrides;
mod ranges;
mod resolve;
mod scene;
pub mod schema;
mod source;
mod suggest;

pub use build::SolverGroup;
pub use collide::{DelayedSelfCollision, SelfContact, collider_desc};
pub use error::{LONGEST_WORD, Origin, SceneError, SceneErrors, elide};
pub use limits::{
    BASE_BYTES, BYTES_PER_PAIR, Limits, Member, PER_PARTICLE_SELF_COLLISION, available_memory,
    bytes_per_particle, contact_pairs, estimate_bytes, human, mesh_contact_pairs, peak_memory,
    self_collision_pairs,
};
pub use load::{from_text, from_text_with, load, load_with};
pub use overrides::{Override, parse_value};
pub use scene::{
    AttachSpec, CappedDirFiles, CharacterSpec, ClothSpec, ColliderSpec, DEFAULT_MAX_FILE_BYTES,
    DirFiles, Files, MapFiles, ModelSpec, Scene, SelfCollisionSpec, read_regular,
};
