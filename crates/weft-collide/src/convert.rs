//! The one seam between weft's types and parry's.
//!
//! parry3d 0.31 does its math in glam 0.33 (through `glamx`), the same glam as the workspace, so
//! `parry3d::math::Vector` *is* `glam::Vec3` and rotations are `glam::Quat`: only poses need
//! assembling.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use weft_solver::RigidTransform;

/// The parry pose that rotates by `rotation`, then translates by `translation`.
pub(crate) fn pose(translation: Vec3, rotation: Quat) -> Pose {
    Pose::from_parts(translation, rotation)
}

/// `motion ∘ base`: the pose of a body placed at `base` and then carried by a rigid motion.
pub(crate) fn compose(motion: RigidTransform, base: &Pose) -> Pose {
    let rotation = motion.rotation.as_quat();
    pose(
        rotation * base.translation + motion.translation.as_vec3(),
        (rotation * base.rotation).normalize(),
    )
}
