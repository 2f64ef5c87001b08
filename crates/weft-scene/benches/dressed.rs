//! The walker in its T-shirt (assets/scenes/character.toml: 10,203 particles, 10 substeps,
//! body contact, self-collision), one frame at a time once the seams have closed, and the
//! same frame without self-collision and without any contact, so that the differences split
//! the cost into solve, body contact and self-collision; and the whole frame and the solve
//! with dihedral bending instead of the isometric bending the jersey preset gets. The skinned glTF character
//! in its cape (assets/scenes/glb_character.toml: 2,374 particles, a 5,126-triangle body
//! skinned once a frame, its vertices moved and faces recomputed every substep) split the
//! same way, and again in the finer cape of assets/garments/cape_fine.toml (8,097 particles)
//! at three points of the jump, each frame warm and from the same state. The walker's whole
//! frame under each of the four methods; last, the walker in two thin garments under mesh
//! contact, particle contact and none.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::time::{Duration, Instant};

use criterion::measurement::WallTime;
use criterion::{Bencher, Criterion, SamplingMode, criterion_group, criterion_main};
use weft_collide::CollisionWorld;
use weft_scene::{Override, SolverGroup};
use weft_solver::{Method, Particles, Solver, SubstepContext, SubstepHook};

/// An active hook that does nothing: the general step loop with no contact at all.
struct Nothing;

impl SubstepHook for Nothing {
    fn project(&mut self, _ctx: &SubstepContext, _p: &mut Particles) -> usize {
        0
    }
}

/// Frames a solve-only row steps one copy of its solver before taking a fresh one: with no body
/// under it the shirt falls, and stepped for as long as criterion asks it would leave the
/// divergence bound (10 km, about 2,700 frames) once the solve is fast enough. The copy, once
/// per 20 frames, is timed with them (about 0.1 % of a frame's time).
const REFRESH: usize = 20;

/// One timed frame of a solve-only row: `solver` stepped through the inert hook, replaced by a
/// copy of `fresh` every [`REFRESH`] frames (`frame` counts them).
fn solve_frame(solver: &mut Solver, fresh: &Solver, frame: &mut usize) {
    if *frame % REFRESH == 0 {
        *solver = fresh.clone();
    }
    *frame += 1;
    solver.step_with(&mut Nothing).unwrap();
}

/// Frames a warm row steps one copy before taking a fresh one.
const WARM_REFRESH: u64 = 10;

/// Times frames of copies of `solver` through copies of `world` (the inert hook without
/// one), each after an untimed frame of the same copy, a fresh copy every [`WARM_REFRESH`]
/// frames: every timed frame is warm, and every run times the same frames.
fn warm_frames(b: &mut Bencher<'_, WallTime>, solver: &Solver, world: Option<&CollisionWorld>) {
    let step = |s: &mut Solver, w: Option<&mut CollisionWorld>| match w {
        Some(w) => s.step_with(w).unwrap(),
        None => s.step_with(&mut Nothing).unwrap(),
    };
    b.iter_custom(|iters| {
        let mut total = Duration::ZERO;
        let mut copy: Option<(Solver, Option<CollisionWorld>)> = None;
        for i in 0..iters {
            if i % WARM_REFRESH == 0 {
                copy = None;
            }
            let (s, w) = copy.get_or_insert_with(|| {
                let (mut s, mut w) = (solver.clone(), world.cloned());
                step(&mut s, w.as_mut());
                (s, w)
            });
            let start = Instant::now();
            std::hint::black_box(step(s, w.as_mut()));
            total += start.elapsed();
        }
        total
    });
}

/// The T-shirt scene with `overrides`, stepped past its seam closing (0.1 s) and 0.1 s more.
fn dressed(overrides: &[&str]) -> SolverGroup {
    shipped("character.toml", overrides)
}

/// The shipped scene `name` with `overrides`, built and not stepped.
fn built(name: &str, overrides: &[&str]) -> SolverGroup {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/scenes")
        .join(name);
    let ov: Vec<Override> = overrides.iter().map(|s| s.parse().unwrap()).collect();
    let scene = weft_scene::load(&path, &ov).unwrap();
    scene.build().unwrap().remove(0)
}

