//! The explicit frame by stencil (f32 spring forces in lanes, one pass a substep) against the
//! general loop (f64 forces by slots): the same motion to the forces' f32 rounding, and the
//! same bits on every thread count and kernel path.

use crate::common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use common::flag::{
    drag_corner, flag_settings, fusable_flag, in_pool, state_bits, step, windy_flag,
};
use weft_solver::glam::DVec3;
use weft_solver::{Family, Method, Motion, Settings, SimdPath, Solver, Wind};

/// The fusable windy flag (stretch, shear and bend-distance springs) under explicit
/// mass-spring, soft enough for h = 1/240 s, springs damped by `damping` (N·s/m), with a
/// moving pin if `moving`.
fn flag(path: SimdPath, damping: f64, moving: bool) -> Solver {
    let settings = Settings {
        simd: Some(path),
        ..flag_settings(Method::MassSpring, 256)
    };
    let (mut b, _) = fusable_flag((40, 40), settings);
    if moving {
        b.add_kinematic_pin(
            0,
            0,
            Motion::Linear {
                velocity: DVec3::new(0.5, 0.0, 0.0),
            },
        )
        .expect("valid pin");
    }
    let mut s = b.build();
    let mut params = s.cloth_params(0).expect("one cloth");
    for f in Family::ALL {
        params.get_mut(f).spring_stiffness = 5.0;
        params.get_mut(f).spring_damping = damping;
    }
    s.set_cloth_params(0, params).expect("valid");
    s
}

/// 30 frames of [`flag`] on `threads` threads, through the general loop when `general`, the
/// corner grabbed and dragged in between: the final state's bits and positions.
fn run(path: SimdPath, threads: usize, general: bool) -> (Vec<[u64; 3]>, Vec<DVec3>) {
    in_pool(threads, || {
        let mut s = flag(path, 0.001, true);
        assert!(s.runs_springs_by_stencil());
        let corner = 40 * 40 - 1;
        let start = s.particles().positions[corner];
        drag_corner(&mut s, corner, general);
        assert!((s.particles().positions[corner] - start).length() > 0.1);
        (state_bits(&s), s.particles().positions.clone())
    })
}

#[test]
fn the_stencil_frame_follows_the_general_loop_to_the_forces_rounding() {
    // In still air, hanging from its pins: a motion that does not amplify small differences
    // (the flag in wind and dragged flaps chaotically, and both runs part by centimetres).
    // Damped springs read the velocities, undamped ones do not: both kernels.
    for damping in [0.001, 0.0] {
        let still = |general: bool| {
            let mut s = flag(SimdPath::Scalar, damping, false);
            let mut forces = *s.forces();
            forces.wind = Wind::default();
            s.set_forces(forces).expect("valid forces");
            for _ in 0..60 {
                step(&mut s, general);
            }
            s.particles().clone()
        };
        let (general, stencil) = (still(true), still(false));
        let start = flag(SimdPath::Scalar, damping, false)
            .particles()
            .positions
            .clone();
        let most = |a: &[DVec3], b: &[DVec3]| {
            (a.iter().zip(b).map(|(a, b)| (*a - *b).length())).fold(0.0, f64::max)
        };
        let fell = most(&general.positions, &start);
        let apart = most(&general.positions, &stencil.positions);
        // The positions at the last substep's start and the velocities follow too (h = 1/240
        // s: a position at another substep's start is ~1e-4 m away at these speeds).
        let apart_prev = most(&general.prev_positions, &stencil.prev_positions);
        let apart_v = most(&general.velocities, &stencil.velocities);
        println!("damping {damping}, after 60 frames: fell {fell:.3} m, runs {apart:e} m apart");
        assert!(fell > 0.05, "{fell} m");
        // Positions rounded to f32 relative to a corner of a 1 m flag (~6e-8 m) in every force.
        assert!(apart < 1e-5, "{apart:e} m");
        assert!(apart > 0.0, "the stencil frame really ran");
        assert!(apart_prev < 1e-5, "{apart_prev:e} m");
        assert!(apart_v < 1e-3, "{apart_v:e} m/s");
    }
}

#[test]
fn the_stencil_frame_gives_the_same_bits_on_every_thread_count_and_path() {
    let (baseline, _) = run(SimdPath::Scalar, 1, false);
    for path in SimdPath::ALL.into_iter().filter(|p| p.supported()) {
        for threads in [1, 2, 3] {
            assert!(
                run(path, threads, false).0 == baseline,
                "{path}, {threads} thread(s)"
            );
        }
    }
}

#[test]
fn springs_that_form_no_stencil_run_the_general_loop() {
    // Dihedral bending is no distance spring: the general loop takes every force.
    let (b, _) = windy_flag((12, 12), flag_settings(Method::MassSpring, 256));
    assert!(!b.build().runs_springs_by_stencil());
    let (b, _) = fusable_flag((12, 12), flag_settings(Method::MassSpring, 256));
    assert!(b.build().runs_springs_by_stencil());
}

#[test]
fn a_stop_inside_a_stencil_frame_keeps_the_last_substeps_start() {
    // Undamped springs and no global damping: every free particle's velocity is its last
    // substep's chord, v = (x − x_prev)/h, whether the frame ran whole or stopped inside.
    let mut s = flag(SimdPath::Scalar, 0.0, false);
    let mut forces = *s.forces();
    forces.damping = 0.0;
    s.set_forces(forces).expect("valid forces");
    let mut settings = *s.settings();
    settings.substeps = 2000;
    s.set_settings(settings).expect("valid settings");
    let h = s.settings().h();
    let flag = Arc::new(AtomicBool::new(false));
    s.set_stop(Arc::clone(&flag));
    let chords_hold = |s: &Solver| {
        let p = s.particles();
        (p.positions.iter().zip(&p.prev_positions).zip(&p.velocities))
            .zip(&p.inv_masses)
            .filter(|(_, w)| **w > 0.0)
            .all(|(((x, prev), v), _)| (*v - (*x - *prev) / h).length() <= 1e-6 * v.length())
    };
    let started = Instant::now();
    s.step().expect("the flag is down");
    let frame = started.elapsed();
    assert!(chords_hold(&s), "after a whole frame");
    // Raise the flag halfway through a frame until a frame is stopped after it moved.
    let mut stopped_inside = false;
    for _ in 0..20 {
        flag.store(false, Ordering::SeqCst);
        let before = s.particles().positions.clone();
        let raise = Arc::clone(&flag);
        let raiser = std::thread::spawn(move || {
            std::thread::sleep(frame / 2);
            raise.store(true, Ordering::SeqCst);
        });
        let result = s.step();
        raiser.join().expect("the raiser ends");
        if result.is_err() && s.particles().positions != before {
            stopped_inside = true;
            assert!(chords_hold(&s), "after a stop inside the frame");
            break;
        }
    }
    assert!(stopped_inside, "no frame was stopped inside in 20 tries");
}
