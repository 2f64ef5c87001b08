//! Free fall follows semi-implicit Euler's closed form; pinned particles never move.

use crate::common;

use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{Forces, Method};

/// Semi-implicit Euler from rest-velocity v₀: xₙ = x₀ + n h v₀ + h² g n(n+1)/2 (exact for this order).
fn closed_form(x0: DVec3, v0: DVec3, g: DVec3, h: f64, n: u32) -> DVec3 {
    let n = f64::from(n);
    x0 + n * h * v0 + h * h * g * n * (n + 1.0) / 2.0
}

#[test]
fn free_fall_matches_the_integrators_closed_form_for_every_method() {
    let g = DVec3::new(0.0, -9.81, 0.0);
    let v0 = DVec3::new(1.0, 2.0, -0.5);
    for method in Method::ALL {
        let mesh = chain(
            &[DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)],
            &[1.0; 3],
            &[0],
        );
        let mut s = solver(
            settings(method, 1.0 / 60.0, 4, 3),
            Forces::default(),
            &mesh,
            no_families(),
        );
        s.particles_mut().velocities[1] = v0;
        s.particles_mut().velocities[2] = v0;
        run(&mut s, 120); // 2 s, 480 substeps
        let h = s.settings().h();
        for i in [1, 2] {
            let expected = closed_form(mesh.positions[i], v0, g, h, 480);
            let got = s.particles().positions[i];
            let err = (got - expected).length();
            assert!(
                err < 1e-12 * expected.length(),
                "{method}: particle {i} at {got}, expected {expected}"
            );
        }
        assert_eq!(
            s.particles().positions[0],
            DVec3::ZERO,
            "{method}: pinned particle moved"
        );
        assert_eq!(s.particles().velocities[0], DVec3::ZERO);
        // And the fall really happened: ~19.6 m of drop in 2 s.
        assert!(s.particles().positions[1].y < -15.0);
    }
}

#[test]
fn pinned_particles_of_a_stretched_cloth_never_move() {
    for method in Method::ALL {
        let mesh = weft_solver::GridDesc {
            resolution: (12, 12),
            orientation: weft_solver::Orientation::Horizontal,
            ..weft_solver::GridDesc::default()
        }
        .build()
        .expect("valid grid");
        let mut s = solver(
            settings(method, 1.0 / 60.0, 10, 2),
            Forces::default(),
            &mesh,
            in_plane(1e-4, 0.5, 500.0),
        );
        let mut deepest = f64::INFINITY;
        for _ in 0..60 {
            s.step().expect("bounded");
            deepest = deepest.min(lowest_y(&s));
        }
        for &p in &mesh.pinned {
            assert_eq!(
                s.particles().positions[p as usize],
                mesh.positions[p as usize],
                "{method}"
            );
        }
        assert!(
            deepest < -0.8,
            "{method}: the horizontal cloth should have swung down, lowest {deepest}"
        );
    }
}