/// The shipped scene `name` with `overrides`, stepped 12 frames (0.2 s).
fn shipped(name: &str, overrides: &[&str]) -> SolverGroup {
    let mut g = built(name, overrides);
    for _ in 0..12 {
        g.step().unwrap();
    }
    g
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("dressed walker frame");
    group
        .sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1));
    let mut full = dressed(&[]);
    assert!(full.delayed_self_collision.is_none());
    group.bench_function("tshirt: solve + body + self-collision", |b| {
        b.iter(|| full.step().unwrap())
    });
    let mut body = dressed(&["self_collision.enabled=false"]);
    group.bench_function("tshirt: solve + body", |b| b.iter(|| body.step().unwrap()));
    let fresh = dressed(&["self_collision.enabled=false"]).solver;
    let (mut solve, mut frame) = (fresh.clone(), 0);
    group.bench_function("tshirt: solve only", |b| {
        b.iter(|| solve_frame(&mut solve, &fresh, &mut frame))
    });
    // The jersey preset is soft per substep, so it bends isometrically (constant weights,
    // one division per hinge); the same shirt through dihedral angles (an atan2 and six
    // divisions per hinge) at about the stiffness the preset gave them, 1/(B |e|²/A_e).
    let dihedral = [
        "cloth.tshirt.bend_isometric_enabled=false",
        "cloth.tshirt.bend_dihedral_enabled=true",
        "cloth.tshirt.bend_dihedral_compliance=1.77e5",
    ];
    let mut angles = dressed(&dihedral);
    group.bench_function("tshirt, dihedral: solve + body + self-collision", |b| {
        b.iter(|| angles.step().unwrap())
    });
    let with_self_off: Vec<&str> = dihedral
        .iter()
        .copied()
        .chain(["self_collision.enabled=false"])
        .collect();
    let fresh = dressed(&with_self_off).solver;
    let (mut angles_solve, mut frame) = (fresh.clone(), 0);
    group.bench_function("tshirt, dihedral: solve only", |b| {
        b.iter(|| solve_frame(&mut angles_solve, &fresh, &mut frame))
    });
    // The skinned glTF character: its body a deforming mesh skinned every substep.
    let mut glb = shipped("glb_character.toml", &[]);
    group.bench_function("glb cape: solve + skinned body + self-collision", |b| {
        b.iter(|| glb.step().unwrap())
    });
    let mut glb_body = shipped("glb_character.toml", &["self_collision.enabled=false"]);
    group.bench_function("glb cape: solve + skinned body", |b| {
        b.iter(|| glb_body.step().unwrap())
    });
    let mut glb_solve = shipped("glb_character.toml", &["self_collision.enabled=false"]);
    group.bench_function("glb cape: solve only", |b| {
        b.iter(|| glb_solve.solver.step_with(&mut Nothing).unwrap())
    });
    // The same body under the cape of about 8,000 particles (cape_fine.toml, 8 mm edges): the
    // 5,126-triangle skinned mesh against a garment of the size the mesh-contact issue names.
    // Timed at three points of the jump (0.5, 1.5 and 2.5 s in), each frame warm and from the
    // same state, so that a run times the same part of the jump as the next.
    let fine = [
        "self_collision.enabled=false",
        "cloth.cape.garment=\"../garments/cape_fine.toml\"",
    ];
    let mut at = shipped("glb_character.toml", &fine);
    let mut stepped = 12;
    for frames in [30, 90, 150] {
        while stepped < frames {
            at.step().unwrap();
            stepped += 1;
        }
        let world = at.world.as_ref();
        group.bench_function(
            format!("glb cape 8k, frame {frames}: solve + skinned body"),
            |b| warm_frames(b, &at.solver, world),
        );
        group.bench_function(format!("glb cape 8k, frame {frames}: solve only"), |b| {
            warm_frames(b, &at.solver, None)
        });
    }
    group.finish();
}

/// The substeps a frame `weft check` advises for the walker's explicit springs under
/// `overrides`: the fewest inside the guaranteed (Gershgorin) bound.
fn stable_substeps(overrides: &[&str]) -> u64 {
    let g = built("character.toml", overrides);
    let dt = g.solver.settings().dt;
    g.solver.stability(0).unwrap().min_substeps(dt)
}

/// The whole walker frame (solve + body + self-collision) under each method, side by side
/// (`cargo bench -p weft-scene --bench dressed -- "walker by method"`): 10 substeps, but
/// explicit mass-spring at the fewest it is stable at (named in the bench's id).
fn by_method(c: &mut Criterion) {
    let mut group = c.benchmark_group("walker by method");
    group
        .sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1));
    for method in Method::ALL {
        let mut set = vec![format!("sim.method={}", method.name())];
        let mut name = method.name().to_owned();
        if method.is_explicit() {
            let ov: Vec<&str> = set.iter().map(String::as_str).collect();
            let n = stable_substeps(&ov);
            set.push(format!("sim.substeps={n}"));
            name = format!("{name} at {n} substeps");
        }
        let ov: Vec<&str> = set.iter().map(String::as_str).collect();
        let mut g = dressed(&ov);
        group.bench_function(name, |b| b.iter(|| g.step().unwrap()));
    }
    group.finish();
}

/// The walker in two thin garments (assets/scenes/layered_outfit.toml: the T-shirt under the
/// cape, 1.5 mm each, 12,577 particles) at 0.5 s, walking with its seams closed, each frame
/// warm and from the same state: under the scene's mesh contact, under particle contact, and
/// with no contact between or within the cloths, so that the differences are cloth contact's
/// cost (`cargo bench -p weft-scene --bench dressed -- "walker in two garments"`).
fn outfit(c: &mut Criterion) {
    let mut group = c.benchmark_group("walker in two garments");
    group
        .sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1));
    for (name, set) in [
        ("mesh contact", None),
        (
            "particle contact",
            Some("self_collision.contact=\"particles\""),
        ),
        ("no cloth contact", Some("self_collision.enabled=false")),
    ] {
        let ov: Vec<&str> = set.into_iter().collect();
        let mut g = shipped("layered_outfit.toml", &ov);
        for _ in 12..30 {
            g.step().unwrap();
        }
        assert!(g.delayed_self_collision.is_none());
        group.bench_function(name, |b| warm_frames(b, &g.solver, g.world.as_ref()));
    }
    group.finish();
}

criterion_group!(benches, bench, by_method, outfit);
criterion_main!(benches);
