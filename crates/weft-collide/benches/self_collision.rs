//! Cost of one substep of collision handling (`begin_substep` + the first `project`; the
//! particles are the same every iteration, so the self-collision list built on the first is
//! kept) at 32², 64², 128² and 256² particles:
//! self-collision of an accordion-folded cloth, and a cloth wrapped on a sphere and on the
//! triangle-mesh blob (every particle in contact in all three).
#![allow(clippy::unwrap_used)]

use std::time::Duration;

use criterion::{
    BatchSize, BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use weft_collide::scenarios::blob_path;
use weft_collide::{ColliderDesc, CollisionWorld, SelfCollisionParams, ShapeDesc};
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothParams, Forces, GridDesc, Mass, Method, Orientation, Particles, Settings, Solver,
    SolverBuilder, SubstepContext, SubstepHook,
};

const SIZES: [usize; 4] = [32, 64, 128, 256];
const WIDTH: f64 = 1.6;

fn flat_cloth(n: usize, thickness: f64) -> Solver {
    let mesh = GridDesc {
        resolution: (n, n),
        size: (WIDTH, WIDTH),
        center: DVec3::ZERO,
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.4),
        pins: vec![],
    }
    .build()
    .unwrap();
    let mut b = SolverBuilder::new(Settings::default(), Forces::default()).unwrap();
    b.add_cloth("cloth", &mesh, ClothParams::default(), thickness)
        .unwrap();
    b.build()
}

fn ctx() -> SubstepContext {
    let s = Settings::default();
    SubstepContext {
        method: Method::Xpbd,
        time: s.h(),
        h: s.h(),
        substep: 0,
        frame_end: s.h(),
    }
}

/// Sets positions (and previous positions, so nothing is clamped or swept) to `f(row, col)`.
fn place(p: &mut Particles, n: usize, f: impl Fn(usize, usize, DVec3) -> DVec3) {
    for j in 0..n {
        for i in 0..n {
            let k = j * n + i;
            p.positions[k] = f(j, i, p.positions[k]);
            p.prev_positions[k] = p.positions[k];
        }
    }
}

fn bench_one(c: &mut Criterion, group: &str, n: usize, solver: &Solver, world: &CollisionWorld) {
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements((n * n) as u64));
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    let ctx = ctx();
    let mut world = world.clone();
    g.bench_with_input(BenchmarkId::from_parameter(n * n), &n, |b, _| {
        b.iter_batched(
            || solver.particles().clone(),
            |mut p| {
                // Inside rayon's pool, as `Solver::step_with` calls its hooks.
                rayon::scope(|_| {
                    world.begin_substep(&ctx, &p);
                    world.project(&ctx, &mut p)
                })
            },
            BatchSize::LargeInput,
        );
    });
    g.finish();
}

fn self_collision(c: &mut Criterion) {
    for n in SIZES {
        let spacing = WIDTH / (n - 1) as f64;
        let thickness = spacing;
        let mut solver = flat_cloth(n, thickness);
        let mut world = CollisionWorld::new(&solver);
        world
            .enable_self_collision(&solver, &[0], SelfCollisionParams::default())
            .unwrap();
        // Accordion fold: 8 rows per layer, layers 0.9 thickness apart, so every particle
        // overlaps the particles of the layers above and below.
        let rows = 8;
        place(solver.particles_mut(), n, |j, i, _| {
            let layer = j / rows;
            let k = j % rows;
            let along = if layer % 2 == 0 { k } else { rows - 1 - k };
            DVec3::new(
                i as f64 * spacing,
                layer as f64 * 0.9 * thickness,
                along as f64 * spacing,
            )
        });
        let contacts = world
            .clone()
            .project(&ctx(), &mut solver.particles().clone());
        eprintln!("self-collision {n}x{n}: {contacts} contacts in one projection");
        bench_one(c, "self_collision", n, &solver, &world);
    }
}

/// Wraps the flat cloth onto a surface: each particle is put 0.9 thickness off the collider
/// along the normal of its closest point.
fn wrapped(n: usize, shape: ShapeDesc, at: DVec3) -> (Solver, CollisionWorld) {
    let thickness = 0.01;
    let mut solver = flat_cloth(n, thickness);
    let mut world = CollisionWorld::new(&solver);
    world
        .add_collider(&ColliderDesc::new(shape).at(at))
        .unwrap();
    let collider = world.colliders()[0].clone();
    place(solver.particles_mut(), n, |_, _, x| {
        // Start from the flat cloth folded down over the top of the body.
        let dir = DVec3::new(x.x, 0.6, x.z).normalize();
        let s = collider.closest(at + dir, 2.0).unwrap();
        s.point + s.normal * 0.9 * thickness
    });
    (solver, world)
}

fn sphere(c: &mut Criterion) {
    for n in SIZES {
        let (solver, world) = wrapped(n, ShapeDesc::Sphere { radius: 0.5 }, DVec3::ZERO);
        bench_one(c, "sphere", n, &solver, &world);
    }
}

fn trimesh(c: &mut Criterion) {
    let blob = ShapeDesc::from_obj(blob_path(), 1.0).unwrap();
    for n in SIZES {
        let (solver, world) = wrapped(n, blob.clone(), DVec3::new(0.0, 0.45, 0.0));
        bench_one(c, "trimesh", n, &solver, &world);
    }
}

criterion_group!(benches, self_collision, sphere, trimesh);
criterion_main!(benches);
