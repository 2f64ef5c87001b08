//! The viewer's camera beyond orbit, pan and zoom: F (or Home) frames what the scene
//! contains now, and "follow" carries the camera along with a character's root as it walks
//! or jumps (on by default in character scenes).

use glam::{UVec2, Vec3};
use weft_render::Camera;
use weft_sim::Simulation;

use crate::framing;
use crate::view::scene_meshes;

/// How far ahead a character's motion is framed (s): room for the arms and legs of the next
/// second's moves around its followed root.
pub const CHARACTER_SPAN: f64 = 1.0;

/// The orbit camera and what moves it besides the mouse.
#[derive(Clone, Debug)]
pub struct ViewCamera {
    /// The camera drawn with.
    pub camera: Camera,
    /// Whether the camera follows the character (character scenes only).
    pub follow: bool,
    /// The character's root where the camera last followed it.
    anchor: Option<Vec3>,
}

impl ViewCamera {
    /// `camera` on `sim`, following its character if it has one.
    pub fn new(camera: Camera, sim: &Simulation) -> Self {
        let anchor = framing::character_anchor(sim);
        Self {
            camera,
            follow: anchor.is_some(),
            anchor,
        }
    }

    /// Whether `sim` has a character to follow.
    pub fn can_follow(&self) -> bool {
        self.anchor.is_some()
    }

    /// Frames what `sim` contains now (cloths, bounded colliders, and the character over the
    /// next [`CHARACTER_SPAN`]) from the default 3/4 angle, in a view of `size` pixels whose
    /// right `covered` pixels are under the side panel: the scene is centred in the rest.
    pub fn frame(&mut self, sim: &Simulation, size: UVec2, covered: f32) {
        let covered = covered.clamp(0.0, 0.8 * size.x as f32);
        let aspect = (size.x as f32 - covered).max(1.0) / size.y.max(1) as f32;
        self.camera = framing::framing_camera(sim, &scene_meshes(sim), aspect, CHARACTER_SPAN);
        // Slide the picture left by half the covered width.
        self.camera.pan(-0.5 * covered, 0.0, size);
        self.anchor = framing::character_anchor(sim);
    }

    /// Moves the camera (target and eye together) by as much as the character's root moved
    /// since the last call, when following; notes where the root is either way.
    pub fn track(&mut self, sim: &Simulation) {
        let now = framing::character_anchor(sim);
        if self.follow
            && let (Some(before), Some(now)) = (self.anchor, now)
        {
            self.camera.target += now - before;
        }
        self.anchor = now;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sim(path: &str) -> Simulation {
        let scene = weft_scene::load(std::path::Path::new(path), &[]).expect("the scene loads");
        Simulation::new(scene).expect("solvers")
    }

    /// Following keeps the character's root where it was on screen while it jumps; without
    /// it, the camera stays put and the root leaves that spot.
    #[test]
    fn follow_keeps_the_jumping_characters_root_in_place_on_screen() {
        let mut s = sim("assets/scenes/glb_character.toml");
        let size = UVec2::new(1280, 800);
        let mut on = ViewCamera::new(Camera::default(), &s);
        assert!(
            on.follow && on.can_follow(),
            "on by default for a character"
        );
        on.frame(&s, size, 0.0);
        let mut off = on.clone();
        off.follow = false;
        let framed = off.camera;
        let root = |s: &Simulation| framing::character_anchor(s).expect("a root");
        let start = on.camera.project(root(&s), size).expect("in view");
        let mut drift_off = 0.0f32;
        for _ in 0..90 {
            s.step().expect("a step");
            on.track(&s);
            off.track(&s);
            let followed = on.camera.project(root(&s), size).expect("in view");
            assert!((followed - start).length() < 0.5, "{followed} vs {start}");
            let still = off.camera.project(root(&s), size).expect("in view");
            drift_off = drift_off.max((still - start).length());
        }
        assert!(drift_off > 20.0, "the root moved only {drift_off} px");
        assert_eq!(off.camera, framed, "a camera not following stays put");
    }

    /// F frames the scene from the default angle whatever the camera did before.
    #[test]
    fn frame_undoes_orbit_pan_and_zoom() {
        let s = sim("assets/scenes/compare.toml");
        let size = UVec2::new(1280, 800);
        let mut c = ViewCamera::new(Camera::default(), &s);
        assert!(!c.follow && !c.can_follow(), "nothing to follow");
        c.frame(&s, size, 300.0);
        let framed = c.camera;
        c.camera.orbit(200.0, -50.0);
        c.camera.pan(30.0, 10.0, size);
        c.camera.zoom(3.0);
        assert_ne!(c.camera, framed);
        c.frame(&s, size, 300.0);
        assert_eq!(c.camera, framed);
        // The scene is centred left of the panel: the framed box's centre is in the middle of
        // the 980 pixels the panel leaves.
        let centre = framing::framing_camera(&s, &scene_meshes(&s), 1.0, 0.0).target;
        let at = c.camera.project(centre, size).expect("in view");
        assert!(
            (at.x - 490.0).abs() < 1.0 && (at.y - 400.0).abs() < 1.0,
            "{at}"
        );
        c.frame(&s, size, 0.0);
        assert_ne!(c.camera, framed);
    }
}
