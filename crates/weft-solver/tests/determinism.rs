//! Same build, inputs and settings give bit-identical states, whatever the thread count and
//! whether colours run in parallel or in sequence.

mod common;

use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{
    Aero, ClothParams, Edge, Family, Forces, GridDesc, Method, Pin, Settings, Solver,
    SolverBuilder, Wind,
};

fn build(method: Method, parallel_min_batch: usize) -> Solver {
    let mesh = GridDesc {
        resolution: (48, 48),
        pins: vec![Pin::Edge(Edge::Top)],
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid");
    let mut params = ClothParams::default()
        .edit(Family::BendDistance, |p| p.enabled = true)
        .edit(Family::Tether, |p| p.enabled = true);
    // Springs soft enough for explicit integration at h = 1/300 s with 0.4 g particles.
    for f in Family::ALL {
        params.get_mut(f).spring_stiffness = 5.0;
        params.get_mut(f).spring_damping = 0.001;
    }
    // Dihedral gradients scale as 1/edge (~47 /m here): N·m/rad values are far smaller.
    params.get_mut(Family::BendDihedral).spring_stiffness = 1e-4;
    params.get_mut(Family::BendDihedral).spring_damping = 1e-8;
    let forces = Forces {
        wind: Wind {
            velocity: DVec3::new(0.0, 0.0, 4.0),
            drag: 0.1,
            aero: Some(Aero::default()),
        },
        damping: 0.1,
        ..Forces::default()
    };
    let settings = Settings {
        method,
        substeps: 5,
        iterations: 2,
        parallel_min_batch,
        ..Settings::default()
    };
    let mut b = SolverBuilder::new(settings, forces).expect("valid");
    b.add_cloth("flag", &mesh, params, 0.01).expect("valid");
    b.build()
}

fn bits(s: &Solver) -> Vec<[u64; 3]> {
    s.particles()
        .positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect()
}

fn run_in_pool(threads: usize, method: Method, parallel_min_batch: usize) -> Vec<[u64; 3]> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut s = build(method, parallel_min_batch);
        run(&mut s, 40);
        bits(&s)
    })
}

#[test]
fn results_are_bit_identical_across_threads_and_paths() {
    for method in [Method::Xpbd, Method::Pbd] {
        let reference = run_in_pool(1, method, usize::MAX);
        assert_eq!(
            reference,
            run_in_pool(1, method, usize::MAX),
            "{method}: same run twice"
        );
        assert_eq!(
            reference,
            run_in_pool(1, method, 1),
            "{method}: parallel path, 1 thread"
        );
        assert_eq!(
            reference,
            run_in_pool(2, method, 1),
            "{method}: parallel path, 2 threads"
        );
        assert_eq!(
            reference,
            run_in_pool(4, method, 64),
            "{method}: parallel path, 4 threads"
        );
        // The run really moved the cloth (a frozen state would be trivially identical).
        let start = bits(&build(method, usize::MAX));
        assert_ne!(reference, start);
    }
    let ms = run_in_pool(1, Method::MassSpring, usize::MAX);
    assert_eq!(ms, run_in_pool(2, Method::MassSpring, 1));
}
