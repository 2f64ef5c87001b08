//! The walker in its T-shirt (assets/scenes/character.toml: 10,172 particles, 10 substeps,
//! body contact, self-collision), one frame at a time once the seams have closed, and the
//! same frame without self-collision and without any contact, so that the differences split
//! the cost into solve, body contact and self-collision; and the whole frame and the solve
//! with dihedral bending instead of the isometric bending the jersey preset gets. The skinned glTF character
//! in its cape (assets/scenes/glb_character.toml: 2,374 particles, a 5,126-triangle body
//! skinned once a frame, its vertices moved and faces recomputed every substep) split the
//! same way, and again in the finer cape of assets/garments/cape_fine.toml (8,097 particles).
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::time::Duration;

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use weft_scene::{Override, SolverGroup};
use weft_solver::{Particles, Solver, SubstepContext, SubstepHook};

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

/// The T-shirt scene with `overrides`, stepped past its seam closing (0.1 s) and 0.1 s more.
fn dressed(overrides: &[&str]) -> SolverGroup {
    shipped("character.toml", overrides)
}

/// The shipped scene `name` with `overrides`, stepped 12 frames (0.2 s).
fn shipped(name: &str, overrides: &[&str]) -> SolverGroup {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/scenes")
        .join(name);
    let ov: Vec<Override> = overrides.iter().map(|s| s.parse().unwrap()).collect();
    let scene = weft_scene::load(&path, &ov).unwrap();
    let mut g = scene.build().unwrap().remove(0);
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
    // The same with the cape of about 8,000 particles (cape_fine.toml, 8 mm edges): the
    // 5,126-triangle skinned body against a garment of the size the mesh-contact issue names.
    let fine = [
        "self_collision.enabled=false",
        "cloth.cape.garment=\"../garments/cape_fine.toml\"",
    ];
    let mut fine_body = shipped("glb_character.toml", &fine);
    group.bench_function("glb cape 8k: solve + skinned body", |b| {
        b.iter(|| fine_body.step().unwrap())
    });
    let mut fine_solve = shipped("glb_character.toml", &fine);
    group.bench_function("glb cape 8k: solve only", |b| {
        b.iter(|| fine_solve.solver.step_with(&mut Nothing).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
