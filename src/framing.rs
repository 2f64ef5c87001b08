//! Where the camera looks, for the window and `weft render` alike: the box holding what a
//! scene contains (its cloths, its bounded colliders, its character over a span of time),
//! the camera that frames that box, and the character's root that the viewer's camera
//! follows.

use glam::Vec3;
use weft_render::Camera;
use weft_sim::Simulation;

use crate::view::{SceneView, deformed_meshes, floor_height, frame_poses};

/// Colliders larger than this (m, box diagonal) are left out of the framing: a wall or a
/// half-space would shrink everything else to a dot.
const LARGEST_FRAMED: f32 = 20.0;

/// Times sampled per second of a character's clip when its bounds over a span are wanted.
const SAMPLES_PER_SECOND: f64 = 20.0;

/// An axis-aligned box, empty until a point is added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lowest corner.
    pub lo: Vec3,
    /// Highest corner.
    pub hi: Vec3,
}

impl Default for Bounds {
    fn default() -> Self {
        Self {
            lo: Vec3::splat(f32::INFINITY),
            hi: Vec3::splat(f32::NEG_INFINITY),
        }
    }
}

impl Bounds {
    /// Grows the box to hold `p` (non-finite points are ignored).
    pub fn add(&mut self, p: Vec3) {
        if p.is_finite() {
            self.lo = self.lo.min(p);
            self.hi = self.hi.max(p);
        }
    }

    /// Grows the box to hold `other`.
    pub fn union(&mut self, other: Bounds) {
        if !other.is_empty() {
            self.add(other.lo);
            self.add(other.hi);
        }
    }

    /// Whether no point was added.
    pub fn is_empty(&self) -> bool {
        !(self.lo.is_finite() && self.hi.is_finite())
    }

    /// The box's diagonal (m).
    pub fn diagonal(&self) -> f32 {
        if self.is_empty() {
            0.0
        } else {
            (self.hi - self.lo).length()
        }
    }
}

/// The box holding `sim`'s cloths and bounded colliders (character included) as they are
/// now.
pub fn content_now(sim: &Simulation, view: &SceneView) -> Bounds {
    let mut b = Bounds::default();
    for i in 0..sim.scene.cloths.len() {
        for p in sim.cloth_positions(i) {
            b.add(p.as_vec3());
        }
    }
    let deformed = deformed_meshes(sim);
    for (i, (mesh, pose)) in view
        .meshes
        .colliders
        .iter()
        .zip(frame_poses(sim))
        .enumerate()
    {
        let now = deformed
            .iter()
            .find(|(j, _)| *j == i)
            .map_or(&mesh.positions, |(_, m)| &m.positions);
        let mut c = Bounds::default();
        for p in now {
            c.add(pose.transform_point3(*p));
        }
        if c.diagonal() < LARGEST_FRAMED {
            b.union(c);
        }
    }
    b
}

/// The solvers' time (s).
fn time(sim: &Simulation) -> f64 {
    sim.groups.first().map_or(0.0, |g| g.solver.time())
}

/// The box the scene's character (walker, BVH or skinned glTF) takes up at any of the times
/// sampled from the solvers' time to `span` seconds later; empty without a character.
pub fn character_over(sim: &Simulation, span: f64) -> Bounds {
    let start = time(sim);
    let samples = (span.max(0.0) * SAMPLES_PER_SECOND)
        .ceil()
        .clamp(1.0, 600.0) as usize;
    let times = (0..=samples).map(|k| start + span.max(0.0) * k as f64 / samples as f64);
    let mut b = Bounds::default();
    if let Some(c) = &sim.scene.character {
        for t in times.clone() {
            for s in c.character.state(t).shapes {
                let (centre, r) = s.geometry.bounding_sphere();
                b.add((centre - r).as_vec3());
                b.add((centre + r).as_vec3());
            }
        }
    }
    if let Some(m) = &sim.scene.model {
        for t in times {
            for v in m.skin.vertices(t) {
                b.add(v.as_vec3());
            }
        }
    }
    b
}

