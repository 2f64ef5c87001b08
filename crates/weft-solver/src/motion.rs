//! Prescribed rigid motions for kinematic pins (and kinematic colliders elsewhere).

use std::f64::consts::TAU;

use glam::{DQuat, DVec3};

/// A rigid motion prescribed as a function of time.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Motion {
    /// Does not move.
    #[default]
    Static,
    /// Constant velocity: x(t) = x₀ + v t.
    Linear {
        /// Velocity (m/s).
        velocity: DVec3,
    },
    /// Harmonic oscillation: x(t) = x₀ + A sin(2π f t).
    Oscillate {
        /// Amplitude A (m).
        amplitude: DVec3,
        /// Frequency f (Hz).
        frequency: f64,
    },
    /// Rotation about an axis through a pivot at a constant angular velocity.
    Rotate {
        /// A point on the axis (m).
        pivot: DVec3,
        /// Axis direction (normalised on use).
        axis: DVec3,
        /// Angular velocity (rad/s).
        angular_velocity: f64,
    },
}

/// A rigid transform x ↦ R x + t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidTransform {
    /// Rotation R.
    pub rotation: DQuat,
    /// Translation t (m).
    pub translation: DVec3,
}

impl RigidTransform {
    /// The identity.
    pub const IDENTITY: Self = Self {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// Applies the transform to a point.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// The pose `(position, rotation)` of a body placed at `position`, `rotation` and then
    /// carried by this transform: the one pose the collision world and the log both use.
    pub fn carry(&self, position: DVec3, rotation: DQuat) -> (DVec3, DQuat) {
        (self.apply(position), self.rotation * rotation)
    }
}

impl Motion {
    /// The transform that maps rest positions to positions at time `t` (s).
    pub fn transform(&self, t: f64) -> RigidTransform {
        match *self {
            Motion::Static => RigidTransform::IDENTITY,
            Motion::Linear { velocity } => RigidTransform {
                rotation: DQuat::IDENTITY,
                translation: velocity * t,
            },
            Motion::Oscillate {
                amplitude,
                frequency,
            } => RigidTransform {
                rotation: DQuat::IDENTITY,
                translation: amplitude * (TAU * frequency * t).sin(),
            },
            Motion::Rotate {
                pivot,
                axis,
                angular_velocity,
            } => {
                let rotation =
                    DQuat::from_axis_angle(axis.normalize_or(DVec3::Y), angular_velocity * t);
                RigidTransform {
                    rotation,
                    translation: pivot - rotation * pivot,
                }
            }
        }
    }

    /// Position at time `t` of a point whose rest position is `rest`.
    pub fn position(&self, rest: DVec3, t: f64) -> DVec3 {
        self.transform(t).apply(rest)
    }
}

/// A pinned particle that follows a prescribed motion (a kinematic attachment).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicPin {
    /// Global particle index.
    pub particle: u32,
    /// Its rest position (m).
    pub rest: DVec3,
    /// The motion it follows.
    pub motion: Motion,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_keeps_distance_to_pivot_and_oscillation_returns() {
        let m = Motion::Rotate {
            pivot: DVec3::new(1.0, 0.0, 0.0),
            axis: DVec3::Y,
            angular_velocity: std::f64::consts::FRAC_PI_2,
        };
        let p = m.position(DVec3::new(2.0, 0.0, 0.0), 1.0);
        assert!((p - DVec3::new(1.0, 0.0, -1.0)).length() < 1e-5, "{p}");
        let o = Motion::Oscillate {
            amplitude: DVec3::X,
            frequency: 2.0,
        };
        assert!((o.position(DVec3::ZERO, 0.125) - DVec3::X).length() < 1e-6);
        assert!(o.position(DVec3::ZERO, 0.5).length() < 1e-5);
    }
}
