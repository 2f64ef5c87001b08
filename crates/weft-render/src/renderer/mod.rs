//! The renderer: a scene's meshes staged on the CPU each frame (`staging.rs`, with the shadow
//! focus of `focus.rs`), uploaded to its GPU resources (`resources.rs`), and drawn by the
//! shadow and main passes (`passes.rs`).

mod focus;
mod passes;
mod resources;
mod staging;

use resources::Resources;
use staging::Staging;

use crate::scene::{FrameData, SceneMeshes, TriMesh};

/// Draws one scene; create it once, then [`update`](Self::update) and
/// [`render`](Self::render) every frame.
pub struct Renderer {
    res: Resources,
    staging: Staging,
    ground_height: f32,
}

impl Renderer {
    /// Creates the pipelines and buffers for `scene`, drawing into targets of `color_format`
    /// (an sRGB format is best; others get the sRGB curve applied in the shader).
    pub fn new(
        device: &wgpu::Device,
        color_format: wgpu::TextureFormat,
        scene: &SceneMeshes,
    ) -> Self {
        let staging = Staging::new(scene);
        Self {
            res: Resources::new(device, color_format, &staging),
            staging,
            ground_height: 0.0,
        }
    }

    /// The colour format this renderer draws into.
    pub fn color_format(&self) -> wgpu::TextureFormat {
        self.res.color_format
    }

    /// Puts the ground plane (and its grid) at height `y` (m); 0 by default.
    pub fn set_ground_height(&mut self, y: f32) {
        if y.is_finite() {
            self.ground_height = y;
        }
    }

    /// Replaces collider `i`'s mesh (in its own frame) with `mesh`, e.g. a deforming mesh's
    /// vertices at this frame; it must have the same triangles as the mesh it replaces, else
    /// nothing changes. Returns whether it was replaced; takes effect at the next
    /// [`update`](Self::update).
    pub fn set_collider_mesh(&mut self, i: usize, mesh: &TriMesh) -> bool {
        self.staging.set_collider_mesh(i, mesh)
    }

    /// Uploads the frame's positions, per-vertex normals and collider poses. Cloths whose
    /// position count does not match their topology keep their previous positions.
    pub fn update(&mut self, queue: &wgpu::Queue, frame: &FrameData) {
        self.staging.stage(frame);
        self.res.upload(queue, &self.staging);
    }
}
