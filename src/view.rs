//! What the renderer is shown of a simulation, for the window and `weft render` alike: the
//! cloth and collider meshes, the collider poses and the floor (`framing.rs` places the
//! camera).

use glam::Mat4;
use weft_render::{ClothTopology, Renderer, SceneMeshes, TriMesh};

use weft_sim::Simulation;

/// What the renderer draws for a simulation, and where its ground is.
pub struct SceneView {
    /// Cloth topologies and collider meshes, in scene order.
    pub meshes: SceneMeshes,
    /// Height of an upward-facing half-space collider, drawn as the ground (and left out of
    /// the meshes, so the two do not fight).
    pub ground: Option<f32>,
}

/// The colliders of a simulation (those of its first collision world: every solver group
/// holds the same ones).
fn colliders(sim: &Simulation) -> &[weft_collide::Collider] {
    sim.groups
        .iter()
        .find_map(|g| g.world.as_ref())
        .map(|w| w.colliders())
        .unwrap_or(&[])
}

/// Cloth topologies and tessellated colliders of `sim`.
pub fn scene_meshes(sim: &Simulation) -> SceneView {
    let cloths = sim
        .scene
        .cloths
        .iter()
        .map(|c| ClothTopology {
            particle_count: c.mesh.positions.len(),
            triangles: c.mesh.triangles.clone(),
        })
        .collect();
    let mut ground: Option<f32> = None;
    let mut colliders: Vec<TriMesh> = colliders(sim)
        .iter()
        .map(|c| match c.half_space_normal() {
            Some(n) if n.y > 0.999 => {
                let y = c.world_matrix().w_axis.y;
                ground = Some(ground.map_or(y, |g| g.max(y)));
                TriMesh::default()
            }
            _ => {
                let (positions, indices) = c.tessellate();
                TriMesh { positions, indices }
            }
        })
        .collect();
    // A character's body parts, each rigid in its own frame: made once, posed every frame.
    colliders.extend(weft_sim::body::parts(sim).iter().map(|(_, p)| {
        let (positions, indices) = weft_sim::body::mesh::round_cone(p.r0, p.r1, p.half_height());
        TriMesh { positions, indices }
    }));
    SceneView {
        meshes: SceneMeshes { cloths, colliders },
        ground,
    }
}

/// The deforming mesh colliders of `sim` (a skinned glTF character's body) at the solvers'
/// time, each with its index among the renderer's collider meshes: vertices in the
/// collider's frame (posed by [`frame_poses`]), triangles as in [`scene_meshes`].
pub fn deformed_meshes(sim: &Simulation) -> Vec<(usize, TriMesh)> {
    colliders(sim)
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_deforming())
        .filter_map(|(i, c)| {
            let vertices = c.mesh_vertices()?;
            let (_, indices) = c.tessellate();
            let positions = vertices.iter().map(|v| v.as_vec3()).collect();
            Some((i, TriMesh { positions, indices }))
        })
        .collect()
}

/// Gives `renderer` this frame's shape of every deforming collider of `sim`.
pub fn refresh_deformed(renderer: &mut Renderer, sim: &Simulation) {
    for (i, mesh) in deformed_meshes(sim) {
        renderer.set_collider_mesh(i, &mesh);
    }
}

/// The current world pose of each collider of `sim`, then of each body part (in the order of
/// [`scene_meshes`]).
pub fn frame_poses(sim: &Simulation) -> Vec<Mat4> {
    colliders(sim)
        .iter()
        .map(|c| c.world_matrix())
        .chain(weft_sim::body::parts(sim).iter().map(|(_, p)| p.matrix()))
        .collect()
}

/// Height of the floor drawn under `sim`: its upward half-space if it has one, else y = 0,
/// lowered under any cloth that starts below it.
pub fn floor_height(sim: &Simulation, view: &SceneView) -> f32 {
    view.ground.unwrap_or_else(|| {
        let lowest = (0..sim.scene.cloths.len())
            .flat_map(|i| sim.cloth_positions(i).iter().map(|p| p.y as f32))
            .fold(0.0f32, f32::min);
        if lowest < 0.0 { lowest - 0.01 } else { 0.0 }
    })
}

/// A renderer drawing `sim` into targets of `format`, with its floor (see [`floor_height`]),
/// and what it was made from (for [`crate::framing`]).
pub fn renderer_for(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    sim: &Simulation,
) -> (Renderer, SceneView) {
    let view = scene_meshes(sim);
    let mut renderer = Renderer::new(device, format, &view.meshes);
    renderer.set_ground_height(floor_height(sim, &view));
    (renderer, view)
}

#[cfg(test)]
mod tests {
    use weft_character::Geometry;

    use super::*;

    /// What the renderer is given for a character: one mesh per body part after the
    /// colliders, which its pose of the frame puts on the character's surface at the solvers'
    /// time (worked out apart, by weft-character).
    #[test]
    fn the_body_is_drawn_on_the_characters_surface_as_it_walks() {
        let source = std::path::Path::new("assets/scenes/skirt.toml");
        let scene = weft_scene::load(source, &[]).expect("the skirt scene");
        let mut sim = Simulation::new(scene).expect("solvers");
        let meshes = scene_meshes(&sim).meshes.colliders;
        let character = sim.scene.character.clone().expect("a character").character;
        let shapes = character.body().shapes().len();
        assert_eq!(meshes.len(), colliders(&sim).len() + shapes);
        for frame in 0..8 {
            if frame > 0 {
                sim.step().expect("a step");
            }
            let poses = frame_poses(&sim);
            let state = character.state(sim.groups[0].solver.time());
            let first = poses.len() - shapes;
            for (i, s) in state.shapes.iter().enumerate() {
                for v in &meshes[first + i].positions {
                    let w = poses[first + i].transform_point3(*v).as_dvec3();
                    let d = match s.geometry {
                        Geometry::Sphere { center, radius } => (w - center).length() - radius,
                        Geometry::RoundCone(c) => c.signed_distance(w),
                    };
                    assert!(d.abs() < 1e-5, "frame {frame}, part {i}: {d} m off");
                }
            }
        }
    }

    /// A skinned glTF character is drawn as it moves: its mesh for the renderer is the
    /// collider's vertices at the solvers' time, which is the skinning at that time.
    #[test]
    fn a_skinned_characters_body_is_drawn_as_skinned_at_the_solvers_time() {
        let source = std::path::Path::new("assets/scenes/glb_character.toml");
        let scene = weft_scene::load(source, &[]).expect("the glb scene");
        let mut sim = Simulation::new(scene).expect("solvers");
        let skin = sim.scene.model.clone().expect("a model").skin;
        let first = scene_meshes(&sim).meshes.colliders;
        for _ in 0..6 {
            sim.step().expect("a step");
        }
        let deformed = deformed_meshes(&sim);
        assert_eq!(deformed.len(), 1);
        let (i, mesh) = &deformed[0];
        assert_eq!(mesh.indices, first[*i].indices);
        let want = skin.vertices(sim.groups[0].solver.time());
        assert_eq!(mesh.positions.len(), want.len());
        let mut moved = 0.0f32;
        for ((p, w), p0) in mesh.positions.iter().zip(&want).zip(&first[*i].positions) {
            assert!((p.as_dvec3() - *w).length() < 1e-6, "{p} vs {w}");
            moved = moved.max((*p - *p0).length());
        }
        assert!(moved > 1e-3, "the drawn body did not move ({moved} m)");
    }
}
