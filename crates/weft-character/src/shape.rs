//! Analytic collision shapes of the body, in a bone's frame or in the world, and their motion.

use glam::DVec3;

use crate::animation::BoneState;
use crate::transform::Transform;
use weft_collide::body::{Contact, RoundCone, sphere_contact};

/// A shape's geometry: a sphere, or a round cone (a capsule when both radii are equal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Geometry {
    /// A sphere.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius (m).
        radius: f64,
    },
    /// A round cone (tapered capsule) or capsule.
    RoundCone(RoundCone),
}

impl Geometry {
    /// Signed distance, closest point and outward normal for the point `p`.
    pub fn contact(&self, p: DVec3) -> Contact {
        match self {
            Geometry::Sphere { center, radius } => sphere_contact(*center, *radius, p, DVec3::Y),
            Geometry::RoundCone(c) => c.contact(p),
        }
    }

    /// Signed distance (m), negative inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.contact(p).distance
    }

    /// A sphere (centre, radius) containing the geometry.
    pub fn bounding_sphere(&self) -> (DVec3, f64) {
        match *self {
            Geometry::Sphere { center, radius } => (center, radius),
            Geometry::RoundCone(c) => (
                (c.a + c.b) * 0.5,
                0.5 * (c.b - c.a).length() + c.ra.max(c.rb),
            ),
        }
    }

    /// The geometry moved by a rigid transform.
    pub fn transformed(&self, t: &Transform) -> Geometry {
        match *self {
            Geometry::Sphere { center, radius } => Geometry::Sphere {
                center: t.transform_point(center),
                radius,
            },
            Geometry::RoundCone(c) => Geometry::RoundCone(RoundCone::new(
                t.transform_point(c.a),
                t.transform_point(c.b),
                c.ra,
                c.rb,
            )),
        }
    }
}

/// A body shape at one instant: world geometry and the rigid motion of the bone carrying it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldShape {
    /// Index of the shape in its [`crate::Body`].
    pub shape: usize,
    /// Index of the bone (joint) that carries it.
    pub bone: usize,
    /// World-space geometry.
    pub geometry: Geometry,
    /// The carrying bone's transform and velocities.
    pub motion: BoneState,
}

impl WorldShape {
    /// Signed distance, closest point and outward normal for the point `p`.
    pub fn contact(&self, p: DVec3) -> Contact {
        self.geometry.contact(p)
    }

    /// Velocity of the shape's material at world point `p` (usually a surface point):
    /// v + ω × (p − bone origin), the rigid-body velocity field of its bone.
    pub fn point_velocity(&self, p: DVec3) -> DVec3 {
        self.motion.point_velocity(p)
    }
}
