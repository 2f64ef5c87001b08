//! Skinned meshes from glTF 2.0: a node hierarchy with rest transforms, one skin (joints and
//! inverse bind matrices), the skinned mesh's bind positions with up to four joint weights per
//! vertex, and node animation channels; linear blend skinning on the CPU at any time.
//!
//! Linear blend skinning (glTF 2.0 specification, §3.7.3): a vertex at bind position v moves
//! to Σₖ wₖ · G(jₖ) · B(jₖ) · v, with G the joint node's global transform at time t and B its
//! inverse bind matrix. The skinned mesh node's own transform is ignored, as the
//! specification requires. This module reads a parsed document and its buffers; reading
//! files (and external buffers) is [`crate::files`]'s job.
//!
//! Its modules:
//!
//! - `animation`: glTF node animation channels, interpolated linearly (slerp for rotations) or
//!   stepwise.
//! - `attach`: cloth vertices attached to a joint of a skinned character, following its node.
//! - `collider`: a skinned mesh as a deforming triangle-mesh collider for weft-collide.
//! - `load`: from a parsed glTF document and its buffers to a `SkinnedMesh`.

mod animation;
mod attach;
mod collider;
mod load;

use glam::{DMat4, DQuat, DVec3};
use thiserror::Error;

pub use animation::{Channel, ChannelValues, Interpolation};
pub use attach::{JointAttachment, SkinAttachmentDriver};
pub use collider::SkinCollider;
pub use load::{AnimationChoice, BufferSource, decode_data_uri, parse_gltf_slice};

/// A glTF that cannot be turned into a skinned mesh.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SkinError {
    /// The JSON or binary container is not valid glTF.
    #[error("not valid glTF: {0}")]
    Gltf(String),
    /// A buffer that cannot be read or decoded.
    #[error("buffer {index}: {message}")]
    Buffer {
        /// Buffer index.
        index: usize,
        /// What is wrong.
        message: String,
    },
    /// No node carries both a mesh and a skin.
    #[error("no node has both a mesh and a skin")]
    NoSkinnedMesh,
    /// A required accessor is missing.
    #[error("mesh {mesh}, primitive {primitive}: no {attribute}")]
    MissingAttribute {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The attribute (POSITION, JOINTS_0, WEIGHTS_0, indices).
        attribute: &'static str,
    },
    /// Something this reader does not support (named).
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// Data that is present but inconsistent (named).
    #[error("invalid: {0}")]
    Invalid(String),
    /// The chosen animation is not in the file (the message lists those that are).
    #[error("{0}")]
    NoSuchAnimation(String),
}

/// A node's rest transform (translation, rotation, scale) and parent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeRest {
    /// Parent node, `None` for a root.
    pub parent: Option<usize>,
    /// Rest translation.
    pub translation: DVec3,
    /// Rest rotation.
    pub rotation: DQuat,
    /// Rest scale.
    pub scale: DVec3,
}

/// A skinned, animated mesh read from glTF.
#[derive(Clone, Debug)]
pub struct SkinnedMesh {
    /// Every node of the document, in document order.
    pub nodes: Vec<NodeRest>,
    /// Nodes ordered parents first.
    pub order: Vec<usize>,
    /// Every node's name, in document order (empty for an unnamed node).
    pub names: Vec<String>,
    /// Node index of each skin joint.
    pub joints: Vec<usize>,
    /// Inverse bind matrix of each skin joint.
    pub inverse_bind: Vec<DMat4>,
    /// Bind-pose vertex positions of the skinned mesh (all its primitives).
    pub positions: Vec<DVec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Per vertex: four (skin joint, weight) pairs, weights summing to 1.
    pub influences: Vec<[(u16, f64); 4]>,
    /// Animation channels of the first animation (empty: the rest pose).
    pub channels: Vec<Channel>,
}

impl SkinnedMesh {
    /// End time of the animation (s); 0 without animation.
    pub fn duration(&self) -> f64 {
        self.channels
            .iter()
            .filter_map(|c| c.times.last().copied())
            .fold(0.0, f64::max)
    }

    /// Every node's global transform at time `t` (s), animation clamped to its keys.
    pub fn node_globals(&self, t: f64) -> Vec<DMat4> {
        let mut local: Vec<(DVec3, DQuat, DVec3)> = self
            .nodes
            .iter()
            .map(|n| (n.translation, n.rotation, n.scale))
            .collect();
        for c in &self.channels {
            c.apply(t, &mut local[c.node]);
        }
        let mut global = vec![DMat4::IDENTITY; self.nodes.len()];
        for &i in &self.order {
            let (tr, rot, sc) = local[i];
            let m = DMat4::from_scale_rotation_translation(sc, rot, tr);
            global[i] = match self.nodes[i].parent {
                Some(p) => global[p] * m,
                None => m,
            };
        }
        global
    }

    /// Skinning matrices G(j) · B(j) of every joint at time `t` (s).
    pub fn joint_matrices(&self, t: f64) -> Vec<DMat4> {
        let global = self.node_globals(t);
        self.joints
            .iter()
            .zip(&self.inverse_bind)
            .map(|(&node, ibm)| global[node] * *ibm)
            .collect()
    }

    /// Vertex positions at time `t` (s) by linear blend skinning.
    pub fn skin(&self, t: f64) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; self.positions.len()];
        self.skin_into(t, &mut out);
        out
    }

    /// [`Self::skin`] written into `out` (one per vertex; extra entries are left alone),
    /// without allocating the positions.
    pub fn skin_into(&self, t: f64, out: &mut [DVec3]) {
        let m = self.joint_matrices(t);
        for ((o, &v), inf) in out.iter_mut().zip(&self.positions).zip(&self.influences) {
            *o = inf
                .iter()
                .filter(|(_, w)| *w != 0.0)
                .map(|&(j, w)| m[j as usize].transform_point3(v) * w)
                .sum();
        }
    }
}
