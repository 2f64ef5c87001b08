//! Step time per frame with and without collisions, at 32², 64², 128² and 256² particles,
//! on the scenario builders of `weft_collide::scenarios` (XPBD, `method_setup`):
//!
//! - `collide_sphere`: `sphere_drop` (a 1.6 m cloth draped over a sphere, and the ground),
//! - `collide_trimesh`: `mesh_drop` (a 1.2 m cloth on the triangle-mesh blob, and the ground),
//! - `collide_self`: `curtain_fold` at N×N (a curtain folding onto itself in layers:
//!   self-collision, ground).
//!
//! Each scenario is first stepped with its collision world until the cloth is in contact;
//! `with` then steps it through the world (`step_with`), frame after frame; `without` steps
//! copies of that state without any (`step`), also warm (`common::warm_frames`: a fresh copy
//! every 20 frames, so the cloth does not fall far). The difference is the collision cost per
//! frame.
//!
//! `self_vs_solve/16384` puts, at N = 128, the constraint solve (a frame without collisions),
//! the solve with self-collision only (no ground), and the self-collision hook alone (its
//! calls of one frame: per substep `begin_substep`, `project` per iteration, `end_substep`,
//! on the unmoving state) side by side.

mod common;

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BatchSize, Bencher, BenchmarkGroup, BenchmarkId, Criterion, SamplingMode, Throughput,
    criterion_group, criterion_main, measurement::WallTime,
};
use weft_collide::scenarios::{curtain_fold, mesh_drop, sphere_drop};
use weft_collide::{CollideError, CollisionWorld, SelfCollisionParams};
use weft_solver::{Method, Solver, SubstepContext, SubstepHook};

const SIZES: [usize; 4] = [32, 64, 128, 256];
/// Frames stepped with collisions before timing: 0.5 s, long enough for every scenario's
/// cloth to have fallen onto its collider.
const PREROLL: usize = 30;

type Scenario = fn(usize) -> Result<(Solver, CollisionWorld), CollideError>;

fn quick(g: &mut BenchmarkGroup<'_, WallTime>) {
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
}

/// Builds a scenario and steps it into contact.
fn in_contact(build: Scenario, n: usize) -> (Solver, CollisionWorld) {
    let (mut solver, mut world) = build(n).expect("scenario builds");
    for _ in 0..PREROLL {
        solver.step_with(&mut world).expect("stable");
    }
    (solver, world)
}

/// Warm frames of copies of `solver` stepped without collisions (see
/// `common::warm_frames`).
fn step_copies(b: &mut Bencher<'_, WallTime>, solver: &Solver) {
    common::warm_frames(b, solver, None);
}

fn with_and_without(c: &mut Criterion, name: &str, build: Scenario) {
    let mut g = c.benchmark_group(name);
    quick(&mut g);
    for n in SIZES {
        let start = std::time::Instant::now();
        let (mut solver, mut world) = in_contact(build, n);
        let bare = solver.clone();
        let contacts = solver.step_with(&mut world).expect("stable").contacts;
        eprintln!(
            "{name} {n}x{n}: {contacts} contacts in the last substep after the pre-roll ({:.1} s)",
            start.elapsed().as_secs_f64()
        );
        g.throughput(Throughput::Elements((n * n) as u64));
        g.bench_function(BenchmarkId::new("without", n * n), |b| {
            step_copies(b, &bare);
        });
        g.bench_function(BenchmarkId::new("with", n * n), |b| {
            b.iter(|| black_box(solver.step_with(&mut world).expect("stable")));
        });
    }
    g.finish();
}

fn sphere(c: &mut Criterion) {
    with_and_without(c, "collide_sphere", |n| sphere_drop(Method::Xpbd, n));
}

fn trimesh(c: &mut Criterion) {
    with_and_without(c, "collide_trimesh", |n| mesh_drop(Method::Xpbd, n));
}

fn self_collision(c: &mut Criterion) {
    with_and_without(c, "collide_self", |n| curtain_fold(Method::Xpbd, n));
}

/// One frame's worth of hook calls on `particles` (which do not move between substeps).
fn hook_frame(world: &mut CollisionWorld, solver: &Solver, particles: &mut weft_solver::Particles) {
    // Inside rayon's pool, as `Solver::step_with` runs its hooks.
    rayon::scope(|_| hook_calls(world, solver, particles));
}

fn hook_calls(world: &mut CollisionWorld, solver: &Solver, particles: &mut weft_solver::Particles) {
    let s = solver.settings();
    let h = s.h();
    for substep in 0..s.substeps {
        let ctx = SubstepContext {
            method: s.method,
            time: solver.time() + h * f64::from(substep + 1),
            h,
            substep,
            frame_end: solver.time() + h * f64::from(s.substeps),
        };
        world.begin_substep(&ctx, particles);
        for _ in 0..s.iterations {
            black_box(world.project(&ctx, particles));
        }
        world.end_substep(&ctx, particles);
    }
}

fn self_vs_solve(c: &mut Criterion) {
    let n = 128;
    let (solver, _) = in_contact(|n| curtain_fold(Method::Xpbd, n), n);
    let mut self_only = CollisionWorld::new(&solver);
    self_only
        .enable_self_collision(&solver, &[0], SelfCollisionParams::default())
        .expect("self-collision");
    let mut g = c.benchmark_group(format!("self_vs_solve/{}", n * n));
    quick(&mut g);
    g.throughput(Throughput::Elements((n * n) as u64));
    g.bench_function("constraint_solve", |b| {
        step_copies(b, &solver);
    });
    let mut both = solver.clone();
    let mut world = self_only.clone();
    g.bench_function("solve_and_self_collision", |b| {
        b.iter(|| black_box(both.step_with(&mut world).expect("stable")));
    });
    let mut world = self_only.clone();
    g.bench_function("self_collision_hook", |b| {
        b.iter_batched(
            || solver.particles().clone(),
            |mut p| {
                hook_frame(&mut world, &solver, &mut p);
                p
            },
            BatchSize::LargeInput,
        );
    });
    g.finish();
}

criterion_group!(benches, sphere, trimesh, self_collision, self_vs_solve);
criterion_main!(benches);
