//! A skinned mesh as a deforming triangle-mesh collider: weft-collide asks for the vertices at
//! the end of every substep and gets [`SkinnedMesh::skin`] at that time (linear blend
//! skinning), then refits its BVH and sweeps contacts against the moving triangles.

use glam::DVec3;
use weft_collide::{ColliderDesc, MeshAnimation, ShapeDesc, TriangleMesh};

use super::{SkinError, SkinnedMesh};

/// A skinned mesh driving a deforming collider (add it with
/// `CollisionWorld::add_deforming_mesh(&collider.desc()?, Arc::new(collider))`): its vertices
/// at time t, in the collider's frame, are `SkinnedMesh::skin(t)`.
#[derive(Clone, Debug)]
pub struct SkinCollider {
    mesh: SkinnedMesh,
}

impl SkinCollider {
    /// The collider of `mesh`, animated by its own channels.
    pub fn new(mesh: SkinnedMesh) -> Self {
        Self { mesh }
    }

    /// The skinned mesh.
    pub fn mesh(&self) -> &SkinnedMesh {
        &self.mesh
    }

    /// The collider's description: the triangles at the pose of t = 0 (the rest shape the
    /// collision world keeps; the skinning, not these positions, gives every substep's
    /// vertices), no friction and no placement (set them on the result).
    pub fn desc(&self) -> Result<ColliderDesc, SkinError> {
        let vertices = self.mesh.skin(0.0);
        let mesh = TriangleMesh::new(vertices, self.mesh.triangles.clone())
            .map_err(|e| SkinError::Invalid(format!("skinned mesh as a collider: {e}")))?;
        Ok(ColliderDesc::new(ShapeDesc::TriMesh(mesh)))
    }
}

impl MeshAnimation for SkinCollider {
    /// Linear blend skinning at time `t` (s); the rest positions are not used.
    fn vertices_at(&self, t: f64, _rest: &[DVec3], out: &mut [DVec3]) {
        self.mesh.skin_into(t, out);
    }
}
