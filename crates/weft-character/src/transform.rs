//! Rigid transforms x ↦ R x + t, kept as a unit quaternion and a translation (no matrix drift).

use std::ops::Mul;

use glam::{DQuat, DVec3};

/// A rigid transform x ↦ R x + t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Rotation R (unit quaternion).
    pub rotation: DQuat,
    /// Translation t (m).
    pub translation: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Self = Self {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// A transform from its rotation and translation.
    pub fn new(rotation: DQuat, translation: DVec3) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// Maps a point: R p + t.
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// Maps a direction: R v.
    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// The inverse transform x ↦ Rᵀ (x − t).
    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self {
            rotation: r,
            translation: -(r * self.translation),
        }
    }
}

impl Mul for Transform {
    type Output = Transform;

    /// Composition: `(a * b).transform_point(p) == a.transform_point(b.transform_point(p))`.
    fn mul(self, rhs: Transform) -> Transform {
        Transform {
            rotation: (self.rotation * rhs.rotation).normalize(),
            translation: self.transform_point(rhs.translation),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composition_and_inverse_agree_with_pointwise_application() {
        let a = Transform::new(DQuat::from_rotation_z(0.7), DVec3::new(1.0, -2.0, 0.5));
        let b = Transform::new(
            DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 1.1),
            DVec3::new(-0.3, 0.2, 4.0),
        );
        let p = DVec3::new(0.25, -1.5, 2.0);
        let composed = (a * b).transform_point(p);
        let nested = a.transform_point(b.transform_point(p));
        assert!(
            (composed - nested).length() < 1e-14,
            "{composed} vs {nested}"
        );
        let back = a.inverse().transform_point(a.transform_point(p));
        assert!((back - p).length() < 1e-14, "{back} vs {p}");
    }
}
