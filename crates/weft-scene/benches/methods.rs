//! Step time per frame of XPBD, PBD and mass-spring on the same square cloths.
//!
//! The cloths are `assets/scenes/reference.toml` (the shared reference workload of
//! `../shared/peers/`: N×N particles, 1 m square of 1 kg, top edge pinned, stretch + shear at
//! α = 0, dt = 1/60, 10 substeps × 1 iteration) loaded through weft-scene with the overrides
//! `cloth.reference.resolution=[N, N]` and `sim.method=…`, exactly as `weft run --set` would.
//! Throughput is constraint evaluations per frame (constraints × substeps × iterations), so
//! criterion reports projections per second. Mass-spring springs are scaled to the lightest
//! particle so that ω h ≤ 1 (stable) at every size.

mod common;

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use weft_solver::Method;

use common::{SIZES, evaluations_per_frame, reference};

fn methods(c: &mut Criterion) {
    for method in Method::ALL {
        let mut group = c.benchmark_group(format!("step/{}", method.name()));
        group
            .sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        for n in SIZES {
            let mut g = reference(n, method);
            group.throughput(Throughput::Elements(evaluations_per_frame(&g)));
            group.bench_function(BenchmarkId::from_parameter(n * n), |b| {
                b.iter(|| black_box(g.step().expect("stable")));
            });
        }
        group.finish();
    }
}

criterion_group!(benches, methods);
criterion_main!(benches);
