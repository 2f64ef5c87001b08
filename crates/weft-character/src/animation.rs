//! A skeleton playing a clip: poses, bone world transforms and bone velocities at any time.

use glam::{DQuat, DVec3};

use crate::bvh::Bvh;
use crate::clip::{Clip, Wrap};
use crate::error::ClipError;
use crate::pose::Pose;
use crate::skeleton::Skeleton;
use crate::transform::Transform;

/// Half-width (s) of the central difference that gives bone velocities.
///
/// Within a frame interval the sampled motion is smooth (slerp at constant angular rate,
/// composed down the chain), so the O(h²) truncation error is negligible at 10⁻⁵ s while the
/// f64 round-off stays near 10⁻¹¹ m/s.
pub const VELOCITY_STEP: f64 = 1e-5;

/// A bone's world transform and the velocity of its rigid motion at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoneState {
    /// World transform of the joint's frame (its origin is the joint's position).
    pub transform: Transform,
    /// Linear velocity of the joint's origin (m/s).
    pub linear: DVec3,
    /// Angular velocity ω of the bone's frame, world axes (rad/s).
    pub angular: DVec3,
}

impl BoneState {
    /// Velocity of a point `p` (world) moving rigidly with the bone: v + ω × (p − origin).
    pub fn point_velocity(&self, p: DVec3) -> DVec3 {
        self.linear + self.angular.cross(p - self.transform.translation)
    }
}

/// A skeleton, a clip for it and what happens past the clip's ends.
#[derive(Clone, Debug)]
pub struct Animation {
    skeleton: Skeleton,
    clip: Clip,
    wrap: Wrap,
}

impl Animation {
    /// Pairs a skeleton with a clip; rejects a clip whose frames have another joint count.
    pub fn new(skeleton: Skeleton, clip: Clip, wrap: Wrap) -> Result<Self, ClipError> {
        if let Some(frame) = clip.frames().iter().position(|f| f.len() != skeleton.len()) {
            return Err(ClipError::JointCount {
                frame,
                found: clip.frames()[frame].len(),
                expected: skeleton.len(),
            });
        }
        Ok(Self {
            skeleton,
            clip,
            wrap,
        })
    }

    /// The skeleton and clip of a parsed BVH file.
    pub fn from_bvh(bvh: Bvh, wrap: Wrap) -> Self {
        Self {
            skeleton: bvh.skeleton,
            clip: bvh.clip,
            wrap,
        }
    }

    /// The skeleton.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// The clip.
    pub fn clip(&self) -> &Clip {
        &self.clip
    }

    /// Clamp or loop.
    pub fn wrap(&self) -> Wrap {
        self.wrap
    }

    /// Length of one play-through (s); see [`Clip::duration`].
    pub fn duration(&self) -> f64 {
        self.clip.duration(self.wrap)
    }

    /// The sampled pose at time `t` (s).
    pub fn pose(&self, t: f64) -> Pose {
        self.clip.sample(t, self.wrap)
    }

    /// World transforms of every joint at time `t` (s).
    pub fn world(&self, t: f64) -> Vec<Transform> {
        self.skeleton.world_transforms(&self.pose(t))
    }

    /// World transforms and velocities of every joint at time `t` (s).
    ///
    /// Velocities are central differences of the sampled world transforms over
    /// ±[`VELOCITY_STEP`] (one-sided at a clamped clip's ends, zero outside them): v = Δx / Δt and
    /// ω = 2 log(q(t + h) q(t − h)⁻¹) / Δt, the rotation vector of the world-frame increment.
    pub fn bones(&self, t: f64) -> Vec<BoneState> {
        let (a, b) = match self.wrap {
            Wrap::Loop => (t - VELOCITY_STEP, t + VELOCITY_STEP),
            // Before the first frame and after the last the pose is held: no velocity.
            Wrap::Clamp if t < 0.0 || t > self.duration() => (t, t),
            Wrap::Clamp => {
                let end = self.duration();
                ((t - VELOCITY_STEP).max(0.0), (t + VELOCITY_STEP).min(end))
            }
        };
        let now = self.world(t);
        if b <= a {
            return now
                .into_iter()
                .map(|transform| BoneState {
                    transform,
                    linear: DVec3::ZERO,
                    angular: DVec3::ZERO,
                })
                .collect();
        }
        let before = self.world(a);
        let after = self.world(b);
        let dt = b - a;
        now.into_iter()
            .zip(before.iter().zip(&after))
            .map(|(transform, (x0, x1))| BoneState {
                transform,
                linear: (x1.translation - x0.translation) / dt,
                angular: rotation_vector(x1.rotation * x0.rotation.inverse()) / dt,
            })
            .collect()
    }
}

/// The rotation vector (axis × angle, angle in [0, π]) of a unit quaternion.
pub(crate) fn rotation_vector(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = q.xyz();
    let s = v.length();
    if s == 0.0 {
        return DVec3::ZERO;
    }
    v * (2.0 * s.atan2(q.w) / s)
}
