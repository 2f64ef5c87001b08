//! Step time per frame of XPBD, PBD and mass-spring on the same square cloths.
//!
//! Cloth: N×N particles, 1 m square of 1 kg, top edge pinned, stretch + shear (the shared
//! reference workload of `../shared/peers/`), dt = 1/60, 10 substeps × 1 iteration. Throughput
//! is counted in constraint evaluations per frame (constraints × substeps × iterations).
//! Mass-spring springs are scaled to the lightest particle so that ω h ≤ 1 (stable) at every size.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use weft_solver::{
    ClothParams, Edge, Family, Forces, GridDesc, Method, Pin, Settings, Solver, SolverBuilder,
};

const SIZES: [usize; 4] = [32, 64, 128, 256];

fn cloth(n: usize, method: Method) -> Solver {
    let mesh = GridDesc {
        resolution: (n, n),
        pins: vec![Pin::Edge(Edge::Top)],
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid");
    let settings = Settings {
        method,
        ..Settings::default()
    };
    let h = settings.h();
    let m = mesh.masses.iter().copied().fold(f64::INFINITY, f64::min);
    let mut params = ClothParams::default();
    for f in Family::ALL {
        let p = params.get_mut(f);
        p.enabled = matches!(f, Family::Stretch | Family::Shear);
        p.compliance = 0.0;
        // ω h ≤ 1 with ω² ≤ 8 springs · k · (2/m) for the lightest particle of mass m.
        p.spring_stiffness = m / (16.0 * h * h);
    }
    let mut b = SolverBuilder::new(settings, Forces::default()).expect("valid settings");
    b.add_cloth("cloth", &mesh, params, 0.0)
        .expect("valid cloth");
    b.build()
}

fn methods(c: &mut Criterion) {
    for method in Method::ALL {
        let mut group = c.benchmark_group(format!("step/{}", method.name()));
        group.sample_size(10);
        for n in SIZES {
            let mut solver = cloth(n, method);
            let s = *solver.settings();
            let projections =
                solver.constraints().len() as u64 * u64::from(s.substeps) * u64::from(s.iterations);
            group.throughput(Throughput::Elements(projections));
            group.bench_function(BenchmarkId::from_parameter(n * n), |b| {
                b.iter(|| black_box(solver.step().expect("stable")));
            });
        }
        group.finish();
    }
}

criterion_group!(benches, methods);
criterion_main!(benches);
