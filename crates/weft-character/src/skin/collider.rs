//! A skinned mesh as a deforming triangle-mesh collider: weft-collide asks for the vertices at
//! the end of every frame and gets [`SkinnedMesh::skin`] at that time (linear blend
//! skinning), placed in the world, moves the mesh there linearly over the frame's substeps,
//! refits its BVH once a frame and sweeps contacts against the moving triangles.

use glam::{DMat4, DVec3};
use weft_collide::{ColliderDesc, MeshAnimation, ShapeDesc, TriangleMesh};

use super::{SkinError, SkinnedMesh};
use crate::clip::Wrap;

/// A skinned mesh driving a deforming collider (add it with
/// `CollisionWorld::add_deforming_mesh(&collider.desc()?, Arc::new(collider))`): its vertices
/// at time t, in the collider's frame, are `placement · SkinnedMesh::skin(t')`, with t' the
/// clip time (t clamped to the animation's keys, or t modulo its duration when looping).
#[derive(Clone, Debug)]
pub struct SkinCollider {
    mesh: SkinnedMesh,
    placement: DMat4,
    wrap: Wrap,
}

impl SkinCollider {
    /// The collider of `mesh`, animated by its own channels (clamped), not moved.
    pub fn new(mesh: SkinnedMesh) -> Self {
        Self::placed(mesh, DMat4::IDENTITY, Wrap::Clamp)
    }

    /// The collider of `mesh` with its skinned vertices carried by `placement` (e.g. a scale
    /// from the file's unit to metres, a turn from z-up to y-up, an offset), the animation
    /// played as `wrap` says.
    pub fn placed(mesh: SkinnedMesh, placement: DMat4, wrap: Wrap) -> Self {
        Self {
            mesh,
            placement,
            wrap,
        }
    }

    /// The skinned mesh.
    pub fn mesh(&self) -> &SkinnedMesh {
        &self.mesh
    }

    /// The placement applied after skinning.
    pub fn placement(&self) -> DMat4 {
        self.placement
    }

    /// The animation's time at solver time `t` (s): `t` when clamped, `t` modulo the
    /// animation's duration when looping.
    pub fn clip_time(&self, t: f64) -> f64 {
        let d = self.mesh.duration();
        match self.wrap {
            Wrap::Loop if d > 0.0 && t.is_finite() => t.rem_euclid(d),
            _ => t,
        }
    }

    /// Every glTF node's placed world transform at solver time `t` (s):
    /// `placement · G(clip_time(t))`.
    pub fn node_world(&self, t: f64) -> Vec<DMat4> {
        let mut g = self.mesh.node_globals(self.clip_time(t));
        for m in &mut g {
            *m = self.placement * *m;
        }
        g
    }

    /// The placed, skinned vertices at solver time `t` (s).
    pub fn vertices(&self, t: f64) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; self.mesh.positions.len()];
        self.vertices_into(t, &mut out);
        out
    }

    /// [`Self::vertices`] written into `out` (one per vertex).
    pub fn vertices_into(&self, t: f64, out: &mut [DVec3]) {
        self.mesh.skin_into(self.clip_time(t), out);
        if self.placement != DMat4::IDENTITY {
            for v in out.iter_mut() {
                *v = self.placement.transform_point3(*v);
            }
        }
    }

    /// The collider's description: the triangles at the pose of t = 0 (the rest shape the
    /// collision world keeps; the skinning, not these positions, gives every frame's
    /// vertices), no friction and no placement of its own (set them on the result).
    pub fn desc(&self) -> Result<ColliderDesc, SkinError> {
        let mesh = TriangleMesh::new(self.vertices(0.0), self.mesh.triangles.clone())
            .map_err(|e| SkinError::Invalid(format!("skinned mesh as a collider: {e}")))?;
        Ok(ColliderDesc::new(ShapeDesc::TriMesh(mesh)))
    }
}

impl MeshAnimation for SkinCollider {
    /// Linear blend skinning at time `t` (s), placed; the rest positions are not used.
    fn vertices_at(&self, t: f64, _rest: &[DVec3], out: &mut [DVec3]) {
        self.vertices_into(t, out);
    }
}
