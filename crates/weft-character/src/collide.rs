//! A character in the simulation: its body as a kinematic body of the collision world
//! ([`weft_collide::KinematicBody`]), and its attachments as the solver's driven pins
//! ([`weft_solver::PinDriver`]), both evaluated at every substep's time.

use std::sync::Arc;

use glam::DVec3;
use weft_collide::body::{BodyPart, KinematicBody, RoundCone};
use weft_solver::PinDriver;

use crate::attach::{Attachment, driven_particles};
use crate::character::Character;
use crate::error::AttachError;
use crate::shape::Geometry;

impl KinematicBody for Character {
    fn part_count(&self) -> usize {
        self.body().shapes().len()
    }

    /// The body's shapes at time `t`, in table order, each with its bone's world frame (one
    /// forward-kinematics pass; no velocities: the world derives motion from two poses).
    fn parts_at(&self, t: f64, out: &mut Vec<BodyPart>) {
        let world = self.animation().world(t);
        out.clear();
        out.extend(self.body().shapes().iter().map(|s| {
            let frame = world[s.bone];
            let shape = match s.local.transformed(&frame) {
                Geometry::Sphere { center, radius } => RoundCone::sphere(center, radius),
                Geometry::RoundCone(c) => c,
            };
            BodyPart {
                shape,
                rotation: frame.rotation,
                translation: frame.translation,
            }
        }));
    }
}

/// A character's attachments as driven pins: each attached cloth vertex is held at its
/// bone-frame coordinates carried by the bone's world transform at every substep's time,
/// with the bone's velocity there (v + ω × r).
#[derive(Clone, Debug)]
pub struct AttachmentDriver {
    character: Arc<Character>,
    attachments: Vec<Attachment>,
    particles: Vec<u32>,
}

impl AttachmentDriver {
    /// Drives `attachments` (vertex indices of one cloth) with `character`'s bones; the
    /// cloth's vertex 0 is the solver's particle `first_particle`
    /// (`solver.cloths()[c].particles.start`).
    pub fn new(
        character: Arc<Character>,
        first_particle: usize,
        attachments: Vec<Attachment>,
    ) -> Result<Self, AttachError> {
        let particles = driven_particles(
            first_particle,
            attachments.iter().map(|a| (a.bone(), a.vertices())),
            character.animation().skeleton().len(),
        )?;
        Ok(Self {
            character,
            attachments,
            particles,
        })
    }

    /// The attachments.
    pub fn attachments(&self) -> &[Attachment] {
        &self.attachments
    }
}

impl PinDriver for AttachmentDriver {
    fn particles(&self) -> &[u32] {
        &self.particles
    }

    fn drive(&self, t: f64, positions: &mut [DVec3], velocities: &mut [DVec3]) {
        let bones = self.character.animation().bones(t);
        let mut k = 0;
        for a in &self.attachments {
            let bone = &bones[a.bone()];
            for &p in a.local() {
                let x = bone.transform.transform_point(p);
                positions[k] = x;
                velocities[k] = bone.point_velocity(x);
                k += 1;
            }
        }
    }
}
