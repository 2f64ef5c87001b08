//! The memory estimate's bound on particle contact's candidate pairs against the pairs the
//! list actually holds, frame by frame, on the shipped scene of that contact and on thick
//! cloths whose lists hold most pairs of particles.

use crate::common;

use weft_scene::{Scene, from_text};

/// Two `n`×`n` sheets of 1 m, `gap` apart, `thickness` thick, kept apart from each other
/// particle by particle.
fn two_sheets(n: usize, gap: f64, thickness: f64) -> String {
    let sheet = |name: &str, y: f64| {
        format!(
            "[cloth.{name}]\nresolution = [{n}, {n}]\nsize = [1.0, 1.0]\n\
             orientation = \"horizontal\"\ncenter = [0.0, {y}, 0.0]\nthickness = {thickness}\n\n"
        )
    };
    format!(
        "[sim]\nsubsteps = 4\n\n{}{}[self_collision]\nenabled = true\ncontact = \"particles\"\n",
        sheet("upper", 1.0 + gap),
        sheet("lower", 1.0)
    )
}

/// One falling `n`×`n` sheet `thickness` thick, colliding with itself.
fn one_sheet(n: usize, thickness: f64) -> String {
    format!(
        "[sim]\nsubsteps = 4\n\n[cloth.sheet]\nresolution = [{n}, {n}]\nsize = [1.0, 1.0]\n\
         orientation = \"vertical\"\npins = [\"top\"]\nthickness = {thickness}\n\n\
         [self_collision]\nenabled = true\ncontact = \"particles\"\n"
    )
}

/// The longest list over `frames` frames, against the scene's bound.
fn longest_list(scene: &Scene, frames: usize) -> (usize, u64) {
    let bound = scene.self_collision_pair_bound();
    let mut groups = scene.build().expect("scene builds");
    let mut longest = 0;
    for frame in 0..frames {
        for g in &mut groups {
            g.step().unwrap_or_else(|e| panic!("frame {frame}: {e}"));
            if let Some((_, _, listed)) = g.world.as_ref().and_then(|w| w.self_collision_lists()) {
                longest = longest.max(listed);
            }
        }
    }
    (longest, bound)
}

#[test]
fn self_collision_lists_never_outgrow_the_estimate() {
    let dir = common::scenes_dir();
    let files = weft_scene::DirFiles(dir.clone());
    let mut cases: Vec<(String, Scene, usize)> = vec![
        (
            "two sheets 1 mm apart, 1 m thick".into(),
            from_text("two.toml", &two_sheets(16, 0.001, 1.0), &[], &files).expect("valid"),
            3,
        ),
        (
            "a sheet 0.5 m thick".into(),
            from_text("one.toml", &one_sheet(24, 0.5), &[], &files).expect("valid"),
            20,
        ),
    ];
    cases.push((
        "self_fold.toml".into(),
        common::load(&dir.join("self_fold.toml"), &[]),
        60,
    ));
    for (name, scene, frames) in cases {
        let (longest, bound) = longest_list(&scene, frames);
        println!("{name}: longest list {longest} pairs, bound {bound}");
        assert!(longest > 0, "{name}: nothing listed");
        assert!(
            longest as u64 <= bound,
            "{name}: {longest} pairs > bound {bound}"
        );
    }
    // Where the list holds most pairs of the two sheets (1 m thick, as thick as a 1 m sheet
    // may be: every pair within reach) the bound is near: within 3×.
    let thick = from_text("two.toml", &two_sheets(16, 0.001, 1.0), &[], &files).expect("valid");
    let (longest, bound) = longest_list(&thick, 1);
    assert!(
        3 * longest as u64 > bound,
        "{longest} pairs against a bound of {bound}"
    );
}
