//! Macklin et al. 2019, "Small steps in physics simulation": at equal cost, n substeps × 1
//! iteration end with a much smaller constraint error than 1 substep × n iterations.

use crate::common;

use common::*;
use weft_solver::{Forces, Method};

fn residual(substeps: u32, iterations: u32) -> f64 {
    let mut s = solver(
        settings(Method::Xpbd, 1.0 / 60.0, substeps, iterations),
        Forces::default(),
        &hanging_grid(24),
        in_plane(0.0, 1.0, 0.0),
    );
    let mut worst = 0.0f64;
    for _ in 0..90 {
        s.step().expect("bounded");
        worst = worst.max(s.residual().rms);
    }
    worst
}

#[test]
fn substeps_beat_iterations_at_equal_cost() {
    let ns = [10, 20, 40];
    let sub: Vec<f64> = ns.iter().map(|&n| residual(n, 1)).collect();
    let it: Vec<f64> = ns.iter().map(|&n| residual(1, n)).collect();
    for (k, n) in ns.iter().enumerate() {
        println!(
            "stiff 24x24 cloth, worst RMS stretch error over 1.5 s: {n} substeps x 1 iteration {:.3e} m, 1 substep x {n} iterations {:.3e} m, ratio {:.1}",
            sub[k],
            it[k],
            it[k] / sub[k]
        );
    }
    // Same cost, much smaller error, and the gap widens with n.
    assert!(
        it[0] > 5.0 * sub[0] && it[1] > 10.0 * sub[1] && it[2] > 20.0 * sub[2],
        "{sub:?} vs {it:?}"
    );
    // Substeps converge at second order in n (error ∝ h²), iterations only at first order.
    for k in 0..2 {
        let (rs, ri) = (sub[k] / sub[k + 1], it[k] / it[k + 1]);
        assert!(
            rs > 3.0,
            "substep error should fall ~4x per doubling, fell {rs:.2}x"
        );
        assert!(
            ri < 2.5,
            "iteration error should fall ~2x per doubling, fell {ri:.2}x"
        );
    }
}
