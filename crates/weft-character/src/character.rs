//! A character: an animation and the body it carries, evaluated at any time into bone
//! transforms and velocities (for attachments) and analytic shapes with velocities (the
//! colliders cloth meets).

use glam::DVec3;
use weft_collide::body::Contact;

use crate::animation::{Animation, BoneState};
use crate::body::Body;
use crate::body_table::BodyTable;
use crate::error::BodyError;
use crate::shape::WorldShape;
use crate::walk::walk_cycle;

/// An animated skeleton with its collision body.
#[derive(Clone, Debug)]
pub struct Character {
    animation: Animation,
    body: Body,
}

/// Everything a solver needs from the character at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct CharacterState {
    /// Time (s).
    pub time: f64,
    /// Every joint's world transform and velocities, indexed like the skeleton.
    pub bones: Vec<BoneState>,
    /// Every body shape in world space, with its bone's motion, in table order.
    pub shapes: Vec<WorldShape>,
}

impl Character {
    /// Resolves `table` against the animation's skeleton.
    pub fn new(animation: Animation, table: &BodyTable) -> Result<Self, BodyError> {
        let body = Body::new(animation.skeleton(), table)?;
        Ok(Self { animation, body })
    }

    /// The procedural walker with its built-in body.
    pub fn walker() -> Self {
        Self::new(walk_cycle(), &BodyTable::walker()).expect("the walker body fits its skeleton")
    }

    /// The animation.
    pub fn animation(&self) -> &Animation {
        &self.animation
    }

    /// The body.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// Bones and shapes at time `t` (s); call it every substep.
    pub fn state(&self, t: f64) -> CharacterState {
        let bones = self.animation.bones(t);
        let shapes = self.body.evaluate(&bones);
        CharacterState {
            time: t,
            bones,
            shapes,
        }
    }
}

impl CharacterState {
    /// The shape whose surface the point `p` is deepest inside (or nearest to), with its
    /// contact; `None` for a body without shapes.
    ///
    /// Shapes whose bounding sphere lies farther than the best distance so far are skipped:
    /// the distance to a shape is never less than the distance to a sphere containing it, so
    /// the answer is the same as testing every shape.
    pub fn nearest(&self, p: DVec3) -> Option<(&WorldShape, Contact)> {
        let mut best: Option<(&WorldShape, Contact)> = None;
        for s in &self.shapes {
            let (centre, radius) = s.geometry.bounding_sphere();
            let bound = (p - centre).length() - radius;
            if best.is_some_and(|(_, c)| bound >= c.distance) {
                continue;
            }
            let c = s.contact(p);
            if best.is_none_or(|(_, b)| c.distance < b.distance) {
                best = Some((s, c));
            }
        }
        best
    }

    /// Signed distance from `p` to the body, the union of its shapes (m); +∞ without shapes.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.nearest(p).map_or(f64::INFINITY, |(_, c)| c.distance)
    }
}
