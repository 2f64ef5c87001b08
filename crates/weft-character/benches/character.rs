//! What a character costs per substep, before it meets any cloth:
//!
//! - `state/walker`, `state/cmu`: `Character::state(t)` (sample the clip, forward kinematics,
//!   bone velocities by central difference, world shapes) for the procedural walker (24
//!   joints, 20 shapes) and the shipped CMU clip (38 joints, 25 shapes);
//! - `distance/8000`: the signed distance of 8,000 points (a T-shirt's particle count) to the
//!   walker's body with bounding-sphere culling (`CharacterState::signed_distance`), and
//!   with every shape tested (`/exhaustive`);
//! - `skin/simple_skin`: linear blend skinning of the glTF fixture.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use weft_character::files::{read_bvh, read_skinned_gltf};
use weft_character::{Animation, BodyTable, BvhOptions, CMU_SCALE, Character, Wrap};

fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("character");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    let walker = Character::walker();
    g.bench_function("state/walker", |b| {
        b.iter(|| walker.state(black_box(0.437)))
    });
    let bvh = read_bvh(
        &assets().join("cmu_01_01_4s.bvh"),
        &BvhOptions { scale: CMU_SCALE },
    )
    .expect("shipped clip");
    let cmu =
        Character::new(Animation::from_bvh(bvh, Wrap::Clamp), &BodyTable::cmu()).expect("CMU body");
    g.bench_function("state/cmu", |b| b.iter(|| cmu.state(black_box(1.437))));
    let state = walker.state(0.437);
    let points: Vec<DVec3> = (0..8000)
        .map(|k| {
            let a = k as f64 * 0.731;
            DVec3::new(
                0.2 * a.cos(),
                0.9 + 0.5 * (k as f64 / 8000.0),
                0.15 * a.sin(),
            )
        })
        .collect();
    g.bench_function("distance/8000", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|&p| state.signed_distance(p))
                .fold(f64::INFINITY, f64::min)
        })
    });
    g.bench_function("distance/8000/exhaustive", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|&p| {
                    state
                        .shapes
                        .iter()
                        .map(|s| s.contact(p).distance)
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(f64::INFINITY, f64::min)
        })
    });
    let skin = read_skinned_gltf(&assets().join("simple_skin.gltf")).expect("fixture");
    g.bench_function("skin/simple_skin", |b| b.iter(|| skin.skin(black_box(1.3))));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
