//! The XPBD paper's oscillator (§6.1): rest length 1, start at 1.5, α = 0.001, m = 1.
//! XPBD's period stays near 2π√(mα) for any step and iteration count; PBD's does not.

use crate::common;

use std::f64::consts::TAU;

use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{Forces, Method};

const ALPHA: f64 = 1e-3;

/// Period (s) from the first upward zero crossings of the extension, sampled every substep.
fn period(method: Method, h: f64, iterations: u32, pbd_stiffness: f64) -> f64 {
    trace(method, h, iterations, pbd_stiffness, 0.0).0
}

/// (period, amplitude of the extension after 1 s) with XPBD constraint damping β.
fn trace(method: Method, h: f64, iterations: u32, pbd_stiffness: f64, beta: f64) -> (f64, f64) {
    // Rest length 1 (taken from the built positions), then released from 1.5.
    let mesh = chain(&[DVec3::ZERO, DVec3::X], &[1.0, 1.0], &[0]);
    let forces = Forces {
        gravity: DVec3::ZERO,
        ..Forces::default()
    };
    let params = in_plane(ALPHA, pbd_stiffness, 0.0)
        .edit(weft_solver::Family::Stretch, |p| p.damping = beta);
    let mut s = solver(settings(method, h, 1, iterations), forces, &mesh, params);
    s.particles_mut().positions[1] = DVec3::new(1.5, 0.0, 0.0);
    let mut crossings = Vec::new();
    let mut last = 0.5f64;
    let mut late_amplitude = 0.0f64;
    for k in 1..=(1.2 / h) as usize {
        s.step().expect("bounded");
        let e = s.particles().positions[1].length() - 1.0;
        if last < 0.0 && e >= 0.0 && crossings.len() < 3 {
            let frac = last / (last - e);
            crossings.push((k as f64 - 1.0 + frac) * h);
        }
        if k as f64 * h > 1.0 {
            late_amplitude = late_amplitude.max(e.abs());
        }
        last = e;
    }
    assert!(
        crossings.len() >= 2,
        "{method} h={h}: no oscillation seen ({crossings:?})"
    );
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    (period, late_amplitude)
}

#[test]
fn xpbd_period_matches_the_analytic_period_for_any_step_and_iterations() {
    let analytic = TAU * ALPHA.sqrt();
    let omega = TAU / analytic;
    for h in [1.0 / 60.0, 1.0 / 120.0, 1.0 / 240.0, 1.0 / 960.0] {
        // Implicit Euler turns ω into atan(hω)/h: the known discretisation error of the step.
        let implicit_euler = TAU * h / (h * omega).atan();
        for iterations in [1, 4, 16] {
            let t = period(Method::Xpbd, h, iterations, 1.0);
            println!(
                "XPBD h=1/{:.0} iterations={iterations}: period {t:.5} s, analytic {analytic:.5} s ({:+.2}%), implicit Euler {implicit_euler:.5} s",
                1.0 / h,
                (t / analytic - 1.0) * 100.0
            );
            assert!(
                (t / implicit_euler - 1.0).abs() < 0.005,
                "h={h}: {t} vs implicit Euler {implicit_euler}"
            );
            assert!(
                (t / analytic - 1.0).abs() < 0.10,
                "h={h}: {t} vs analytic {analytic}"
            );
            if h <= 1.0 / 240.0 {
                assert!(
                    (t / analytic - 1.0).abs() < 0.02,
                    "h={h}: {t} vs analytic {analytic}"
                );
            }
        }
    }
}

#[test]
fn pbd_period_depends_on_step_and_iterations() {
    let analytic = TAU * ALPHA.sqrt();
    let mut periods = Vec::new();
    for h in [1.0 / 60.0, 1.0 / 240.0] {
        for iterations in [1, 4, 16] {
            let t = period(Method::Pbd, h, iterations, 0.05);
            println!(
                "PBD k=0.05 h=1/{:.0} iterations={iterations}: period {t:.5} s ({:+.1}% from analytic)",
                1.0 / h,
                (t / analytic - 1.0) * 100.0
            );
            periods.push(t);
        }
    }
    let (min, max) = periods
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    assert!(
        max / min > 3.0,
        "PBD periods should spread with h and iterations: {periods:?}"
    );
    // More iterations make PBD stiffer, so its period shrinks, at each step size.
    for pair in periods.chunks(3) {
        assert!(pair[0] > pair[1] && pair[1] > pair[2], "{pair:?}");
    }
}

#[test]
fn xpbd_constraint_damping_damps_without_changing_the_period_much() {
    let h = 1.0 / 960.0;
    let omega = 1.0 / ALPHA.sqrt();
    let (t0, a0) = trace(Method::Xpbd, h, 1, 1.0, 0.0);
    // β = 2 N·s/m on m = 1 kg: damping ratio ζ = β / (2 m ω) ≈ 0.032, decay rate ζω = 1 /s.
    let (t1, a1) = trace(Method::Xpbd, h, 1, 1.0, 2.0);
    // Undamped, implicit Euler still loses (1 + (hω)²)^(−1/2) of the amplitude per step.
    let predicted = 0.5 * (1.0 + (h * omega).powi(2)).powf(-0.5 / h);
    println!(
        "XPBD h=1/960: undamped period {t0:.5} s, amplitude after 1 s {a0:.4} m (implicit Euler predicts {predicted:.4}); β = 2 N·s/m: {t1:.5} s, {a1:.4} m (ratio {:.3}, e^-1 = 0.368)",
        a1 / a0
    );
    assert!((a0 / predicted - 1.0).abs() < 0.05, "{a0} vs {predicted}");
    assert!((a1 / a0 - (-1.0f64).exp()).abs() < 0.06, "{a1} vs {a0}");
    assert!((t1 / t0 - 1.0).abs() < 0.01, "period {t1} vs {t0}");
}
