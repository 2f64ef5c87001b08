//! The viewer's character choices, free of any window: the clip the body plays, the garment
//! scene and each cloth's fabric, each applied by reloading the scene with overrides (the
//! scene file stays as written; the choice shows in the log's overrides when recording).

use std::str::FromStr;

use weft_scene::Override;

use crate::app::session::{SceneSource, Session};

/// A clip the character can play: the overrides of `[character]` that select it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Clip {
    /// Shown in the panel.
    pub label: &'static str,
    /// `(key, value)` overrides (values as TOML).
    pub keys: &'static [(&'static str, &'static str)],
}

/// The clips offered: the procedural walk cycle and the shipped CMU capture (with its body
/// table and the CMU conversion's unit, `weft_character::CMU_SCALE`). Paths are relative to
/// the shipped scenes in `assets/scenes`.
pub const CLIPS: [Clip; 2] = [
    Clip {
        label: "walk cycle (walker)",
        keys: &[
            ("character.skeleton", "\"walker\""),
            ("character.body", "\"walker\""),
        ],
    },
    Clip {
        label: "CMU 01_01: forward jumps",
        keys: &[
            ("character.skeleton", "\"../characters/cmu_01_01_4s.bvh\""),
            ("character.scale", "0.056444444444444446"),
            ("character.body", "\"cmu\""),
        ],
    },
];

/// `overrides` with `key` set to `value` (replacing an earlier value of that key).
pub fn with_override(overrides: &[Override], key: &str, value: &str) -> Vec<Override> {
    let mut out: Vec<Override> = overrides.iter().filter(|o| o.key != key).cloned().collect();
    // Keys come from this module's lists and cloth names: always well-formed.
    if let Ok(o) = Override::from_str(&format!("{key}={value}")) {
        out.push(o);
    }
    out
}

/// The clip in `overrides` (the last one whose skeleton override matches), if any.
pub fn current_clip(overrides: &[Override]) -> Option<usize> {
    let skeleton = overrides
        .iter()
        .rev()
        .find(|o| o.key == "character.skeleton")?;
    CLIPS.iter().position(|c| {
        c.keys
            .iter()
            .any(|(k, v)| *k == "character.skeleton" && *v == skeleton.value)
    })
}

impl Session {
    /// Reloads the scene from its source with its overrides changed by `change`, keeping
    /// the old scene if the new one does not load.
    fn reload_with(&mut self, change: impl Fn(&[Override]) -> Vec<Override>) -> anyhow::Result<()> {
        let overrides = change(&self.sim.scene.overrides);
        self.load(self.source.clone(), &overrides)
    }

    /// Plays clip `CLIPS[clip]` from its start (the scene reloaded with its overrides).
    pub fn set_clip(&mut self, clip: usize) -> anyhow::Result<()> {
        let chosen = CLIPS
            .get(clip)
            .ok_or_else(|| anyhow::anyhow!("no clip {clip}"))?;
        // Every clip's keys go first (the walker refuses a BVH's `scale`).
        let clip_key = |key: &str| CLIPS.iter().any(|c| c.keys.iter().any(|(k, _)| *k == key));
        self.reload_with(|o| {
            let rest: Vec<Override> = o.iter().filter(|o| !clip_key(&o.key)).cloned().collect();
            chosen
                .keys
                .iter()
                .fold(rest, |acc, (k, v)| with_override(&acc, k, v))
        })
    }

    /// Dresses cloth `cloth` (a scene cloth name) in the fabric preset `preset` (the scene
    /// reloaded with `cloth.<name>.material`).
    pub fn set_fabric(&mut self, cloth: &str, preset: &str) -> anyhow::Result<()> {
        let key = format!("cloth.{cloth}.material");
        self.reload_with(|o| with_override(o, &key, &format!("\"{preset}\"")))
    }

    /// Switches to the garment scene `source`, keeping the chosen clip.
    pub fn set_garment(&mut self, source: SceneSource) -> anyhow::Result<()> {
        let keep: Vec<Override> = self
            .sim
            .scene
            .overrides
            .iter()
            .filter(|o| o.key.starts_with("character."))
            .cloned()
            .collect();
        self.load(source, &keep)
    }
}

