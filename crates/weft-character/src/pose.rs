//! A pose: every joint's local rotation and channel translation at one instant.

use glam::{DQuat, DVec3};

/// Local joint state: rotation R_i and channel translation d_i (added to the rest offset).
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// Per-joint channel translation d_i (m, parent frame); zero for joints without
    /// position channels. For the root this is the root's motion.
    pub translations: Vec<DVec3>,
    /// Per-joint local rotation R_i (unit quaternions).
    pub rotations: Vec<DQuat>,
}

impl Pose {
    /// The pose with no rotation and no translation for `n` joints.
    pub fn identity(n: usize) -> Self {
        Self {
            translations: vec![DVec3::ZERO; n],
            rotations: vec![DQuat::IDENTITY; n],
        }
    }

    /// Number of joints.
    pub fn len(&self) -> usize {
        self.rotations.len()
    }

    /// Whether the pose has no joint.
    pub fn is_empty(&self) -> bool {
        self.rotations.is_empty()
    }

    /// The root's channel translation (m).
    pub fn root_translation(&self) -> DVec3 {
        self.translations.first().copied().unwrap_or(DVec3::ZERO)
    }

    /// Interpolation between two poses: slerp of rotations (shortest arc), lerp of
    /// translations; `f = 0` gives `a`, `f = 1` gives `b`.
    pub fn interpolate_into(a: &Pose, b: &Pose, f: f64, out: &mut Pose) {
        out.translations.clear();
        out.rotations.clear();
        out.translations.extend(
            a.translations
                .iter()
                .zip(&b.translations)
                .map(|(x, y)| x.lerp(*y, f)),
        );
        out.rotations.extend(
            a.rotations
                .iter()
                .zip(&b.rotations)
                .map(|(x, y)| x.slerp(*y, f).normalize()),
        );
    }
}
