//! Attachments: cloth vertices pinned to a bone (a waistband to the hips, a cape to the
//! shoulders), following the bone's rigid motion exactly.

use glam::DVec3;

use crate::animation::BoneState;
use crate::error::AttachError;
use crate::transform::Transform;

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
        let local = vertices
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
                Ok(inverse.transform_point(*p))
            })
            .collect::<Result<_, _>>()?;
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
