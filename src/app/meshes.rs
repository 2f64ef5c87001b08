//! The renderer for a simulation, and the camera that frames it when the viewer opens:
//! the same meshes, ground and framing as `weft render` (src/video.rs).

use weft_render::{Camera, Renderer};

use crate::sim::Simulation;
use crate::video::{floor_height, framing_camera, scene_meshes};

pub use crate::video::frame_poses as collider_poses;

/// A renderer drawing `sim` into targets of `format`, with its floor where `weft render` puts
/// it, and the camera framing the scene now.
pub fn renderer_for(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    sim: &Simulation,
) -> (Renderer, Camera) {
    let view = scene_meshes(sim);
    let mut renderer = Renderer::new(device, format, &view.meshes);
    renderer.set_ground_height(floor_height(sim, &view));
    (renderer, framing_camera(sim, &view))
}

/// The camera that frames the scene now, as `weft render` does
/// ([`crate::video::framing_camera`]).
pub fn initial_camera(sim: &Simulation) -> Camera {
    framing_camera(sim, &scene_meshes(sim))
}
