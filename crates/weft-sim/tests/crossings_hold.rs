//! No cloth passes through itself or another cloth: every shipped scene under every method,
//! every 10th frame after its garments' seams have closed, counted by the independent measure
//! (`weft_collide::crossings::measure`, through `Simulation`'s statistics, each solver's
//! cloths together, a closed seam's two sides as one vertex).
//!
//! The single sheets that fold over a collider (`sphere_drop.toml`, `table_drape.toml`,
//! `mesh_drape.toml`) and the thin layers (`layers.toml`, `towel_fold.toml`, `twist.toml`)
//! hold by mesh contact and are checked with the rest; the twist's turning pins
//! ([`PIN_DRIVEN`]) may force cloth through cloth, but only after the contact's fail-safe has
//! reported a pair it could not stop. The walker in two garments
//! (`layered_outfit.toml`, among [`HEAVY`]) is checked under XPBD alone, every frame, and
//! so are the skirt and the skinned character's cape under the default contact, every 10th
//! frame.

use std::path::{Path, PathBuf};

use weft_collide::ClothContactStats;
use weft_scene::Override;
use weft_sim::Simulation;
use weft_solver::Method;

/// Frames each scene runs under each method (2 s at 60 frames a second).
const FRAMES: u64 = 120;

/// Scenes checked for longer than [`FRAMES`]: `towel_fold.toml` folds its layers together
/// only after 2 s.
const LONGER: &[(&str, u64)] = &[("towel_fold.toml", 300)];

/// Scenes whose pins are driven through cloth by design: the twist's turning edge winds the
/// sheet until, past about half a turn, it drags cloth through cloth where no free particle
/// can give way. Their crossings must come after the fail-safe reports such a forced pair.
const PIN_DRIVEN: &[&str] = &["twist.toml"];

/// Scenes built to diverge under some method, by design.
const BUILT_TO_EXPLODE: &[&str] = &["explode.toml"];

/// The walker's and the skinned character's scenes: thousands of particles on a moving body
/// under four methods would hold the suite up for minutes (their own tests run them), and
/// explicit mass-spring needs far smaller substeps for their fabrics; and the cantilever
/// strip and the Cusick disc, which explicit mass-spring cannot hold at their substeps
/// (`weft check` says so).
const HEAVY: &[&str] = &[
    "cape.toml",
    "character.toml",
    "skirt.toml",
    "layered_outfit.toml",
    "glb_character.toml",
    "cantilever.toml",
    "cusick.toml",
];

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes")
}

/// What one run of a scene under one method found.
#[derive(Debug)]
pub struct Run {
    /// The method.
    pub method: Method,
    /// Frames checked (every 10th, once the seams have closed).
    pub checked: usize,
    /// The frame with the most crossings and how many, if any crossed.
    pub worst: Option<(u64, usize)>,
    /// Pairs the mesh contact's fail-safe found forced together by pins (every free particle
    /// of the pair frozen, the pins still driving it in), over every substep of the run (0
    /// without mesh contact).
    pub forced: u64,
    /// The first checked frame that crossed before any pair was forced, and its count: a
    /// crossing the contact let through, not one the pins made.
    pub unforced: Option<(u64, usize)>,
    /// Whether mesh contact ran.
    pub mesh: bool,
}

/// Runs `path` (with `extra` overrides) under every method for `frames` frames and counts the
/// crossings of every 10th frame after the seams have closed.
pub fn crossings_under_every_method(path: &Path, extra: &[String], frames: u64) -> Vec<Run> {
    (Method::ALL.into_iter())
        .map(|method| crossings_under(path, method, extra, frames))
        .collect()
}

/// Runs `path` (with `extra` overrides) under `method` for `frames` frames and counts the
/// crossings of every 10th frame after the seams have closed.
pub fn crossings_under(path: &Path, method: Method, extra: &[String], frames: u64) -> Run {
    let mut sim = simulation(path, method, extra);
    let sewn = sim
        .scene
        .cloths
        .iter()
        .filter(|c| !c.seams.is_empty())
        .map(|c| c.seam_time)
        .fold(0.0, f64::max);
    let mut run = Run {
        method,
        checked: 0,
        worst: None,
        forced: 0,
        unforced: None,
        mesh: false,
    };
    for k in 0..frames {
        // Measured only on the frames checked: the count costs about a frame.
        let checked = (k + 1) % 10 == 0;
        sim.set_measure_crossings(checked);
        let s = sim
            .step()
            .unwrap_or_else(|e| panic!("{} under {method}: {e}", path.display()));
        if !checked || s.time < sewn + 1e-9 {
            continue;
        }
        run.checked += 1;
        let n = s.crossings.expect("measured").crossings;
        if n > 0 && run.worst.is_none_or(|(_, w)| n > w) {
            run.worst = Some((s.frame, n));
        }
        if n > 0 && run.unforced.is_none() && forced_so_far(&sim) == 0 {
            run.unforced = Some((s.frame, n));
        }
    }
    run.forced = forced_so_far(&sim);
    run.mesh = mesh_contact(&sim).next().is_some();
    run
}

/// The statistics of every solver's mesh contact (none where it is off).
fn mesh_contact(sim: &Simulation) -> impl Iterator<Item = ClothContactStats> + '_ {
    (sim.groups.iter()).filter_map(|g| g.world.as_ref()?.cloth_contact_stats())
}

/// Pairs forced through each other by pins so far, over every solver's mesh contact.
fn forced_so_far(sim: &Simulation) -> u64 {
    mesh_contact(sim).map(|s| s.forced_so_far).sum()
}

