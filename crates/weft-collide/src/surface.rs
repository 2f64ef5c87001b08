//! The answer of a closest-point query, shared by the closed-form queries (`analytic.rs`) and
//! the colliders that ask them (`collider.rs`).

use glam::DVec3;

/// The closest surface point of a collider to a particle, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Closest point on the surface (m).
    pub point: DVec3,
    /// Outward unit normal there.
    pub normal: DVec3,
    /// Signed distance of the particle from the surface, negative inside (m).
    pub distance: f64,
}
