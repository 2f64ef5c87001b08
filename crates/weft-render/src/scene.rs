//! What the renderer draws: the fixed meshes of a scene and the per-frame state.

use glam::{DVec3, Mat4, Vec3};

/// A triangle mesh in its local frame (colliders).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions (m).
    pub positions: Vec<Vec3>,
    /// Counter-clockwise triangles (outward normals), indices into `positions`.
    pub indices: Vec<[u32; 3]>,
}

/// The connectivity of one cloth; its positions come every frame in [`FrameData`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClothTopology {
    /// Number of particles.
    pub particle_count: usize,
    /// Triangles, indices into the particles; counter-clockwise seen from the front side.
    pub triangles: Vec<[u32; 3]>,
}

/// What the renderer draws, fixed at creation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneMeshes {
    /// The cloths.
    pub cloths: Vec<ClothTopology>,
    /// The colliders, each in its local frame.
    pub colliders: Vec<TriMesh>,
}

/// The per-frame, read-only state to draw.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameData<'a> {
    /// Positions of each cloth (f64, as the solver holds them).
    pub cloths: &'a [&'a [DVec3]],
    /// World transform of each collider.
    pub collider_poses: &'a [Mat4],
    /// `(cloth, particle)` being dragged: drawn marked.
    pub highlight: Option<(usize, usize)>,
    /// Where the mouse drags it: drawn as a marker joined to the particle by a line.
    pub drag_target: Option<Vec3>,
}

/// Which optional layers to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Cloth edges as lines over the shaded surface.
    pub wireframe: bool,
    /// Particles as small squares.
    pub particles: bool,
    /// The ground grid.
    pub grid: bool,
    /// Directional-light shadows on the ground, cloth and colliders.
    pub shadows: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            wireframe: false,
            particles: false,
            grid: true,
            shadows: true,
        }
    }
}