/// The point the viewer's camera follows in a character scene: the root joint (the walker's
/// and a BVH's hips) or, for a skinned glTF model, its pelvis or hips joint (else its
/// top-most joint), now. `None` without a character.
pub fn character_anchor(sim: &Simulation) -> Option<Vec3> {
    let t = time(sim);
    if let Some(c) = &sim.scene.character {
        let world = c.character.animation().world(t);
        return world.first().map(|w| w.translation.as_vec3());
    }
    let m = sim.scene.model.as_ref()?;
    let mesh = m.skin.mesh();
    let depth = |mut n: usize| {
        let mut d = 0;
        while let Some(p) = mesh.nodes.get(n).and_then(|r| r.parent) {
            n = p;
            d += 1;
        }
        d
    };
    let mut joints = mesh.joints.clone();
    joints.sort_unstable();
    let named = joints.iter().copied().find(|&j| {
        mesh.names.get(j).is_some_and(|n| {
            let n = n.to_lowercase();
            n.contains("pelvis") || n.contains("hips")
        })
    });
    let node = named.or_else(|| joints.iter().copied().min_by_key(|&j| depth(j)))?;
    let world = m.skin.node_world(t);
    world.get(node).map(|w| w.w_axis.truncate().as_vec3())
}

/// A camera for an image of width/height `aspect` that frames `sim`: its cloths and bounded
/// colliders now, its character over the next `span` seconds, and the floor under them when
/// it is near (so shadows and the drop are in view).
pub fn framing_camera(sim: &Simulation, view: &SceneView, aspect: f32, span: f64) -> Camera {
    let mut b = content_now(sim, view);
    b.union(character_over(sim, span));
    let floor = floor_height(sim, view);
    if !b.is_empty() && floor < b.lo.y && b.lo.y - floor < 2.0 * b.diagonal() {
        // Take in the floor and the shadow of the box's underside on it (its corners carried
        // down along the sunlight), so hanging things show where their shadow falls.
        let sun = weft_render::sun_direction();
        let (a, c) = (b.lo, b.hi);
        for i in 0..4 {
            let corner = Vec3::new(
                if i & 1 == 0 { a.x } else { c.x },
                a.y,
                if i & 2 == 0 { a.z } else { c.z },
            );
            b.add(corner - sun * ((corner.y - floor) / sun.y.max(0.1)));
        }
    }
    Camera::framing_for(b.lo, b.hi, aspect)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::scene_meshes;

    fn sim(path: &str) -> Simulation {
        let scene = weft_scene::load(std::path::Path::new(path), &[]).expect("the scene loads");
        Simulation::new(scene).expect("solvers")
    }

    /// The skinned glTF character jumps: its pelvis rises, and the follow point with it.
    #[test]
    fn the_glb_characters_anchor_is_its_pelvis_and_rises_as_it_jumps() {
        let mut s = sim("assets/scenes/glb_character.toml");
        let start = character_anchor(&s).expect("an anchor");
        // The feet are on the floor at y = 0 and the pelvis about a metre up.
        assert!((0.6..1.3).contains(&start.y), "{start}");
        let mut highest = start.y;
        for _ in 0..120 {
            s.step().expect("a step");
            highest = highest.max(character_anchor(&s).expect("an anchor").y);
        }
        assert!(highest > start.y + 0.2, "{start} rose only to {highest}");
    }

    /// The walker's anchor is its hips, inside the body's bounds.
    #[test]
    fn the_walkers_anchor_is_its_hips() {
        let s = sim("assets/scenes/character.toml");
        let a = character_anchor(&s).expect("an anchor");
        let body = character_over(&s, 0.0);
        assert!(
            a.cmpge(body.lo).all() && a.cmple(body.hi).all(),
            "{a} {body:?}"
        );
        assert!((0.8..1.1).contains(&a.y), "{a}");
        assert_eq!(character_anchor(&sim("assets/scenes/compare.toml")), None);
    }

    /// The character's bounds over a span hold every pose in it: the top of the glTF jump
    /// is inside, though the first frame's box is not that tall.
    #[test]
    fn the_characters_bounds_over_a_span_take_in_the_whole_jump() {
        let s = sim("assets/scenes/glb_character.toml");
        let now = character_over(&s, 0.0);
        let jump = character_over(&s, 3.3);
        assert!(jump.hi.y > now.hi.y + 0.2, "{now:?} vs {jump:?}");
        let view = scene_meshes(&s);
        let camera = framing_camera(&s, &view, 4.0 / 3.0, 3.3);
        let size = glam::UVec2::new(800, 600);
        for y in [jump.lo.y, jump.hi.y] {
            let p = Vec3::new(0.5 * (jump.lo.x + jump.hi.x), y, 0.0);
            let px = camera.project(p, size).expect("in front");
            assert!(px.y > 0.0 && px.y < 600.0, "{p} at {px}");
        }
    }
}
