//! Cloth vertices attached to a joint of a skinned glTF character (a cape to the neck): each
//! keeps its coordinates in the joint node's frame, and follows the node's placed world
//! transform (`placement · G(t)`, scale included) at every substep's time.

use std::sync::Arc;

use glam::{DMat4, DVec3};
use weft_solver::PinDriver;

use super::SkinCollider;
use crate::animation::VELOCITY_STEP;
use crate::attach::{driven_particles, local_coordinates};
use crate::error::AttachError;

/// A set of vertices held at fixed coordinates in one glTF node's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct JointAttachment {
    node: usize,
    vertices: Vec<u32>,
    local: Vec<DVec3>,
}

impl JointAttachment {
    /// Binds `vertices` (indices into `positions`, world m) to glTF node `node`, whose placed
    /// world transform at binding time is `bind` (see [`SkinCollider::node_world`]).
    pub fn bind(
        node: usize,
        vertices: Vec<u32>,
        positions: &[DVec3],
        bind: &DMat4,
    ) -> Result<Self, AttachError> {
        let inverse = bind.inverse();
        let local = local_coordinates(&vertices, positions, |p| inverse.transform_point3(p))?;
        Ok(Self {
            node,
            vertices,
            local,
        })
    }

    /// The glTF node the vertices follow.
    pub fn node(&self) -> usize {
        self.node
    }

    /// The attached vertices.
    pub fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    /// World positions of the attached vertices for the node's world transform `world`.
    pub fn positions(&self, world: &DMat4) -> Vec<DVec3> {
        self.local
            .iter()
            .map(|p| world.transform_point3(*p))
            .collect()
    }
}

/// Drives cloth vertices attached to joints of a skinned glTF character (a
/// [`weft_solver::PinDriver`]): positions from the joint's placed world transform at the
/// substep's time, velocities by a central difference over ±[`VELOCITY_STEP`].
#[derive(Debug)]
pub struct SkinAttachmentDriver {
    skin: Arc<SkinCollider>,
    attachments: Vec<JointAttachment>,
    particles: Vec<u32>,
}

impl SkinAttachmentDriver {
    /// Drives `attachments` (vertex indices of one cloth) with `skin`'s nodes; the cloth's
    /// vertex 0 is the solver's particle `first_particle`.
    pub fn new(
        skin: Arc<SkinCollider>,
        first_particle: usize,
        attachments: Vec<JointAttachment>,
    ) -> Result<Self, AttachError> {
        let particles = driven_particles(
            first_particle,
            attachments.iter().map(|a| (a.node, a.vertices.as_slice())),
            skin.mesh().nodes.len(),
        )?;
        Ok(Self {
            skin,
            attachments,
            particles,
        })
    }

    /// The attachments.
    pub fn attachments(&self) -> &[JointAttachment] {
        &self.attachments
    }
}

impl PinDriver for SkinAttachmentDriver {
    fn particles(&self) -> &[u32] {
        &self.particles
    }

    fn drive(&self, t: f64, positions: &mut [DVec3], velocities: &mut [DVec3]) {
        let now = self.skin.node_world(t);
        let before = self.skin.node_world(t - VELOCITY_STEP);
        let after = self.skin.node_world(t + VELOCITY_STEP);
        let mut k = 0;
        for a in &self.attachments {
            let (m, m0, m1) = (now[a.node], before[a.node], after[a.node]);
            for &p in &a.local {
                positions[k] = m.transform_point3(p);
                velocities[k] =
                    (m1.transform_point3(p) - m0.transform_point3(p)) / (2.0 * VELOCITY_STEP);
                k += 1;
            }
        }
    }
}
