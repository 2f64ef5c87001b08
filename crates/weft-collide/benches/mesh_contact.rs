//! Triangle-mesh contact against the cloth's own solve, side by side in one run (XPBD,
//! `method_setup`, 10 substeps, one iteration):
//!
//! - `static_mesh/16384`: a 128² cloth draped (after 30 frames) on `icosphere_drop`'s
//!   sphere-shaped mesh of 20,480 triangles, and the ground. `constraint_solve` steps the
//!   same state without any collision; `mesh` with the mesh (f64 path, contact grid) and the
//!   ground; `mesh_alone` with the mesh only; `mesh_parry` with the same mesh through parry's
//!   f32 projection (the path before Weft's own); `sphere` the same cloth after 30 frames on
//!   `sphere_drop`'s analytic sphere of the same size and the ground, `sphere_alone` on the
//!   sphere only.
//! - `static_mesh_draped/16384`: the same after 120 frames (2 s), when the cloth has come to
//!   rest over the ball and on the ground, not still sliding off it as at 30 frames: the bare
//!   solve, the mesh and ground, and the analytic sphere and ground.
//! - `deforming_mesh/8100`: a 90² cloth on `breathing_drop`'s deforming ball of 5,120
//!   triangles (the animation evaluated and the BVH refitted once a frame, the vertices moved,
//!   the faces recomputed and contacts swept every substep), against its own constraint
//!   solve.
//! - `deforming_mesh_draped/8100`: the same after 120 frames, the cloth come to rest on the
//!   breathing ball (it still rides the ball's motion).
//!
//! Every timed frame is warm: it follows the same copy's previous frame, as in a running app
//! (see `common::warm_frames`).

mod common;

use std::time::Duration;

use criterion::{
    Bencher, BenchmarkGroup, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
    measurement::WallTime,
};
use weft_collide::CollisionWorld;
use weft_collide::scenarios::{balls_alone, breathing_drop, icosphere_drop, sphere_drop};
use weft_solver::{Method, Solver};

/// Frames stepped before timing: the cloth has fallen onto the collider.
const PREROLL: usize = 30;

/// Frames stepped before timing the draped cloth: it has come to rest.
const DRAPED: usize = 120;

fn quick(g: &mut BenchmarkGroup<'_, WallTime>) {
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
}

fn in_contact(scene: (Solver, CollisionWorld)) -> (Solver, CollisionWorld) {
    after(PREROLL, scene)
}

/// `scene` after `frames` frames.
fn after(frames: usize, mut scene: (Solver, CollisionWorld)) -> (Solver, CollisionWorld) {
    for _ in 0..frames {
        scene.0.step_with(&mut scene.1).expect("stable");
    }
    scene
}

/// Warm frames of `solver` without collisions.
fn step_copies(b: &mut Bencher<'_, WallTime>, solver: &Solver) {
    common::warm_frames(b, solver, None);
}

/// Warm frames of `solver` through `world`.
fn step_with_copies(b: &mut Bencher<'_, WallTime>, solver: &Solver, world: &CollisionWorld) {
    common::warm_frames(b, solver, Some(world));
}

fn static_mesh(c: &mut Criterion) {
    let n = 128;
    let (solver, world) = in_contact(icosphere_drop(Method::Xpbd, n).expect("scene"));
    let (sphere_solver, sphere_world) = in_contact(sphere_drop(Method::Xpbd, n).expect("scene"));
    let mut parry = world.clone();
    parry.set_parry_meshes(true);
    let (mesh_alone, sphere_alone) = balls_alone(&solver, &sphere_solver).expect("each ball alone");
    let mut g = c.benchmark_group(format!("static_mesh/{}", n * n));
    quick(&mut g);
    g.throughput(Throughput::Elements((n * n) as u64));
    g.bench_function("constraint_solve", |b| step_copies(b, &solver));
    g.bench_function("mesh", |b| step_with_copies(b, &solver, &world));
    g.bench_function("mesh_alone", |b| step_with_copies(b, &solver, &mesh_alone));
    g.bench_function("mesh_parry", |b| step_with_copies(b, &solver, &parry));
    g.bench_function("sphere_solve", |b| step_copies(b, &sphere_solver));
    g.bench_function("sphere", |b| {
        step_with_copies(b, &sphere_solver, &sphere_world)
    });
    g.bench_function("sphere_alone", |b| {
        step_with_copies(b, &sphere_solver, &sphere_alone)
    });
    g.finish();
}

fn draped_mesh(c: &mut Criterion) {
    let n = 128;
    let (solver, world) = after(DRAPED, icosphere_drop(Method::Xpbd, n).expect("scene"));
    let (sphere_solver, sphere_world) = after(DRAPED, sphere_drop(Method::Xpbd, n).expect("scene"));
    let mut g = c.benchmark_group(format!("static_mesh_draped/{}", n * n));
    quick(&mut g);
    g.throughput(Throughput::Elements((n * n) as u64));
    g.bench_function("constraint_solve", |b| step_copies(b, &solver));
    g.bench_function("mesh", |b| step_with_copies(b, &solver, &world));
    g.bench_function("sphere_solve", |b| step_copies(b, &sphere_solver));
    g.bench_function("sphere", |b| {
        step_with_copies(b, &sphere_solver, &sphere_world)
    });
    g.finish();
}

fn deforming_mesh(c: &mut Criterion) {
    deforming_group(c, "deforming_mesh", PREROLL);
}

fn deforming_mesh_draped(c: &mut Criterion) {
    deforming_group(c, "deforming_mesh_draped", DRAPED);
}

/// The group `name` of the breathing ball's 90² cloth after `frames` frames: its bare solve
/// and its frame with the ball and the ground.
fn deforming_group(c: &mut Criterion, name: &str, frames: usize) {
    let n = 90;
    let (solver, world) = after(frames, breathing_drop(Method::Xpbd, n).expect("scene"));
    let mut g = c.benchmark_group(format!("{name}/{}", n * n));
    quick(&mut g);
    g.throughput(Throughput::Elements((n * n) as u64));
    g.bench_function("constraint_solve", |b| step_copies(b, &solver));
    g.bench_function("deforming", |b| step_with_copies(b, &solver, &world));
    g.finish();
}

criterion_group!(
    benches,
    static_mesh,
    draped_mesh,
    deforming_mesh,
    deforming_mesh_draped
);
criterion_main!(benches);
