//! Weft's animated characters: motion capture (BVH), skeletons and clips sampled at any time,
//! a procedural walk cycle, a mannequin body of analytic collision shapes that carry their
//! velocities, attachments of cloth vertices to bones, and garments sewn from flat panels.
//!
//! Everything is f64 and knows nothing of rendering or windows; the solver appears only as
//! the [`weft_solver::ClothMesh`] a garment becomes. Reading files is confined to [`files`].
#![warn(missing_docs)]

mod animation;
mod attach;
mod body;
mod body_table;
pub mod bvh;
mod character;
mod clip;
mod collide;
mod error;
pub mod files;
pub mod garment;
mod pose;
mod shape;
mod skeleton;
pub mod skin;
mod toml_lines;
mod transform;
pub mod walk;

pub use animation::{Animation, BoneState, VELOCITY_STEP};
pub use attach::Attachment;
pub use body::{Body, BodyShape};
pub use body_table::{BodyTable, ShapeKind, ShapeSpec};
pub use bvh::{Bvh, BvhOptions, CMU_SCALE, parse_bvh};
pub use character::{Character, CharacterState};
pub use clip::{Clip, Wrap};
pub use collide::AttachmentDriver;
pub use error::{AttachError, BodyError, BvhError, ClipError, SkeletonError};
pub use pose::Pose;
pub use shape::{Geometry, WorldShape};
pub use skeleton::{Joint, Skeleton};
pub use transform::Transform;
pub use walk::{WALK_FRAMES, WALK_PERIOD, walk_cycle, walker_skeleton};
pub use weft_collide::body::{Contact, RoundCone};
