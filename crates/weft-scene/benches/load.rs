//! Loading and building a big cloth, as `weft check` and every run start: the reference scene
//! (`assets/scenes/reference.toml`) at N × N for N = 256 and 512, loaded from its file with
//! `--set`-style overrides (spring defaults and all), then built into its solver (colouring,
//! domains, constraint blocks). Time linear in N² is the aim; the 512² row is a quarter of
//! `weft check`'s 1024² case.

mod common;

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};

use common::{load, simd_path, single_group};

const SIZES: [usize; 2] = [256, 512];

fn overrides(n: usize) -> Vec<String> {
    vec![format!("cloth.reference.resolution=[{n}, {n}]")]
}

fn load_and_build(c: &mut Criterion) {
    let _ = simd_path();
    let mut group = c.benchmark_group("load");
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for n in SIZES {
        // Outside the timing: the scene is the N × N cloth it claims to be.
        let scene = load("reference.toml", &overrides(n));
        assert_eq!(scene.cloths[0].mesh.len(), n * n);
        assert_eq!(single_group(&scene).solver.particles().len(), n * n);
        group.throughput(Throughput::Elements((n * n) as u64));
        group.bench_function(BenchmarkId::new("load", n), |b| {
            b.iter(|| black_box(load("reference.toml", &overrides(n))))
        });
        group.bench_function(BenchmarkId::new("load and build", n), |b| {
            b.iter(|| {
                let scene = load("reference.toml", &overrides(n));
                black_box(single_group(&scene))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, load_and_build);
criterion_main!(benches);
