//! Prescribed rigid motions for kinematic pins (and kinematic colliders elsewhere).

use std::f64::consts::TAU;

use glam::{Quat, Vec3};

/// A rigid motion prescribed as a function of time.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Motion {
    /// Does not move.
    #[default]
    Static,
    /// Constant velocity: x(t) = x₀ + v t.
    Linear {
        /// Velocity (m/s).
        velocity: Vec3,
    },
    /// Harmonic oscillation: x(t) = x₀ + A sin(2π f t).
    Oscillate {
        /// Amplitude A (m).
        amplitude: Vec3,
        /// Frequency f (Hz).
        frequency: f32,
    },
    /// Rotation about an axis through a pivot at a constant angular velocity.
    Rotate {
        /// A point on the axis (m).
        pivot: Vec3,
        /// Axis direction (normalised on use).
        axis: Vec3,
        /// Angular velocity (rad/s).
        angular_velocity: f32,
    },
}

/// A rigid transform x ↦ R x + t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidTransform {
    /// Rotation R.
    pub rotation: Quat,
    /// Translation t (m).
    pub translation: Vec3,
}

impl RigidTransform {
    /// The identity.
    pub const IDENTITY: Self = Self {
        rotation: Quat::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// Applies the transform to a point.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }
}

impl Motion {
    /// The transform that maps rest positions to positions at time `t` (s).
    pub fn transform(&self, t: f64) -> RigidTransform {
        match *self {
            Motion::Static => RigidTransform::IDENTITY,
            Motion::Linear { velocity } => RigidTransform {
                rotation: Quat::IDENTITY,
                translation: velocity * t as f32,
            },
            Motion::Oscillate {
                amplitude,
                frequency,
            } => RigidTransform {
                rotation: Quat::IDENTITY,
                translation: amplitude * (TAU * f64::from(frequency) * t).sin() as f32,
            },
            Motion::Rotate {
                pivot,
                axis,
                angular_velocity,
            } => {
                let rotation = Quat::from_axis_angle(
                    axis.normalize_or(Vec3::Y),
                    (f64::from(angular_velocity) * t) as f32,
                );
                RigidTransform {
                    rotation,
                    translation: pivot - rotation * pivot,
                }
            }
        }
    }

    /// Position at time `t` of a point whose rest position is `rest`.
    pub fn position(&self, rest: Vec3, t: f64) -> Vec3 {
        self.transform(t).apply(rest)
    }
}

/// A pinned particle that follows a prescribed motion (a kinematic attachment).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicPin {
    /// Global particle index.
    pub particle: u32,
    /// Its rest position (m).
    pub rest: Vec3,
    /// The motion it follows.
    pub motion: Motion,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_keeps_distance_to_pivot_and_oscillation_returns() {
        let m = Motion::Rotate {
            pivot: Vec3::new(1.0, 0.0, 0.0),
            axis: Vec3::Y,
            angular_velocity: std::f32::consts::FRAC_PI_2,
        };
        let p = m.position(Vec3::new(2.0, 0.0, 0.0), 1.0);
        assert!((p - Vec3::new(1.0, 0.0, -1.0)).length() < 1e-5, "{p}");
        let o = Motion::Oscillate {
            amplitude: Vec3::X,
            frequency: 2.0,
        };
        assert!((o.position(Vec3::ZERO, 0.125) - Vec3::X).length() < 1e-6);
        assert!(o.position(Vec3::ZERO, 0.5).length() < 1e-5);
    }
}
