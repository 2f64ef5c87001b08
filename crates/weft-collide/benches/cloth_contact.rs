//! Cost of a frame with mesh-level cloth contact against the same frame with it off, side by
//! side from the same state: two 2 mm sheets (48², 1 m) over a ball at rest and while
//! landing, and a 50² sheet 4 mm thick twisted a full turn (issue 62's floors: ≤ 1.5×, ≤ 2.5×
//! and ≤ 3×).
#![allow(clippy::unwrap_used)]

use std::time::Duration;

use criterion::{BatchSize, Criterion, SamplingMode, criterion_group, criterion_main};
use weft_collide::CollisionWorld;
use weft_collide::layered::{layers_on_ball, twist};
use weft_solver::{Method, Solver};

/// `frames` frames of `solver` with `world`.
fn advance(solver: &mut Solver, world: &mut CollisionWorld, frames: usize) {
    for _ in 0..frames {
        solver.step_with(world).unwrap();
    }
}

/// Benches one frame from `solver`'s state with `world` (`on`) and with cloth contact off.
fn pair(c: &mut Criterion, group: &str, solver: &Solver, world: &CollisionWorld) {
    let mut g = c.benchmark_group(group);
    g.sample_size(20)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(4));
    let mut off = world.clone();
    off.disable_cloth_contact();
    for (name, w) in [("contact off", &off), ("contact on", world)] {
        g.bench_function(name, |b| {
            b.iter_batched(
                || (solver.clone(), w.clone()),
                |(mut s, mut w)| s.step_with(&mut w).unwrap(),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

fn layers(c: &mut Criterion) {
    let (mut solver, mut world) = layers_on_ball(Method::Xpbd, 48, 1.0, true).unwrap();
    // Landing: the lower sheet has reached the ball (0.1 s) and the upper one meets it.
    advance(&mut solver, &mut world, 12);
    pair(c, "cloth contact: layers landing", &solver, &world);
    // At rest: draped and settled (3 s).
    advance(&mut solver, &mut world, 168);
    pair(c, "cloth contact: layers at rest", &solver, &world);
}

fn twisted(c: &mut Criterion) {
    let (mut solver, mut world) = twist(Method::Xpbd, 50, 0.004, true).unwrap();
    // A full turn: the sheet pressed against itself along the axis.
    advance(&mut solver, &mut world, 120);
    pair(c, "cloth contact: twist", &solver, &world);
}

criterion_group!(benches, layers, twisted);
criterion_main!(benches);
