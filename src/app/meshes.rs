//! The renderer for a simulation, and the camera that frames it when the viewer opens:
//! the same meshes, ground and framing as `weft render` (src/video.rs).

use weft_render::{Camera, Renderer};

use crate::sim::Simulation;
use crate::video::{framing_camera, scene_meshes};

pub use crate::video::frame_poses as collider_poses;

/// A renderer drawing `sim` into targets of `format`, with its ground at the scene's ground
/// collider (or just under the lowest particle), and the camera framing the scene now.
pub fn renderer_for(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    sim: &Simulation,
) -> (Renderer, Camera) {
    let view = scene_meshes(sim);
    let mut renderer = Renderer::new(device, format, &view.meshes);
    renderer.set_ground_height(view.ground.unwrap_or_else(|| floor_under(sim)));
    (renderer, framing_camera(sim, &view))
}

/// The camera the viewer opens with (see [`crate::video::framing_camera`]: the bounding box
/// of the cloths and bounded colliders, framed by [`Camera::framing`]). The end-to-end test
/// frames its camera the same way to find a cloth pixel.
pub fn initial_camera(sim: &Simulation) -> Camera {
    framing_camera(sim, &scene_meshes(sim))
}

/// A floor just under everything when the scene has no ground, so nothing sinks into it.
fn floor_under(sim: &Simulation) -> f32 {
    let lowest = (0..sim.scene.cloths.len())
        .flat_map(|i| sim.cloth_positions(i).iter().map(|p| p.y as f32))
        .fold(0.0f32, f32::min);
    if lowest < 0.0 { lowest - 0.01 } else { 0.0 }
}
