//! A mass hanging on one compliant XPBD constraint stretches by m·g·α, whatever the time step.

use crate::common;

use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{Forces, Method};

fn settle(mass: f64, alpha: f64, dt: f64, substeps: u32) -> f64 {
    let mesh = chain(
        &[DVec3::ZERO, DVec3::new(0.0, -1.0, 0.0)],
        &[1.0, mass],
        &[0],
    );
    let forces = Forces {
        damping: 4.0,
        ..Forces::default()
    };
    let mut s = solver(
        settings(Method::Xpbd, dt, substeps, 1),
        forces,
        &mesh,
        in_plane(alpha, 1.0, 0.0),
    );
    run(&mut s, (8.0 / dt) as usize);
    s.particles().positions[1].length() - 1.0
}

#[test]
fn extension_is_m_g_alpha_for_any_time_step_and_substep_count() {
    for (mass, alpha) in [(1.0, 1e-3), (0.25, 1e-2), (2.0, 1e-4)] {
        let expected = mass * 9.81 * alpha;
        for dt in [1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0] {
            for substeps in [1, 4, 20] {
                let e = settle(mass, alpha, dt, substeps);
                let rel = (e - expected).abs() / expected;
                println!(
                    "m={mass} α={alpha:e} dt=1/{:.0} substeps={substeps}: extension {e:.6e} m, m·g·α {expected:.6e} m, error {:.3}%",
                    1.0 / dt,
                    rel * 100.0
                );
                assert!(rel < 0.01, "extension {e} vs m·g·α = {expected}");
            }
        }
    }
}
