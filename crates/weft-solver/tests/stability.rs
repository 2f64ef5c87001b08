//! Mass-spring explodes at high stiffness with a frame time step; XPBD at the matching
//! compliance stays bounded. Divergence is reported, never propagated.

mod common;

use common::*;
use weft_solver::{Forces, Method, SolverError};

const DT: f64 = 1.0 / 60.0;

#[test]
fn stiff_mass_spring_diverges_and_is_reported() {
    let mut s = solver(
        settings(Method::MassSpring, DT, 1, 1),
        Forces::default(),
        &hanging_grid(16),
        in_plane(1e-7, 1.0, 1e7),
    );
    let err = (0..300)
        .find_map(|_| s.step().err())
        .expect("k = 1e7 N/m at dt = 1/60 s must diverge");
    match &err {
        SolverError::Diverged {
            method,
            frame,
            particle,
            position,
            ..
        } => {
            println!("reported: {err}");
            assert_eq!(*method, Method::MassSpring);
            assert!(*frame < 300);
            assert!(*particle < 256);
            assert!(!position.is_finite() || position.abs().max_element() > 1e4);
        }
        other => panic!("expected divergence, got {other:?}"),
    }
    assert!(err.to_string().contains("mass-spring"));
}

#[test]
fn xpbd_with_the_same_stiffness_stays_bounded() {
    let mut s = solver(
        settings(Method::Xpbd, DT, 1, 1),
        Forces::default(),
        &hanging_grid(16),
        in_plane(1e-7, 1.0, 1e7),
    );
    for _ in 0..300 {
        s.step().expect("XPBD must stay stable");
        let far = s
            .particles()
            .positions
            .iter()
            .map(|p| p.length())
            .fold(0.0, f64::max);
        assert!(
            far < 1.5,
            "a 1 m cloth pinned at the origin's row cannot reach {far} m"
        );
    }
}

#[test]
fn soft_mass_spring_at_small_steps_is_stable_and_sags() {
    // The same integrator is fine where h < 2/ω: k = 500 N/m, 20 substeps.
    let forces = Forces {
        damping: 1.0,
        ..Forces::default()
    };
    let mut s = solver(
        settings(Method::MassSpring, DT, 20, 1),
        forces,
        &hanging_grid(16),
        in_plane(0.0, 1.0, 500.0),
    );
    run(&mut s, 240);
    let low = lowest_y(&s);
    assert!(low < -0.5 && low > -1.5, "lowest point {low}");
}

#[test]
fn a_nan_is_reported_with_its_particle_not_propagated() {
    let mut s = solver(
        settings(Method::Xpbd, DT, 4, 1),
        Forces::default(),
        &hanging_grid(8),
        in_plane(0.0, 1.0, 0.0),
    );
    run(&mut s, 5);
    s.particles_mut().velocities[37].y = f64::NAN;
    match s.step() {
        Err(SolverError::Diverged {
            method: Method::Xpbd,
            frame: 5,
            particle,
            ..
        }) => {
            // The NaN reaches 37's constraint neighbours within the frame; the first is reported.
            assert!(particle <= 37, "particle {particle}");
        }
        other => panic!("expected divergence at frame 5, got {other:?}"),
    }
}
