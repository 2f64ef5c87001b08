//! Shared test helpers: the shipped scenes, loaded with overrides and switched to one method,
//! a hook that checks the particles after every substep, and a reference closest point on a
//! triangle.
//!
//! - `triangle`: weft-collide's reference closest point on a triangle, included by path.
//! - `watch`: weft-collide's hook that checks the particles after every substep, included by path.
#![allow(dead_code)]

#[path = "../../../../weft-collide/tests/integration/common/triangle.rs"]
pub mod triangle;
#[path = "../../../../weft-collide/tests/integration/common/watch.rs"]
pub mod watch;

use std::path::{Path, PathBuf};

use watch::Watch;
use weft_scene::{Override, Scene, SolverGroup};
use weft_solver::{Method, Particles, SubstepContext};

/// `assets/scenes`, the scenes Weft ships.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes")
}

/// The scene at `path` with `overrides` (`key=value`) applied.
pub fn load(path: &Path, overrides: &[String]) -> Scene {
    let ov: Vec<Override> = overrides
        .iter()
        .map(|s| s.parse().expect("valid override"))
        .collect();
    weft_scene::load(path, &ov).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()))
}

/// The scene at `path` with every cloth switched to `method`.
pub fn with_method(path: &Path, method: Method, extra: &[String]) -> Vec<SolverGroup> {
    let probe = load(path, extra);
    let mut ov: Vec<String> = extra.to_vec();
    ov.push(format!("sim.method={}", method.name()));
    for c in &probe.cloths {
        ov.push(format!("cloth.{}.method={}", c.name, method.name()));
    }
    load(path, &ov).build().expect("scene builds")
}

/// Steps `group` (which must have a collision world) `frames` frames, calling `check` after
/// every substep.
pub fn run_watched(
    group: &mut SolverGroup,
    frames: usize,
    mut check: impl FnMut(&SubstepContext, &Particles) + Send,
) {
    let world = group.world.as_mut().expect("the scene has colliders");
    let check =
        |ctx: &SubstepContext, p: &Particles, _: &weft_collide::CollisionWorld| check(ctx, p);
    let mut hook = Watch { world, check };
    for frame in 0..frames {
        if let Err(e) = group.solver.step_with(&mut hook) {
            panic!("frame {frame}: {e}");
        }
    }
}

/// The errors (line, key, message) of `text` loaded as `bad.toml` beside the shipped scenes;
/// panics when it loads.
pub fn errors(text: &str) -> Vec<(Option<usize>, String, String)> {
    let files = weft_scene::DirFiles(scenes_dir());
    match weft_scene::from_text("bad.toml", text, &[], &files) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => {
            e.0.iter()
                .map(|e| {
                    let line = match &e.origin {
                        weft_scene::Origin::File { line, .. } => *line,
                        weft_scene::Origin::CommandLine => None,
                    };
                    (line, e.key.clone(), e.message.clone())
                })
                .collect()
        }
    }
}

/// Each case's text fails to load with an error at its line and key whose message holds its
/// text.
pub fn assert_errors(cases: &[(String, usize, &str, &str)]) {
    for (text, line, key, message) in cases {
        let errs = errors(text);
        assert!(
            errs.iter()
                .any(|(l, k, m)| *l == Some(*line) && k == key && m.contains(message)),
            "expected line {line}, key {key}: {message}\ngot {errs:?}\nfor\n{text}"
        );
    }
}

/// Runs `group` for `frames` frames and returns the least distance from any particle to its
/// world's collider `k` seen after any substep (searched within 1 m), with the collider.
pub fn closest_approach(
    group: &mut SolverGroup,
    k: usize,
    frames: usize,
) -> (f64, weft_collide::Collider) {
    let collider = group.world.as_ref().expect("colliders").colliders()[k].clone();
    let mut worst = f64::INFINITY;
    run_watched(group, frames, |_, p| {
        for x in &p.positions {
            if let Some(s) = collider.closest(*x, 1.0) {
                worst = worst.min(s.distance);
            }
        }
    });
    (worst, collider)
}

/// The particle nearest the vertical axis through the origin (half a spacing off it for an
/// even grid centred there).
pub fn middle_particle(p: &Particles) -> weft_solver::glam::DVec3 {
    p.positions
        .iter()
        .copied()
        .min_by(|a, b| a.with_y(0.0).length().total_cmp(&b.with_y(0.0).length()))
        .expect("particles")
}
