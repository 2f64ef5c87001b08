//! Weft's animated characters: motion capture (BVH), skeletons and clips sampled at any time,
//! a procedural walk cycle, a mannequin body of analytic collision shapes that carry their
//! velocities, and attachments of cloth vertices to bones.
//!
//! Everything is f64 and knows nothing of the solver, rendering or windows; reading files is
//! confined to [`files`].
#![warn(missing_docs)]

mod animation;
pub mod bvh;
mod clip;
mod error;
pub mod files;
mod pose;
mod skeleton;
mod transform;
pub mod walk;

pub use animation::{Animation, BoneState, VELOCITY_STEP};
pub use bvh::{Bvh, BvhOptions, CMU_SCALE, parse_bvh};
pub use clip::{Clip, Wrap};
pub use error::{BvhError, ClipError, SkeletonError};
pub use pose::Pose;
pub use skeleton::{Joint, Skeleton};
pub use transform::Transform;
pub use walk::{WALK_FRAMES, WALK_PERIOD, walk_cycle, walker_skeleton};
