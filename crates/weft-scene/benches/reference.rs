//! The reference workload other solvers run too (`../shared/peers/`, `scripts/compare_peers.sh`):
//! N×N grid, 1 m square of 1 kg, top edge pinned, stretch (grid edges) and shear (both
//! diagonals) distance constraints at α = 0, gravity, dt = 1/60, 10 substeps × 1 iteration, no
//! bending: `assets/scenes/reference.toml` with `cloth.reference.resolution=[N, N]`, at
//! N = 64, 128, 256, each on a 1-thread and a 2-thread rayon pool.
//!
//! The kernel path (`WEFT_SIMD`, else the widest the CPU has) is printed first and checked to be
//! the one the solvers run.
//!
//! Outside the timing it checks the workload is the one the peers run: N² particles and
//! 2N(N−1) + 2(N−1)² constraints, which is 16,384 and exactly 64,770 at N = 128.

mod common;

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use weft_solver::Method;

use common::{evaluations_per_frame, reference, simd_path};

const SIZES: [usize; 3] = [64, 128, 256];
const THREADS: [usize; 2] = [1, 2];

fn reference_workload(c: &mut Criterion) {
    let path = simd_path();
    let at_128 = reference(128, Method::Xpbd);
    assert_eq!(at_128.solver.simd_path(), path);
    assert_eq!(at_128.solver.particles().len(), 16_384);
    assert_eq!(at_128.solver.constraints().len(), 64_770);
    let s = at_128.solver.settings();
    assert_eq!((s.substeps, s.iterations), (10, 1));
    assert!((s.dt - 1.0 / 60.0).abs() < 1e-15, "dt = {}", s.dt);

    for threads in THREADS {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("rayon pool");
        let mut group = c.benchmark_group(format!("reference/threads={threads}"));
        group
            .sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        for n in SIZES {
            let mut g = reference(n, Method::Xpbd);
            assert_eq!(
                g.solver.constraints().len(),
                2 * n * (n - 1) + 2 * (n - 1) * (n - 1),
                "N = {n}"
            );
            group.throughput(Throughput::Elements(evaluations_per_frame(&g)));
            group.bench_function(BenchmarkId::from_parameter(n), |b| {
                pool.install(|| b.iter(|| black_box(g.step().expect("stable"))));
            });
        }
        group.finish();
    }
}

criterion_group!(benches, reference_workload);
criterion_main!(benches);
