//! Attachments: cloth vertices pinned to a bone (a waistband to the hips, a cape to the
//! shoulders), following the bone's rigid motion exactly.

use glam::DVec3;

use crate::animation::BoneState;
use crate::error::AttachError;
use crate::transform::Transform;

/// `vertices`' positions (indices into `positions`, world m) carried into a frame by
/// `to_local`; an index past `positions` or a non-finite position is an error.
pub(crate) fn local_coordinates(
    vertices: &[u32],
    positions: &[DVec3],
    to_local: impl Fn(DVec3) -> DVec3,
) -> Result<Vec<DVec3>, AttachError> {
    vertices
        .iter()
        .map(|&v| {
            let p = positions
                .get(v as usize)
                .ok_or(AttachError::VertexOutOfRange {
                    vertex: v,
                    len: positions.len(),
                })?;
            if !p.is_finite() {
                return Err(AttachError::NonFinite { vertex: v });
            }
            Ok(to_local(*p))
        })
        .collect()
}

/// The solver particles a pin driver moves: for each `(frame, vertices)` set, in order, the
/// cloth's vertices offset by `first_particle`; a frame index of `frames` or more (a bone or
/// node the character lacks) is an error.
pub(crate) fn driven_particles<'a>(
    first_particle: usize,
    sets: impl IntoIterator<Item = (usize, &'a [u32])>,
    frames: usize,
) -> Result<Vec<u32>, AttachError> {
    let mut particles = Vec::new();
    for (frame, vertices) in sets {
        if frame >= frames {
            return Err(AttachError::BoneOutOfRange {
                bone: frame,
                len: frames,
            });
        }
        for &v in vertices {
            let i = u32::try_from(first_particle + v as usize).map_err(|_| {
                AttachError::VertexOutOfRange {
                    vertex: v,
                    len: u32::MAX as usize,
                }
            })?;
            particles.push(i);
        }
    }
    Ok(particles)
}

/// A set of vertices held at fixed coordinates in one bone's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Attachment {
    bone: usize,
    vertices: Vec<u32>,
    local: Vec<DVec3>,
}

impl Attachment {
    /// Binds `vertices` (indices into `positions`, world m) to `bone`, whose world transform at
    /// binding time is `bind`: each vertex keeps its coordinates in the bone's frame.
    pub fn bind(
        bone: usize,
        vertices: Vec<u32>,
        positions: &[DVec3],
        bind: &Transform,
    ) -> Result<Self, AttachError> {
        let inverse = bind.inverse();
        let local = local_coordinates(&vertices, positions, |p| inverse.transform_point(p))?;
        Ok(Self {
            bone,
            vertices,
            local,
        })
    }

    /// The bone (joint index).
    pub fn bone(&self) -> usize {
        self.bone
    }

    /// The attached vertices.
    pub fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    /// Checks that the bone exists in a skeleton of `bones` joints.
    pub fn check_bone(&self, bones: usize) -> Result<(), AttachError> {
        if self.bone < bones {
            Ok(())
        } else {
            Err(AttachError::BoneOutOfRange {
                bone: self.bone,
                len: bones,
            })
        }
    }

    /// The vertices' coordinates in the bone's frame (in `vertices()` order).
    pub fn local(&self) -> &[DVec3] {
        &self.local
    }

    /// World positions of the attached vertices (in `vertices()` order) for the bone's world
    /// transform.
    pub fn positions(&self, bone: &Transform) -> Vec<DVec3> {
        self.local
            .iter()
            .map(|&p| bone.transform_point(p))
            .collect()
    }

    /// World velocities of the attached vertices for the bone's state: v + ω × r.
    pub fn velocities(&self, bone: &BoneState) -> Vec<DVec3> {
        self.local
            .iter()
            .map(|&p| bone.point_velocity(bone.transform.transform_point(p)))
            .collect()
    }
}
