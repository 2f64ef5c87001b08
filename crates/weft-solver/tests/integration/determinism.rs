//! Same build, inputs and settings give bit-identical states, whatever the thread count and
//! whether a frame runs fused or through the general loop.

use crate::common;

use common::flag::{drag_corner, flag_settings, fusable_flag, in_pool, state_bits};
use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{
    Aero, ClothParams, Family, Forces, Method, Motion, Settings, Solver, SolverBuilder, Wind,
};

fn build(method: Method, domain_size: usize) -> Solver {
    let mesh = top_pinned_grid((48, 48));
    let mut params = ClothParams::default()
        .edit(Family::BendDistance, |p| p.enabled = true)
        .edit(Family::BendDihedral, |p| p.enabled = true)
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
        domain_size,
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

fn run_in_pool(threads: usize, method: Method, domain_size: usize) -> Vec<[u64; 3]> {
    in_pool(threads, || {
        let mut s = build(method, domain_size);
        run(&mut s, 40);
        bits(&s)
    })
}

#[test]
fn results_are_bit_identical_across_thread_counts() {
    // 48² = 2304 particles in domains of at most 256: sixteen domains and their links.
    for method in Method::ALL {
        let reference = run_in_pool(1, method, 256);
        assert_eq!(reference, run_in_pool(1, method, 256), "{method}: twice");
        assert_eq!(
            reference,
            run_in_pool(2, method, 256),
            "{method}: 2 threads"
        );
        assert_eq!(
            reference,
            run_in_pool(3, method, 256),
            "{method}: 3 threads"
        );
        assert_eq!(
            reference,
            run_in_pool(4, method, 256),
            "{method}: 4 threads"
        );
        // The run really moved the cloth (a frozen state would be trivially identical).
        let start = bits(&build(method, 256));
        assert_ne!(reference, start);
    }
}

/// A flag in linear wind with a moving pin, global and XPBD damping, and a dragged corner:
/// everything the fused frame handles.
fn fusable(method: Method, threads: usize, active: bool) -> Vec<[u64; 3]> {
    fusable_in(method, threads, active, false)
}

/// [`fusable`], in still air if `still` (no drag: the fused prediction then takes a = g).
fn fusable_in(method: Method, threads: usize, active: bool, still: bool) -> Vec<[u64; 3]> {
    in_pool(threads, || {
        let (mut b, mesh) = fusable_flag((40, 40), flag_settings(method, 200));
        b.add_kinematic_pin(
            0,
            0,
            Motion::Linear {
                velocity: DVec3::new(0.5, 0.0, 0.0),
            },
        )
        .expect("valid pin");
        let mut s = b.build();
        if still {
            let mut forces = *s.forces();
            forces.wind = Wind::default();
            s.set_forces(forces).expect("valid forces");
        }
        assert!(s.runs_fused(), "the fused side really runs fused");
        assert!(s.domain_stats().domains > 1 && s.domain_stats().links > 0);
        let corner = 40 * 40 - 1;
        drag_corner(&mut s, corner, active);
        let p = s.particles();
        assert!((p.positions[corner] - mesh.positions[corner]).length() > 0.1);
        state_bits(&s)
    })
}

#[test]
fn fused_frames_match_the_general_loop_bit_for_bit() {
    for method in [Method::Xpbd, Method::Pbd] {
        let fused = fusable(method, 1, false);
        assert_eq!(fused, fusable(method, 1, true), "{method}");
        assert_eq!(fused, fusable(method, 2, false), "{method}, 2 threads");
        assert_eq!(fused, fusable(method, 2, true), "{method}, 2 threads");
        // Without a hook the fused frame runs on a team of threads: of two workers with four
        // domains each on three threads, of four workers on four (links above the slots).
        assert_eq!(fused, fusable(method, 3, false), "{method}, 3 threads");
        assert_eq!(fused, fusable(method, 4, false), "{method}, 4 threads");
        // In still air the fused prediction drops the drag term (a = g exactly).
        let still = fusable_in(method, 1, false, true);
        assert_eq!(
            still,
            fusable_in(method, 1, true, true),
            "{method}, still air"
        );
        assert_eq!(
            still,
            fusable_in(method, 2, false, true),
            "{method}, still air"
        );
        assert_ne!(still, fused, "{method}: the wind made a difference");
    }
}
