//! Mass-spring explodes at high stiffness with a frame time step; XPBD at the matching
//! compliance stays bounded. Divergence is reported, never propagated.

use crate::common;

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

/// An 8² XPBD cloth hanging for five frames (a fused solver).
fn hanging_xpbd_after_five_frames() -> weft_solver::Solver {
    let mut s = solver(
        settings(Method::Xpbd, DT, 4, 1),
        Forces::default(),
        &hanging_grid(8),
        in_plane(0.0, 1.0, 0.0),
    );
    run(&mut s, 5);
    s
}

#[test]
fn a_nan_is_reported_with_its_particle_not_propagated() {
    let mut s = hanging_xpbd_after_five_frames();
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

/// The soft cloth: 40², 1.6 m, 0.15 kg/m², pinned at two corners, springs of 100, 50
/// and 5 N/m (stretch, shear, bend-distance), no damping.
fn soft_grid(substeps: u32) -> weft_solver::Solver {
    use weft_solver::{Family, GridDesc, Mass, Orientation};
    let mesh = GridDesc {
        resolution: (40, 40),
        size: (1.6, 1.6),
        orientation: Orientation::Horizontal,
        mass: Mass::Density(0.15),
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid");
    let mut params = in_plane(0.0, 1.0, 100.0);
    params.get_mut(Family::Shear).spring_stiffness = 50.0;
    let bend = params.get_mut(Family::BendDistance);
    bend.enabled = true;
    bend.spring_stiffness = 5.0;
    solver(
        settings(Method::MassSpring, DT, substeps, 1),
        Forces::default(),
        &mesh,
        params,
    )
}

#[test]
fn the_stability_bound_predicts_where_explicit_springs_explode() {
    let b = soft_grid(1).stability(0).expect("one cloth");
    // One spring's √(k/m) of an interior particle says far less than the grid's highest mode.
    let m = 0.15 * (1.6f64 / 39.0).powi(2);
    let one_spring = (100.0 / m).sqrt();
    assert!(
        b.mode_omega > 2.0 * one_spring,
        "{} vs {one_spring}",
        b.mode_omega
    );
    assert!(
        b.mode_omega <= b.omega,
        "the mode cannot exceed Gershgorin's bound"
    );
    // Below the guaranteed limit: 300 frames run. 15 % past the mode's limit: it explodes.
    let safe = (DT / b.max_substep()).floor() as u32 + 1;
    let mut s = soft_grid(safe);
    run(&mut s, 300);
    let past = (DT / (1.15 * b.mode_max_substep())).floor() as u32;
    let mut s = soft_grid(past);
    let err = (0..300)
        .find_map(|_| s.step().err())
        .unwrap_or_else(|| panic!("{past} substeps (h past the limit) must diverge"));
    println!(
        "highest mode ω = {:.0} rad/s (Gershgorin ≤ {:.0}); {safe} substeps run, {past} diverge: {err}",
        b.mode_omega, b.omega
    );
    assert!(
        err.to_string()
            .contains("past the springs' stability limit"),
        "{err}"
    );
}

/// Throws particle 37 of `s` (after five frames) at 1e9 m/s, finite but carrying it and its
/// neighbours far past the 1e4 m bound within a frame, and checks that the next step reports
/// one of them (the first: 37 or a neighbour before it) under `method` at frame 5.
fn reports_a_particle_thrown_past_the_bound(mut s: weft_solver::Solver, method: Method) {
    s.particles_mut().velocities[37].z = 1e9;
    match s.step() {
        Err(SolverError::Diverged {
            method: m,
            frame: 5,
            particle,
            position,
            bound,
            ..
        }) if m == method => {
            assert!(particle <= 37, "particle {particle}");
            assert!(position.is_finite() && position.abs().max_element() > bound);
        }
        other => panic!("expected {method} to diverge at frame 5, got {other:?}"),
    }
}

#[test]
fn a_fused_frame_reports_a_particle_beyond_the_bound() {
    let s = hanging_xpbd_after_five_frames();
    assert!(
        s.runs_fused(),
        "the fused frame checks positions as it copies them out"
    );
    reports_a_particle_thrown_past_the_bound(s, Method::Xpbd);
}

#[test]
fn a_stencil_frame_reports_a_particle_beyond_the_bound() {
    let mut s = solver(
        settings(Method::MassSpring, DT, 40, 1),
        Forces::default(),
        &hanging_grid(8),
        in_plane(0.0, 1.0, 100.0),
    );
    run(&mut s, 5);
    assert!(
        s.runs_springs_by_stencil(),
        "the stencil frame checks positions as it writes them back"
    );
    reports_a_particle_thrown_past_the_bound(s, Method::MassSpring);
}
