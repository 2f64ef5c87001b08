//! Weft's animated characters: motion capture (BVH), skeletons and clips sampled at any time,
//! a procedural walk cycle, a mannequin body of analytic collision shapes that carry their
//! velocities, attachments of cloth vertices to bones, and garments sewn from flat panels.
//!
//! Everything is f64 and knows nothing of rendering or windows; the solver appears only as
//! the [`weft_solver::ClothMesh`] a garment becomes. Reading files is confined to [`files`].
//!
//! The crate's modules:
//!
//! - `animation`: a skeleton playing a clip: poses, bone transforms and velocities at any time.
//! - `attach`: cloth vertices pinned to a bone, following its rigid motion exactly.
//! - `body`: the mannequin body: a body table's shapes on a skeleton, evaluated at a pose.
//! - `body_table`: the TOML table that sizes a mannequin body, one entry per shape on a bone.
//! - `bvh`: a reader of BVH motion capture text (Biovision Hierarchy).
//! - `character`: an animation and the body it carries, evaluated at any time.
//! - `clip`: poses sampled at a fixed frame time.
//! - `collide`: a character in the simulation: its body a kinematic collider, its attachments
//!   driven pins.
//! - `error`: the crate's errors, each naming where the problem is.
//! - `files`: reading character files from disk; every error names the file.
//! - `garment`: garments sewn from flat panels into a weft-solver cloth mesh.
//! - `pose`: every joint's local rotation and channel translation at one instant.
//! - `shape`: analytic collision shapes of the body, in a bone's frame or in the world.
//! - `skeleton`: a joint hierarchy (names, parents, rest offsets) and its forward kinematics.
//! - `skin`: skinned meshes from glTF and linear blend skinning on the CPU.
//! - `toml_lines`: lines of keys in TOML text, for errors that name where a bad value sits.
//! - `transform`: rigid transforms kept as a unit quaternion and a translation.
//! - `walk`: a procedural walk cycle of our own, sampled into a looping clip.
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
