//! The XPBD paper's hanging cloth (§6.2, Fig. 4): with PBD the cloth stiffens as iterations
//! grow 20 → 40 → 80 → 160; with XPBD its sag stays put.
//!
//! XPBD's sag is set by compliance once each solve converges. Convergence needs α̃ = α/h² not
//! far below the particles' inverse masses; with α = 0.03 m/N on this 16² cloth of 1 kg that
//! holds from 20 iterations on. (With α → 0 and few iterations XPBD, like any unconverged
//! solve, is softer than asked: `small_steps.rs` measures that error.)

use crate::common;

use common::*;
use weft_solver::{Forces, Method, Settings};

const DT: f64 = 1.0 / 60.0;
const ALPHA: f64 = 0.03;

/// Sag (m) of the lowest point below its rest height after the cloth settles.
fn sag(
    method: Method,
    substeps: u32,
    iterations: u32,
    dt: f64,
    compliance: f64,
    pbd_stiffness: f64,
) -> f64 {
    let settings = settings(method, dt, substeps, iterations);
    sag_with(settings, compliance, pbd_stiffness).0
}

/// [`sag`] with every setting given, and the number of domains the cloth was cut into.
fn sag_with(settings: Settings, compliance: f64, pbd_stiffness: f64) -> (f64, usize) {
    let dt = settings.dt;
    let forces = Forces {
        damping: 2.0,
        ..Forces::default()
    };
    let mut s = solver(
        settings,
        forces,
        &hanging_grid(16),
        in_plane(compliance, pbd_stiffness, 0.0),
    );
    run(&mut s, (5.0 / dt) as usize);
    (-0.5 - lowest_y(&s), s.domain_stats().domains)
}

#[test]
fn pbd_stiffens_with_iterations_while_xpbd_sag_stays_the_same() {
    let iterations = [20, 40, 80, 160];
    let pbd: Vec<f64> = iterations
        .iter()
        .map(|&n| sag(Method::Pbd, 1, n, DT, 0.0, 0.01))
        .collect();
    let xpbd: Vec<f64> = iterations
        .iter()
        .map(|&n| sag(Method::Xpbd, 1, n, DT, ALPHA, 1.0))
        .collect();
    for (k, n) in iterations.iter().enumerate() {
        println!(
            "iterations {n:>3}: PBD (k = 0.01) sag {:.4} m, XPBD (α = 0.03 m/N) sag {:.4} m",
            pbd[k], xpbd[k]
        );
    }
    // PBD: each doubling of iterations makes the cloth visibly stiffer.
    for w in pbd.windows(2) {
        assert!(
            w[1] < 0.9 * w[0],
            "PBD sag should drop with iterations: {pbd:?}"
        );
    }
    assert!(pbd[0] > 2.0 * pbd[3], "PBD sag spread too small: {pbd:?}");
    // XPBD: the same cloth whatever the iteration count (within 1 % of the 160-iteration value).
    let converged = xpbd[3];
    for s in &xpbd {
        assert!(
            (s / converged - 1.0).abs() < 0.01,
            "XPBD sag should not depend on iterations: {xpbd:?}"
        );
    }
    // And it really is a compliant cloth, sagging well beyond its rigid drape.
    let rigid = sag(Method::Xpbd, 1, 160, DT, 0.0, 1.0);
    println!("rigid (α = 0) sag {rigid:.4} m");
    assert!(
        converged > rigid + 0.05,
        "compliant {converged} vs rigid {rigid}"
    );
}

#[test]
fn xpbd_sag_does_not_depend_on_the_time_step_but_pbd_sag_does() {
    let dts = [1.0 / 30.0, 1.0 / 60.0, 1.0 / 120.0];
    let xpbd: Vec<f64> = dts
        .iter()
        .map(|&dt| sag(Method::Xpbd, 5, 20, dt, ALPHA, 1.0))
        .collect();
    let pbd: Vec<f64> = dts
        .iter()
        .map(|&dt| sag(Method::Pbd, 5, 20, dt, 0.0, 0.05))
        .collect();
    for (k, dt) in dts.iter().enumerate() {
        println!(
            "dt 1/{:.0}, 5 substeps x 20 iterations: XPBD sag {:.4} m, PBD (k = 0.05) sag {:.4} m",
            1.0 / dt,
            xpbd[k],
            pbd[k]
        );
    }
    for s in &xpbd {
        assert!(
            (s / xpbd[1] - 1.0).abs() < 0.01,
            "XPBD sag should not depend on dt: {xpbd:?}"
        );
    }
    assert!(
        pbd[0] > 3.0 * pbd[1] && pbd[1] > 3.0 * pbd[2],
        "PBD should stiffen as dt shrinks: {pbd:?}"
    );
}

#[test]
fn xpbd_sag_is_the_same_in_one_domain_and_cut_into_four() {
    // 256 particles: one domain by default, four of 64 (with links between them) when cut.
    let base = settings(Method::Xpbd, DT, 5, 20);
    let (whole, one) = sag_with(base, ALPHA, 1.0);
    let (cut, four) = sag_with(
        Settings {
            domain_size: 64,
            ..base
        },
        ALPHA,
        1.0,
    );
    println!("XPBD sag in one domain {whole:.5} m, in four {cut:.5} m");
    assert_eq!((one, four), (1, 4), "domain counts");
    assert!(
        (cut / whole - 1.0).abs() < 0.001,
        "the domains' split moved the converged sag: {whole} vs {cut}"
    );
}
