//! Weft's scene files: the TOML format (`[sim]`, `[cloth.<name>]`, `[wind]`, `[[collider]]`,
//! `[self_collision]`), `--set` overrides, validation with file/line/key errors, and the
//! solvers a scene yields (one per method, stepped in lockstep).
#![warn(missing_docs)]

mod build;
mod collide;
mod error;
pub mod family;
mod load;
pub mod material;
mod overrides;
mod resolve;
mod scene;
pub mod schema;
mod source;

pub use build::SolverGroup;
pub use collide::collider_desc;
pub use error::{Origin, SceneError, SceneErrors};
pub use load::{from_text, load};
pub use overrides::{Override, parse_value};
pub use scene::{
    ClothSpec, ColliderSpec, DirFiles, Files, MapFiles, Scene, SelfCollisionSpec, ShapeSpec,
};
