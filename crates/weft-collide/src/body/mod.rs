//! Kinematic bodies: sets of round cones (capsules, spheres) carried by moving frames — an
//! animated character's limbs — that the cloth meets, evaluated at every substep's start and
//! end time.
//!
//! A body is its own kind of collider (not a [`crate::ShapeDesc`]): it tells the world, through
//! [`KinematicBody`], where its parts are at any time, and the world does the rest: a broad
//! phase built for a few substeps at a time (`grid.rs`), swept contact in each part's moving
//! frame and contact planes with Coulomb friction against the part's own motion
//! (`contact.rs`).
//!
//! Its modules:
//!
//! - `collider`: a body in the collision world: its parts at a substep's ends, broad phase, sweeps.
//! - `contact`: one particle against a body's parts: the swept test and the contact planes.
//! - `grid`: the body's broad phase, a uniform grid of the parts each cell's particles could touch.
//! - `motion`: a body part over one substep: its geometry at the end and its frame's rigid motion.
//! - `round_cone`: a tapered capsule, with its signed distance, closest point and normal in f64.

mod collider;
mod contact;
mod grid;
mod motion;
mod round_cone;

pub(crate) use collider::BodyCollider;
pub use round_cone::{Contact, PreparedCone, RoundCone, sphere_contact};

use glam::{DQuat, DVec3};

/// One convex part of a kinematic body at one instant: world geometry and the world pose of
/// the frame that carries it (a bone's), which says how its surface moves (a limb twisting
/// about its own axis drags cloth round with it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPart {
    /// World geometry: a round cone (a capsule when both radii are equal, a sphere when both
    /// ends coincide).
    pub shape: RoundCone,
    /// World rotation of the carrying frame.
    pub rotation: DQuat,
    /// World position of the carrying frame's origin (m).
    pub translation: DVec3,
}

/// A body whose parts move kinematically: the world asks for their poses at the start and at
/// the end of every substep.
///
/// Implemented by `weft_character::Character`; anything with a closed-form pose over time can
/// implement it (the tests move a single capsule). Parts must be answered in the same order
/// and number at every time, and the answer must depend on `t` alone (determinism).
pub trait KinematicBody: Send + Sync {
    /// Number of parts (the same at every time).
    fn part_count(&self) -> usize;

    /// The parts at time `t` (s), in a fixed order, into `out` (cleared first).
    fn parts_at(&self, t: f64, out: &mut Vec<BodyPart>);
}

impl std::fmt::Debug for dyn KinematicBody {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KinematicBody")
            .field("parts", &self.part_count())
            .finish()
    }
}
