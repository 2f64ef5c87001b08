//! Weft's scene files: the TOML format (`[sim]`, `[cloth.<name>]`, `[wind]`, `[[collider]]`,
//! `[self_collision]`, `[character]`), `--set` overrides, validation with file/line/key errors, and the
//! solvers a scene yields (one per method, stepped in lockstep).
//!
//! The crate's modules:
//!
//! - `build`: the solvers a scene yields, one per method, cloths in name order.
//! - `collide`: a scene's colliders and self-collision wired to weft-collide, a world per solver.
//! - `duplicate`: a duplicate key named by its dotted key and the line of its first definition.
//! - `error`: scene errors, each naming where the bad value came from and its dotted key.
//! - `family`: per-family constraint parameters as flat cloth keys (`<family>_<field>`).
//! - `limits`: limits a load enforces before it reads or allocates: file size and memory.
//! - `load`: loading: file, TOML document, `--set` overrides, serde, validation.
//! - `material`: a cloth's material: a fabric preset by name, or a table of physical values.
//! - `overrides`: `--set KEY=VALUE` overrides, applied to the TOML document before serde.
//! - `ranges`: physical ranges of scene values, each with its reason.
//! - `resolve`: validation: a deserialised scene file checked into a `Scene` with solver types.
//! - `scene`: a validated scene: solver settings, forces, cloths, colliders and its texts.
//! - `schema`: the scene file as written: serde structures mirroring the TOML.
//! - `source`: the scene text with spans: dotted keys to lines, byte offsets back to keys.
//! - `suggest`: "did you mean": the name nearest a misspelt one, by edit distance.
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
