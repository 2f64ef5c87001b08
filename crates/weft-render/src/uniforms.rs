//! The uniform block shared by every main-pass shader, the material palette and the sun.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::camera::Camera;
use crate::geometry::Bounds;
use crate::tile::Tile;

/// Materials in the palette: cloths cycle through the first [`CLOTH_MATERIALS`].
pub const CLOTH_MATERIALS: u32 = 6;
/// The colliders' material.
pub const COLLIDER_MATERIAL: u32 = 6;

/// Linear front and back colours of cloth materials: warm fronts, cool backs.
const CLOTH_COLOURS: [([f32; 3], [f32; 3]); CLOTH_MATERIALS as usize] = [
    ([0.80, 0.20, 0.09], [0.09, 0.22, 0.52]),
    ([0.85, 0.55, 0.08], [0.28, 0.12, 0.42]),
    ([0.12, 0.50, 0.30], [0.50, 0.44, 0.38]),
    ([0.70, 0.70, 0.72], [0.18, 0.18, 0.22]),
    ([0.55, 0.12, 0.40], [0.10, 0.38, 0.38]),
    ([0.20, 0.35, 0.75], [0.75, 0.55, 0.15]),
];
/// Linear colour of colliders: a cool steel grey.
const COLLIDER_COLOUR: [f32; 3] = [0.42, 0.45, 0.50];

/// The linear RGB front colour the renderer gives the cloth at index `i` of a scene (cloths
/// cycle through the palette in scene order), for legends and labels that name it.
pub fn cloth_colour(i: usize) -> [f32; 3] {
    CLOTH_COLOURS[i % CLOTH_COLOURS.len()].0
}

/// Direction towards the sun (normalised on use): 46° up, from the front left.
const SUN_DIR: Vec3 = Vec3::new(-0.55, 0.85, 0.6);

/// The unit direction towards the sun (the key light that casts shadows).
pub fn sun_direction() -> Vec3 {
    SUN_DIR.normalize()
}

/// Shadow-map side (texels).
pub const SHADOW_SIZE: u32 = 2048;

/// The main pass's uniforms; mirrors `Globals` in `scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Globals {
    view_proj: [[f32; 4]; 4],
    light_view_proj: [[f32; 4]; 4],
    inv_view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light_dir: [f32; 4],
    ground: [f32; 4],
    ground_center: [f32; 4],
    viewport: [f32; 4],
    palette: [[f32; 4]; 16],
}

/// Everything the globals are made from.
pub struct GlobalsInput<'a> {
    /// The camera.
    pub camera: &'a Camera,
    /// The part of the image the target holds (the whole image but for tiled renders).
    pub tile: Tile,
    /// The sun's view-projection.
    pub light_view_proj: Mat4,
    /// Whether shadows are sampled.
    pub shadows: bool,
    /// Whether grid lines are drawn on the ground.
    pub grid: bool,
    /// Ground height (m).
    pub ground_height: f32,
    /// Minor grid spacing (m).
    pub grid_spacing: f32,
    /// Whether the shader must encode sRGB itself (non-sRGB target).
    pub encode_srgb: bool,
}

impl Globals {
    /// Assembles the uniforms.
    pub fn new(i: &GlobalsInput) -> Self {
        let view_proj = i.tile.clip_from_full() * i.camera.view_proj(i.tile.full);
        let eye = i.camera.eye();
        let mut palette = [[0.0; 4]; 16];
        for (m, (front, back)) in CLOTH_COLOURS.iter().enumerate() {
            palette[2 * m] = [front[0], front[1], front[2], 0.0];
            palette[2 * m + 1] = [back[0], back[1], back[2], 0.0];
        }
        let c = COLLIDER_COLOUR;
        palette[2 * COLLIDER_MATERIAL as usize] = [c[0], c[1], c[2], 1.0];
        palette[2 * COLLIDER_MATERIAL as usize + 1] = [c[0], c[1], c[2], 1.0];
        palette[14] = [c[0], c[1], c[2], 1.0];
        palette[15] = [c[0], c[1], c[2], 1.0];
        // The ground reaches far enough to meet the horizon haze from any sensible zoom.
        let radius = (i.camera.distance * 12.0).clamp(8.0, 0.9 * i.camera.far);
        let l = SUN_DIR.normalize();
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            light_view_proj: i.light_view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            eye: eye.extend(1.0).to_array(),
            light_dir: [l.x, l.y, l.z, if i.shadows { 1.0 } else { 0.0 }],
            ground: [
                i.ground_height,
                i.grid_spacing,
                radius,
                if i.grid { 1.0 } else { 0.0 },
            ],
            ground_center: [
                i.camera.target.x,
                i.camera.target.z,
                if i.encode_srgb { 1.0 } else { 0.0 },
                0.0,
            ],
            viewport: [
                i.tile.size.x as f32,
                i.tile.size.y as f32,
                1.0 / SHADOW_SIZE as f32,
                0.0,
            ],
            palette,
        }
    }
}

/// The sun's orthographic view-projection covering `focus` (and the ground under it).
pub fn light_view_proj(focus: Bounds, ground_height: f32) -> Mat4 {
    let mut b = focus;
    if b.is_empty() {
        b.add(Vec3::splat(-1.0));
        b.add(Vec3::splat(1.0));
    }
    // Include the ground below the focus so shadows land on it.
    b.add(Vec3::new(b.min.x, ground_height, b.min.z));
    let (center, radius) = b.sphere();
    let radius = radius.max(0.1) * 1.05;
    let l = SUN_DIR.normalize();
    let eye = center + l * (2.0 * radius);
    let view = glam::camera::rh::view::look_at_mat4(eye, center, Vec3::Y);
    // The sun sees the ground shadow stretched by 1/sin(elevation); widen the box for it.
    let spread = radius * 1.6;
    let proj = glam::camera::rh::proj::directx::orthographic(
        -spread,
        spread,
        -spread,
        spread,
        0.0,
        4.0 * radius,
    );
    proj * view
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globals_match_the_shader_layout() {
        // 3 matrices + 5 vec4 + 16 palette vec4.
        assert_eq!(std::mem::size_of::<Globals>(), 3 * 64 + 5 * 16 + 16 * 16);
    }

    #[test]
    fn light_box_holds_the_focus_and_the_ground_under_it() {
        let mut b = Bounds::default();
        b.add(Vec3::new(-0.5, 1.0, -0.5));
        b.add(Vec3::new(0.5, 2.0, 0.5));
        let m = light_view_proj(b, 0.0);
        for p in [
            Vec3::new(-0.5, 1.0, -0.5),
            Vec3::new(0.5, 2.0, 0.5),
            Vec3::new(0.5, 0.0, -0.5),
            Vec3::new(-0.5, 0.0, 0.5),
        ] {
            let c = m.project_point3(p);
            assert!(c.x.abs() < 1.0 && c.y.abs() < 1.0, "{p:?} -> {c:?}");
            assert!(c.z > 0.0 && c.z < 1.0, "{p:?} -> {c:?}");
        }
    }
}
