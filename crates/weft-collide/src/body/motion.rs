//! A body part over one substep: its geometry at the end, prepared for queries, and the rigid
//! motion of its frame from the start to the end.

use glam::{DQuat, DVec3};
use weft_solver::RigidTransform;

use super::BodyPart;
use super::round_cone::PreparedCone;

/// One part during one substep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MovingPart {
    /// Geometry at the substep's end.
    pub cone: PreparedCone,
    /// Maps a material point of the part from its start-of-substep position to its end one:
    /// T₁ T₀⁻¹.
    pub forward: RigidTransform,
    /// The inverse, T₀ T₁⁻¹: where a material point now at q was at the substep's start.
    pub back: RigidTransform,
    /// The frame did not move over the substep (exactly).
    pub still: bool,
    /// A bound on how far any point within `extent` of the part moved over the substep (m).
    pub travel: f64,
}

/// x ↦ a(b(x)).
fn compose(a: &RigidTransform, b: &RigidTransform) -> RigidTransform {
    RigidTransform {
        rotation: (a.rotation * b.rotation).normalize(),
        translation: a.apply(b.translation),
    }
}

/// x ↦ R x + t inverted: x ↦ Rᵀ (x − t).
fn inverse(t: &RigidTransform) -> RigidTransform {
    let r = t.rotation.inverse();
    RigidTransform {
        rotation: r,
        translation: -(r * t.translation),
    }
}

/// Rotation angle of a unit quaternion, in [0, π].
fn angle(q: DQuat) -> f64 {
    2.0 * q.xyz().length().atan2(q.w.abs())
}

impl MovingPart {
    /// The part moving from `start` to `end`; `extent` is how far from the surface its
    /// travel bound must hold (the contact reach and the broad phase's cell).
    pub fn new(start: &BodyPart, end: &BodyPart, extent: f64) -> Self {
        let frame = |p: &BodyPart| RigidTransform {
            rotation: p.rotation,
            translation: p.translation,
        };
        let (t0, t1) = (frame(start), frame(end));
        let still = t0 == t1 && start.shape == end.shape;
        let forward = compose(&t1, &inverse(&t0));
        let back = inverse(&forward);
        let cone = end.shape.prepare();
        let travel = if still {
            0.0
        } else {
            // Displacement is affine in the point: on the hull of two balls it is largest at
            // a ball's centre plus (rotation angle) × (radius + extent).
            let (a, ra, b, rb) = cone.ends();
            let turn = angle(back.rotation);
            let at = |c: DVec3, r: f64| (c - back.apply(c)).length() + turn * (r + extent);
            // Geometry that changed in the frame (a part not rigid in its frame) is covered
            // too: the ends' own moves.
            let (a0, b0) = (start.shape.a, start.shape.b);
            let drift = (back.apply(a) - a0)
                .length()
                .max((back.apply(b) - b0).length());
            at(a, ra).max(at(b, rb)) + drift
        };
        Self {
            cone,
            forward,
            back,
            still,
            travel,
        }
    }

    /// How far the material point of the part now at `q` moved over the substep.
    pub fn displacement_at(&self, q: DVec3) -> DVec3 {
        if self.still {
            DVec3::ZERO
        } else {
            q - self.back.apply(q)
        }
    }

    /// Where `x` would be at the substep's end had it moved rigidly with the part.
    pub fn carry(&self, x: DVec3) -> DVec3 {
        if self.still { x } else { self.forward.apply(x) }
    }
}
