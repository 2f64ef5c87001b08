//! What the renderer needs from a simulation: cloth topology, collider meshes and poses, and
//! the camera that frames the scene when it opens.

use glam::{Mat4, Vec3};
use weft_render::{Camera, ClothTopology, SceneMeshes};

use crate::sim::Simulation;

/// The scene's cloths (in scene order) and colliders, for [`weft_render::Renderer::new`].
pub fn scene_meshes(sim: &Simulation) -> SceneMeshes {
    let cloths = sim
        .scene
        .cloths
        .iter()
        .enumerate()
        .map(|(i, c)| ClothTopology {
            particle_count: sim.cloth_positions(i).len(),
            triangles: c.mesh.triangles.clone(),
        })
        .collect();
    SceneMeshes {
        cloths,
        colliders: Vec::new(),
    }
}

/// The pose of every collider in [`scene_meshes`] order, at the current time.
pub fn collider_poses(_sim: &Simulation) -> Vec<Mat4> {
    Vec::new()
}

/// The camera the viewer opens with: [`Camera::framing`] of the bounding box of every
/// cloth particle at the current state. (The end-to-end test frames its camera the same way
/// to find a cloth pixel.)
pub fn initial_camera(sim: &Simulation) -> Camera {
    let mut min = Vec3::splat(f32::INFINITY);
    let mut max = Vec3::splat(f32::NEG_INFINITY);
    for i in 0..sim.scene.cloths.len() {
        for p in sim.cloth_positions(i) {
            let p = p.as_vec3();
            min = min.min(p);
            max = max.max(p);
        }
    }
    Camera::framing(min, max)
}
