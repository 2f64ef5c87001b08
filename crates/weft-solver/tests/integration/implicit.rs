//! Implicit mass-spring (Baraff & Witkin 1998): unconditionally stable, damped exactly as
//! backward Euler predicts, and at rest where XPBD with α = 1/k rests.

use crate::common;

use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{DEFAULT_CG_TOLERANCE, Forces, GridDesc, Method, Orientation, Settings};

const DT: f64 = 1.0 / 60.0;

/// A horizontal 16² cloth of 1 kg pinned at two corners: it falls and swings about them.
fn swinging_cloth() -> weft_solver::ClothMesh {
    GridDesc {
        resolution: (16, 16),
        orientation: Orientation::Horizontal,
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid")
}

#[test]
fn stable_at_ten_million_newtons_per_metre_where_explicit_diverges() {
    let params = in_plane(1e-7, 1.0, 1e7);
    let mut explicit = solver(
        settings(Method::MassSpring, DT, 1, 1),
        Forces::default(),
        &swinging_cloth(),
        params,
    );
    assert!(
        (0..300).any(|_| explicit.step().is_err()),
        "explicit springs at k = 1e7 N/m and h = 1/60 s must diverge"
    );
    let mut implicit = solver(
        settings(Method::ImplicitMassSpring, DT, 1, 1),
        Forces::default(),
        &swinging_cloth(),
        params,
    );
    let bound = implicit.stability(0).expect("one cloth");
    assert!(!bound.allows(DT), "the explicit bound is passed here");
    let mut lowest = f64::INFINITY;
    let mut longest = 0.0f64;
    for frame in 0..300 {
        implicit.step().expect("implicit stays finite");
        lowest = lowest.min(lowest_y(&implicit));
        // Stiff springs: no edge stretches by more than a few percent of its 1/15 m.
        let r = implicit.residual();
        longest = longest.max(r.max);
        assert!(
            r.max < 0.1 / 15.0,
            "frame {frame}: an edge stretched by {} m",
            r.max
        );
    }
    // It swung down below its pins (a cloth pinned at one edge's corners hangs ~1 m).
    assert!(lowest < -0.7, "lowest point reached {lowest}");
    println!(
        "k = 1e7 N/m, h = 1/60 s: lowest point {lowest:.3} m, largest stretch {longest:.2e} m"
    );
}

/// The swinging cloth's positions after `frames` frames at `substeps` and CG `tolerance`.
fn swing(substeps: u32, tolerance: f64, frames: usize) -> Vec<DVec3> {
    let settings = Settings {
        cg_tolerance: tolerance,
        ..settings(Method::ImplicitMassSpring, DT, substeps, 1)
    };
    let mesh = swinging_cloth();
    let mut s = solver(settings, Forces::default(), &mesh, in_plane(1e-3, 1.0, 1e3));
    run(&mut s, frames);
    s.particles().positions.clone()
}

/// Root mean square of the distances between two runs' particles.
fn rms_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(a, b)| a.distance_squared(*b)).sum();
    (sum / a.len() as f64).sqrt()
}

#[test]
fn the_default_tolerance_errs_far_less_than_the_substeps_do() {
    // The default `cg_tolerance` keeps the solve's error two orders of magnitude under the time
    // discretisation's: a 1 s swing against the same run solved to 1e-10, beside that run at
    // 10 against 20 substeps. (Measured: 0.5 % at 1e-3; 1.7 % at 3e-3, 3.9 % at 1e-2.)
    let frames = 60;
    let converged = swing(10, 1e-10, frames);
    let solve = rms_distance(&swing(10, DEFAULT_CG_TOLERANCE, frames), &converged);
    let steps = rms_distance(&swing(20, 1e-10, frames), &converged);
    println!(
        "RMS after 1 s: solve to the default {solve:.2e} m, 10 against 20 substeps {steps:.2e} m"
    );
    assert!(
        steps > 1e-3,
        "the cloth swings: the substeps' error is {steps} m"
    );
    assert!(
        solve < 0.01 * steps,
        "the default tolerance errs by {solve} m, the substeps by {steps} m"
    );
}

