//! A garment's frame on the walking walker, split: an ≥ 8,000-particle sheet draped over the
//! walker (1 cm edges; 10 substeps, 1 iteration, XPBD) stepped one frame at a time, after 40
//! frames of walking so it lies on the body:
//!
//! - `solve/fused`: no hook (the solver fuses each substep's phases);
//! - `solve/general`: an inert but active hook (the general loop the collision world runs in);
//!   with no body under it the sheet falls, so both are timed on warm frames of copies made
//!   every 20 frames;
//! - `body`: + the walker as a kinematic body (broad phase, sweep, contact planes, friction);
//! - `body+self`: + self-collision;
//! - `contact-only`: the body's own work for one frame without the solver: ten substeps of the
//!   world's `begin_substep` (poses, broad phase) and first `project` (sweep, contact planes,
//!   friction) on a copy of the warmed-up particles.
//!
//! Differences of medians give the body contact's and self-collision's shares.

use std::hint::black_box;
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::measurement::WallTime;
use criterion::{BatchSize, Bencher};
use criterion::{Criterion, criterion_group, criterion_main};
use weft_character::Character;
use weft_character::garment::{GarmentSpec, build_garment};
use weft_collide::{CollisionWorld, Friction, SelfCollisionParams};
use weft_solver::{
    ClothParams, Forces, Settings, Solver, SolverBuilder, SubstepContext, SubstepHook,
};

/// Frames stepped from one copy of the solver before the next copy is made, where nothing
/// holds the sheet: falling freely, it would leave the divergence bound after some thousands
/// of frames (a fast solver gets there within criterion's measurement time).
const REFRESH: u64 = 20;

/// Times warm frames of copies of `solver`, each stepped by `step`: a fresh copy, stepped
/// once untimed, every [`REFRESH`] frames.
fn warm_frames(b: &mut Bencher<'_, WallTime>, solver: &Solver, step: impl Fn(&mut Solver)) {
    b.iter_custom(|iters| {
        let mut total = Duration::ZERO;
        let mut copy = solver.clone();
        for i in 0..iters {
            if i % REFRESH == 0 {
                copy = solver.clone();
                step(&mut copy);
            }
            let start = Instant::now();
            step(&mut copy);
            total += start.elapsed();
        }
        total
    });
}

/// Active, does nothing: forces the general loop.
struct Inert;

impl SubstepHook for Inert {}

/// A 0.95 m square sheet, 1 cm edges, laid flat just above the walker's head: it falls onto
/// the head and shoulders and drapes over the swinging arms (a ghost costume: most of its
/// particles touch the body, as a shirt's do).
const SHEET: &str = r#"edge_length = 0.0095
area_density = 0.15

[[panel]]
name = "sheet"
outline = [[-0.475, -0.475], [0.475, -0.475], [0.475, 0.475], [-0.475, 0.475]]
position = [0.0, 1.8, 0.0]
rotation = [90.0, 0.0, 0.0]
"#;

/// The sheet on the walker: solver, and a world with the body (and self-collision if asked).
fn dressed(body: bool, self_collision: bool) -> (Solver, CollisionWorld) {
    let walker = Arc::new(Character::walker());
    let sheet = build_garment(&GarmentSpec::from_toml(SHEET).expect("spec")).expect("sheet");
    assert!(
        sheet.mesh.positions.len() >= 8000,
        "{}",
        sheet.mesh.positions.len()
    );
    let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("settings");
    b.add_cloth("sheet", &sheet.mesh, ClothParams::default(), 0.004)
        .expect("cloth");
    let mut solver = b.build();
    let mut world = CollisionWorld::new(&solver);
    if body {
        world.add_body(walker, Friction::default()).expect("body");
    }
    if self_collision {
        world
            .enable_self_collision(&solver, &[0], SelfCollisionParams::default())
            .expect("self-collision");
    }
    for _ in 0..40 {
        solver.step_with(&mut world).expect("warm-up");
    }
    (solver, world)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("dressed");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);
    let (solver, _) = dressed(false, false);
    println!(
        "sheet: {} particles, SIMD path {:?}, {} threads",
        solver.particles().len(),
        solver.simd_path(),
        rayon::current_num_threads()
    );
    g.bench_function("solve/fused", |b| {
        warm_frames(b, &solver, |s| {
            black_box(s.step().expect("step"));
        })
    });
    g.bench_function("solve/general", |b| {
        warm_frames(b, &solver, |s| {
            black_box(s.step_with(&mut Inert).expect("step"));
        })
    });
    let (mut solver, mut world) = dressed(true, false);
    let particles = solver.particles().clone();
    let settings = *solver.settings();
    let t = solver.time();
    g.bench_function("contact-only", |b| {
        b.iter_batched(
            || particles.clone(),
            |mut p| {
                for k in 0..settings.substeps {
                    let ctx = SubstepContext {
                        method: settings.method,
                        time: t + settings.h() * f64::from(k + 1),
                        h: settings.h(),
                        substep: k,
                        frame_end: t + settings.h() * f64::from(settings.substeps),
                    };
                    world.begin_substep(&ctx, &p);
                    world.project(&ctx, &mut p);
                }
                p
            },
            BatchSize::SmallInput,
        )
    });
    println!("contact planes per substep: {}", world.stats().body_planes);
    g.bench_function("body", |b| {
        b.iter(|| black_box(solver.step_with(&mut world).expect("step")))
    });
    let (mut solver, mut world) = dressed(true, true);
    g.bench_function("body+self", |b| {
        b.iter(|| black_box(solver.step_with(&mut world).expect("step")))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