/// The scene at `path` with every cloth switched to `method` (one solver for all).
fn simulation(path: &Path, method: Method, extra: &[String]) -> Simulation {
    let parse = |v: &[String]| -> Vec<Override> {
        v.iter()
            .map(|s| s.parse().expect("valid override"))
            .collect()
    };
    let load = |ov: &[String]| {
        weft_scene::load(path, &parse(ov)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    };
    let probe = load(extra);
    let mut ov = extra.to_vec();
    ov.push(format!("sim.method={}", method.name()));
    for c in &probe.cloths {
        ov.push(format!("cloth.{}.method={}", c.name, method.name()));
    }
    Simulation::new(load(&ov)).expect("the scene builds")
}

/// The shipped scenes but those listed in `except`, sorted.
fn shipped_but(except: &[&[&str]]) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("scenes folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            !except.iter().any(|list| list.contains(&name))
        })
        .collect();
    paths.sort();
    paths
}

#[test]
fn no_shipped_scene_crosses_under_any_method() {
    let paths = shipped_but(&[BUILT_TO_EXPLODE, HEAVY]);
    assert!(paths.len() >= 8, "{paths:?}");
    let mut failed = Vec::new();
    for path in &paths {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let frames = (LONGER.iter())
            .find(|(n, _)| *n == name)
            .map_or(FRAMES, |(_, f)| *f);
        for run in crossings_under_every_method(path, &[], frames) {
            println!("{} under {}: {run:?}", path.display(), run.method);
            assert!(run.checked >= 10, "{}: {run:?}", path.display());
            let let_through = if PIN_DRIVEN.contains(&name) {
                run.unforced
            } else {
                run.worst
            };
            if let Some((frame, n)) = let_through {
                failed.push(format!(
                    "{} under {}: {n} crossings at frame {frame}",
                    path.display(),
                    run.method
                ));
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn the_check_sees_a_cloth_pushed_through_another() {
    // An upright square pushed down through a flat sheet (held by its corners) by a linear
    // pin motion, no gravity, no contact: from about frame 15 to 35 it straddles the sheet,
    // and the count must see it there.
    let dir = std::env::temp_dir().join(format!("weft-crossings-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let path = dir.join("through.toml");
    std::fs::write(
        &path,
        "[sim]\ndt = \"1/60\"\nsubsteps = 10\ngravity = [0.0, 0.0, 0.0]\n\n\
         [cloth.lower]\nresolution = [12, 12]\nsize = [1.0, 1.0]\norientation = \"horizontal\"\n\
         center = [0.0, 1.0, 0.0]\npins = [\"top-left\", \"top-right\", \"bottom-left\", \"bottom-right\"]\n\n\
         [cloth.upper]\nresolution = [5, 5]\nsize = [0.3, 0.3]\norientation = \"vertical\"\n\
         center = [0.03, 1.2, 0.03]\npins = [\"top\"]\n\
         motion = { kind = \"linear\", velocity = [0.0, -0.6, 0.0] }\n",
    )
    .expect("written");
    let runs = crossings_under_every_method(&path, &[], 60);
    let _ = std::fs::remove_dir_all(&dir);
    for run in &runs {
        println!("{run:?}");
        assert_eq!(run.checked, 6);
        assert!(run.worst.is_some(), "{run:?}");
    }
}

/// Runs shipped scene `name` under XPBD for `frames` frames, as shipped (self-collision on,
/// no contact named), and asserts that mesh contact ran, that at least 10 frames were counted
/// after the seams closed, that none crossed and that no pin forced cloth through cloth.
fn holds_by_the_default_contact(name: &str, frames: u64) {
    let run = crossings_under(&scenes_dir().join(name), Method::Xpbd, &[], frames);
    println!("{name}: {run:?}");
    assert!(run.mesh, "{name}: mesh contact is the default");
    assert!(run.checked >= 10, "{name}: {run:?}");
    assert_eq!(run.worst, None, "{name}: {run:?}");
    assert_eq!(
        run.forced, 0,
        "{name}: no pin drove cloth through cloth: {run:?}"
    );
}

#[test]
fn the_skinned_cape_holds_by_the_default_contact() {
    // Kept apart particle by particle instead (5 mm on this mesh), its folds let up to 760
    // crossings through within 2 s.
    holds_by_the_default_contact("glb_character.toml", FRAMES);
}

#[test]
fn the_skirt_holds_by_the_default_contact() {
    // Mesh contact from the first substep, through the sewing (0.6 s) and into the walk. Kept
    // apart particle by particle instead (4 mm on a 1.5 cm mesh), its folds let up to 450
    // crossings through after the sewing.
    holds_by_the_default_contact("skirt.toml", FRAMES + 30);
}

#[test]
fn the_walker_in_two_thin_garments_never_crosses() {
    // The T-shirt under the cape, both 1.5 mm, under mesh contact: through the sewing (the
    // seams close over the first 0.1 s) and into the walk, every frame counted. Turned on
    // only after the sewing, contact met the 400-odd crossings the sewing had made.
    let path = scenes_dir().join("layered_outfit.toml");
    let mut sim = simulation(&path, Method::Xpbd, &[]);
    sim.set_measure_crossings(true);
    for _ in 0..90 {
        let s = sim.step().expect("steps");
        let c = s.crossings.expect("measured");
        assert_eq!(c.crossings, 0, "frame {}: {c:?}", s.frame);
    }
    assert_eq!(forced_so_far(&sim), 0, "no pin drove cloth through cloth");
}