/// A 1 kg particle on a spring of rest length 1 along x, released from 1.5 with no gravity:
/// the linear oscillator ẍ = −(k/m) x (the spring stays on its axis, where C is linear). The
/// linear solve runs to 1e-12, not the default tolerance: this checks the integrator, and a
/// warm start within 1e-3 of the answer would end the solve before its first iteration.
fn oscillator(k: f64, h: f64, steps: usize) -> Vec<(f64, f64)> {
    let mesh = chain(&[DVec3::ZERO, DVec3::X], &[1.0, 1.0], &[0]);
    let forces = Forces {
        gravity: DVec3::ZERO,
        ..Forces::default()
    };
    let tight = Settings {
        cg_tolerance: 1e-12,
        ..settings(Method::ImplicitMassSpring, h, 1, 1)
    };
    let mut s = solver(tight, forces, &mesh, in_plane(0.0, 1.0, k));
    s.particles_mut().positions[1] = DVec3::new(1.5, 0.0, 0.0);
    (0..steps)
        .map(|_| {
            s.step().expect("bounded");
            let p = s.particles();
            (p.positions[1].x - 1.0, p.velocities[1].x)
        })
        .collect()
}

#[test]
fn oscillator_decays_as_backward_euler_predicts() {
    // Backward Euler multiplies each mode by 1/(1 + i hω): the energy-like ω² x² + v² falls by
    // |1/(1 + i hω)|² = 1/(1 + h²ω²) per step, exactly, for the linear oscillator.
    let k: f64 = 400.0;
    let omega = k.sqrt();
    for h in [1e-3, 1e-2, 0.05] {
        let trace = oscillator(k, h, 200);
        let e0 = omega * omega * 0.25;
        let per_step = 1.0 / (1.0 + h * h * omega * omega);
        // (Until the state nears the rounding of positions near 1 m: 1e-9 of the energy.)
        for (n, &(x, v)) in trace.iter().enumerate() {
            let measured = (omega * omega * x * x + v * v) / e0;
            let predicted = per_step.powi(n as i32 + 1);
            if predicted < 1e-9 {
                break;
            }
            assert!(
                (measured - predicted).abs() <= 1e-6 * predicted + 1e-300,
                "h = {h}, step {}: measured {measured:e}, backward Euler {predicted:e}",
                n + 1
            );
        }
        // The phase too: x_n = Re(x₀ zⁿ) with z = 1/(1 + i hω) for starting velocity 0.
        let z = |n: usize| {
            let (re, im) = (
                1.0 / (1.0 + (h * omega).powi(2)),
                -h * omega / (1.0 + (h * omega).powi(2)),
            );
            let (r, a) = ((re * re + im * im).sqrt(), im.atan2(re));
            let (rn, an) = (r.powi(n as i32), a * n as f64);
            // x₀ = 0.5, v₀ = 0: u = ωx + i v starts at 0.5 ω and evolves as u zⁿ.
            (0.5 * rn * an.cos(), 0.5 * omega * rn * an.sin())
        };
        for n in [1usize, 10, 50] {
            let (x, v) = z(n);
            let (mx, mv) = trace[n - 1];
            assert!(
                (mx - x).abs() < 1e-6 && (mv - v).abs() < 1e-6 * omega,
                "h = {h}, n = {n}: ({mx}, {mv}) vs ({x}, {v})"
            );
        }
    }
}

/// Sag (m) of the lowest point below the pins after the cloth settles.
fn sag(method: Method, k: f64, substeps: u32, iterations: u32) -> f64 {
    let forces = Forces {
        damping: 2.0,
        ..Forces::default()
    };
    let mut s = solver(
        settings(method, DT, substeps, iterations),
        forces,
        &hanging_grid(16),
        in_plane(1.0 / k, 1.0, k),
    );
    run(&mut s, 360);
    0.5 - lowest_y(&s)
}

#[test]
fn hanging_cloth_sags_as_much_as_xpbd_with_compliance_one_over_k() {
    for k in [100.0, 1000.0] {
        let xpbd = sag(Method::Xpbd, k, 10, 20);
        let implicit = sag(Method::ImplicitMassSpring, k, 10, 1);
        println!("k = {k} N/m: sag XPBD {xpbd:.4} m, implicit mass-spring {implicit:.4} m");
        assert!(
            (implicit - xpbd).abs() < 0.01 * xpbd,
            "k = {k}: implicit {implicit} vs XPBD {xpbd}"
        );
        assert!(xpbd > 1.0, "the cloth hangs below its pins: {xpbd}");
    }
    // And the sag does depend on k (a test blind to stiffness would pass above).
    assert!(
        sag(Method::ImplicitMassSpring, 100.0, 10, 1)
            > sag(Method::ImplicitMassSpring, 1000.0, 10, 1) + 0.01
    );
}
