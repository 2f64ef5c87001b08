//! Every kernel path this CPU runs (`Settings::simd`, `WEFT_SIMD`) gives the same bits as the
//! baseline build, fused or through the general loop, on one and two threads.

use crate::common;

use common::flag::{flag_settings, in_pool, state_bits, step, windy_flag};
use common::top_pinned_grid;
use weft_solver::{ClothParams, Forces, Method, Settings, SimdPath, SolverBuilder};

/// A flag in wind with compliant, damped stretch, bend-distance and mixed chunks (a 37-wide grid
/// leaves ragged rows and gathered chunks), run 20 frames on `path`.
fn run(method: Method, path: SimdPath, threads: usize, general: bool) -> Vec<[u64; 3]> {
    in_pool(threads, || {
        let settings = Settings {
            simd: Some(path),
            ..flag_settings(method, 256)
        };
        let (b, _) = windy_flag((37, 29), settings);
        let mut s = b.build();
        assert_eq!(s.simd_path(), path, "a supported path runs as asked");
        assert_eq!(s.domain_stats().simd, path);
        let stats = s.domain_stats();
        assert!(stats.domains > 1 && stats.gathered > 0 && stats.remainder > 0);
        for _ in 0..20 {
            step(&mut s, general);
        }
        state_bits(&s)
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
    let mesh = top_pinned_grid((24, 24));
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