/// How the panel names the garment scene `source`: the stems of its cloths' garment files,
/// followed by the scene's own when it differs (`tshirt (character)`); `None` for a scene
/// without a `[character]` table (or one that does not parse).
pub fn garment_label(source: &SceneSource) -> Option<String> {
    let SceneSource::File(path) = source else {
        return None;
    };
    let doc: toml_edit::DocumentMut = std::fs::read_to_string(path).ok()?.parse().ok()?;
    doc.get("character")?;
    let stem = |p: &str| {
        std::path::Path::new(p)
            .file_stem()
            .map_or_else(|| p.to_owned(), |s| s.to_string_lossy().into_owned())
    };
    let garments: Vec<String> = doc
        .get("cloth")
        .and_then(|c| c.as_table_like())
        .map(|cloths| {
            cloths
                .iter()
                .filter_map(|(_, c)| c.get("garment")?.as_str().map(stem))
                .collect()
        })
        .unwrap_or_default();
    let scene = stem(&path.to_string_lossy());
    let garments = garments.join(", ");
    Some(if garments.is_empty() || garments == scene {
        scene
    } else {
        format!("{garments} ({scene})")
    })
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use weft_collide::{BodyPart, KinematicBody};

    use super::*;
    use crate::app::picking::Ray;
    use weft_sim::Simulation;

    fn skirt() -> Session {
        let source = SceneSource::File(PathBuf::from("assets/scenes/skirt.toml"));
        let scene = source.load(&[]).expect("the skirt scene");
        Session::new(Simulation::new(scene).expect("solvers"), source, 4)
    }

    /// The parts the viewer draws now, and the character's own parts at time `t`.
    /// The scene's character (the test scenes all have one).
    fn character_of(s: &Session) -> &weft_character::Character {
        &s.sim
            .scene
            .character
            .as_ref()
            .expect("a character")
            .character
    }

    fn drawn_and_at(
        s: &Session,
        t: f64,
    ) -> (Vec<weft_sim::body::PartPose>, Vec<weft_sim::body::PartPose>) {
        let drawn = weft_sim::body::parts(&s.sim)
            .into_iter()
            .map(|(_, p)| p)
            .collect();
        let mut at: Vec<BodyPart> = Vec::new();
        character_of(s).parts_at(t, &mut at);
        (drawn, at.iter().map(weft_sim::body::PartPose::of).collect())
    }

    #[test]
    fn step_pause_and_reset_carry_the_animation() {
        let mut s = skirt();
        let dt = s.dt();
        for _ in 0..3 {
            s.step_once().expect("steps");
        }
        let (drawn, want) = drawn_and_at(&s, 3.0 * dt);
        assert_eq!(drawn, want, "three steps: the body at 3 dt");
        let (_, start) = drawn_and_at(&s, 0.0);
        assert_ne!(drawn, start, "the body moved");
        // Paused, real time does not move it.
        s.clock.set_paused(true);
        std::thread::sleep(std::time::Duration::from_millis(40));
        s.advance(None).expect("advances");
        assert_eq!(drawn_and_at(&s, 0.0).0, drawn);
        // Reset: the clip starts again.
        s.reset().expect("resets");
        assert_eq!(drawn_and_at(&s, 0.0).0, start);
    }

    #[test]
    fn the_grabbed_garment_follows_the_mouse_while_the_body_moves() {
        use weft_solver::glam::DVec3;
        let mut s = skirt();
        for _ in 0..2 {
            s.step_once().expect("steps");
        }
        // Aim horizontally from outside the skirt at the middle of a triangle at its lowest
        // particle (at the particle itself the ray would graze the triangles' shared corner).
        let x = s.sim.cloth_positions(0);
        let centre = x.iter().copied().sum::<DVec3>() / x.len() as f64;
        let low = (0..x.len())
            .min_by(|&a, &b| x[a].y.total_cmp(&x[b].y))
            .expect("particles");
        let out = DVec3::new(x[low].x - centre.x, 0.0, x[low].z - centre.z).normalize();
        let facing = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| x[i as usize]);
            (b - a).cross(c - a).normalize_or_zero().dot(out).abs()
        };
        let tri = (s.sim.scene.cloths[0].mesh.triangles.iter())
            .filter(|t| t.contains(&(low as u32)))
            .max_by(|a, b| facing(a).total_cmp(&facing(b)))
            .expect("the particle is in a triangle");
        let aim = tri.iter().map(|&i| x[i as usize]).sum::<DVec3>() / 3.0;
        let ray = Ray {
            origin: aim + 2.0 * out,
            dir: -out,
        };
        assert!(s.grab(&ray, -out), "the hem is under the ray");
        let start = s.grab.as_ref().map(|g| g.target).expect("held");
        // The mouse moves 5 cm up.
        let up = Ray {
            origin: ray.origin + DVec3::new(0.0, 0.05, 0.0),
            dir: ray.dir,
        };
        s.drag(&up);
        let before = drawn_and_at(&s, 0.0).0;
        for _ in 0..6 {
            s.step_once().expect("steps");
        }
        assert_ne!(drawn_and_at(&s, 0.0).0, before, "the body moved meanwhile");
        let g = s.grab.as_ref().expect("still held");
        assert!((g.target - start - DVec3::new(0.0, 0.05, 0.0)).length() < 1e-9);
        let now = s.sim.cloth_positions(g.cloth)[g.particle];
        assert!(
            (now - g.target).length() < 1e-3,
            "held at {now}, target {}",
            g.target
        );
    }

    #[test]
    fn garments_are_named_by_their_garment_files() {
        let label = |f: &str| garment_label(&SceneSource::File(PathBuf::from(f)));
        assert_eq!(label("assets/scenes/skirt.toml").as_deref(), Some("skirt"));
        assert_eq!(
            label("assets/scenes/character.toml").as_deref(),
            Some("tshirt (character)")
        );
        assert_eq!(
            label("assets/scenes/glb_character.toml").as_deref(),
            Some("cape (glb_character)")
        );
        assert_eq!(label("assets/scenes/hanging.toml"), None);
        assert_eq!(garment_label(&SceneSource::Default), None);
    }

    #[test]
    fn clip_fabric_and_garment_reload_the_scene_with_overrides() {
        let mut s = skirt();
        s.step_once().expect("steps");
        let walker_joints = |s: &Session| character_of(s).animation().skeleton().len();
        let walker = walker_joints(&s);
        s.set_clip(1).expect("the CMU clip loads");
        assert_eq!(current_clip(&s.sim.scene.overrides), Some(1));
        assert_ne!(walker_joints(&s), walker, "the CMU skeleton");
        assert_eq!(s.sim.frame(), 0, "the clip starts at its beginning");
        s.set_fabric("skirt", "denim").expect("denim");
        let keys: Vec<String> = s
            .sim
            .scene
            .overrides
            .iter()
            .map(|o| o.to_string())
            .collect();
        assert!(
            keys.contains(&"cloth.skirt.material=\"denim\"".to_owned()),
            "{keys:?}"
        );
        assert_eq!(
            current_clip(&s.sim.scene.overrides),
            Some(1),
            "the clip stays"
        );
        let e = s
            .set_fabric("skirt", "tinfoil")
            .expect_err("no such preset");
        assert!(format!("{e:#}").contains("tinfoil"), "{e:#}");
        let cape = SceneSource::File(PathBuf::from("assets/scenes/cape.toml"));
        assert!(garment_label(&cape).is_some() && garment_label(&SceneSource::Default).is_none());
        // The cape hangs from the walker's Chest bone, which the CMU skeleton lacks: refused,
        // naming it, and the skirt stays.
        let e = s
            .set_garment(cape.clone())
            .expect_err("no Chest bone in CMU");
        assert!(format!("{e:#}").contains("Chest"), "{e:#}");
        assert_eq!(s.source, skirt().source);
        s.set_clip(0).expect("the walker again");
        assert_eq!(current_clip(&s.sim.scene.overrides), Some(0));
        s.set_garment(cape.clone()).expect("the cape on the walker");
        assert_eq!(s.source, cape);
        assert_eq!(
            current_clip(&s.sim.scene.overrides),
            Some(0),
            "the clip stays"
        );
        assert_eq!(walker_joints(&s), walker);
    }
}
