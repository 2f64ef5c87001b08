//! Every kernel path this CPU runs (`Settings::simd`, `WEFT_SIMD`) gives the same bits as the
//! baseline build, fused or through the general loop, on one and two threads.

use weft_solver::glam::DVec3;
use weft_solver::{
    ClothParams, Edge, Family, Forces, GridDesc, Method, Pin, Settings, SimdPath, SolverBuilder,
    SubstepHook, Wind,
};

/// A hook that does nothing but says it is active, forcing the general loop.
struct Active;

impl SubstepHook for Active {}

/// A flag in wind with compliant, damped stretch, bend-distance and mixed chunks (a 37-wide grid
/// leaves ragged rows and gathered chunks), run 20 frames on `path`.
fn run(method: Method, path: SimdPath, threads: usize, general: bool) -> Vec<[u64; 3]> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mesh = GridDesc {
            resolution: (37, 29),
            pins: vec![Pin::Edge(Edge::Top)],
            ..GridDesc::default()
        }
        .build()
        .expect("valid grid");
        let params = ClothParams::default()
            .edit(Family::BendDistance, |p| p.enabled = true)
            .edit(Family::Stretch, |p| {
                p.compliance = 1e-6;
                p.damping = 0.5;
            });
        let forces = Forces {
            wind: Wind {
                velocity: DVec3::new(0.0, 0.0, 3.0),
                drag: 0.2,
                aero: None,
            },
            damping: 0.1,
            ..Forces::default()
        };
        let settings = Settings {
            method,
            substeps: 4,
            iterations: 2,
            domain_size: 256,
            simd: Some(path),
            ..Settings::default()
        };
        let mut b = SolverBuilder::new(settings, forces).expect("valid");
        b.add_cloth("flag", &mesh, params, 0.01).expect("valid");
        let mut s = b.build();
        assert_eq!(s.simd_path(), path, "a supported path runs as asked");
        assert_eq!(s.domain_stats().simd, path);
        let stats = s.domain_stats();
        assert!(stats.domains > 1 && stats.gathered > 0 && stats.remainder > 0);
        for _ in 0..20 {
            if general {
                s.step_with(&mut Active).expect("stable");
            } else {
                s.step().expect("stable");
            }
        }
        let p = s.particles();
        p.positions
            .iter()
            .chain(&p.velocities)
            .map(|v| v.to_array().map(f64::to_bits))
            .collect()
    })
}

#[test]
fn every_kernel_path_gives_the_baseline_bits() {
    let paths: Vec<SimdPath> = SimdPath::ALL
        .into_iter()
        .filter(|p| p.supported())
        .collect();
    println!("paths this CPU runs: {paths:?}");
    for method in [Method::Xpbd, Method::Pbd] {
        let baseline = run(method, SimdPath::Scalar, 1, false);
        for &path in &paths {
            for (threads, general) in [(1, false), (2, false), (2, true)] {
                assert!(
                    run(method, path, threads, general) == baseline,
                    "{method} on {path}, {threads} thread(s), general loop {general}"
                );
            }
        }
    }
}

#[test]
fn switching_the_path_between_frames_keeps_the_bits() {
    let widest = SimdPath::widest();
    let mesh = GridDesc {
        resolution: (24, 24),
        pins: vec![Pin::Edge(Edge::Top)],
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid");
    let build = || {
        let settings = Settings {
            simd: Some(SimdPath::Scalar),
            domain_size: 128,
            ..Settings::default()
        };
        let mut b = SolverBuilder::new(settings, Forces::default()).expect("valid");
        b.add_cloth("c", &mesh, ClothParams::default(), 0.0)
            .expect("valid");
        b.build()
    };
    let (mut a, mut b) = (build(), build());
    let mut on_widest = *b.settings();
    on_widest.simd = Some(widest);
    b.set_settings(on_widest).expect("valid settings");
    assert_eq!(b.simd_path(), widest);
    for _ in 0..10 {
        a.step().expect("stable");
        b.step().expect("stable");
    }
    assert_eq!(a.particles().positions, b.particles().positions);
    assert_ne!(a.particles().positions, mesh.positions, "the cloth moved");
}
