//! A cloth dropped on a sphere never enters it and comes to rest draped over it, for every method.

mod common;

use weft_collide::scenarios::{SPHERE_RADIUS, THICKNESS, sphere_drop};
use weft_solver::Method;

/// Allowed penetration of the thickness shell at the end of any substep (m): 10 % of thickness.
const TOLERANCE: f64 = 0.1 * THICKNESS;

#[test]
fn cloth_drapes_on_sphere_without_penetration_for_every_method() {
    for method in Method::ALL {
        let (mut solver, mut world) = sphere_drop(method, 20).expect("scenario builds");
        // Energy the fall releases: m g Δh for the 0.2 m drop plus the drape (≈ 0.3 m more).
        let released = 0.4 * 9.81 * 0.5;
        let mut worst = f64::INFINITY;
        let mut first_contact = None;
        common::run(&mut solver, &mut world, 180, |ctx, p| {
            for x in &p.positions {
                let gap = x.length() - (SPHERE_RADIUS + THICKNESS);
                if gap < 0.05 && first_contact.is_none() {
                    first_contact = Some(ctx.time);
                }
                worst = worst.min(gap);
            }
        });
        let p = solver.particles();
        let n = 20;
        let c = (n / 2) * n + n / 2;
        let centre = p.positions[c];
        let centre_speed = p.velocities[c].length();
        let ke = p.kinetic_energy();
        let vmax = common::max_speed(p);
        println!(
            "{method}: worst gap {:.5} m (tolerance {TOLERANCE}), centre y {:.4}, KE {ke:.2e} J, \
             vmax {vmax:.4} m/s, centre speed {centre_speed:.2e} m/s, first contact {first_contact:?}",
            worst, centre.y
        );
        assert!(
            first_contact.is_some(),
            "{method}: cloth never reached the sphere"
        );
        assert!(
            worst >= -TOLERANCE,
            "{method}: a particle went {:.4} m into the thickness shell",
            -worst
        );
        // Resting on top: the particle nearest the middle (half a spacing off the axis for an
        // even grid) lies a thickness above the sphere's top and does not move.
        let top = SPHERE_RADIUS + THICKNESS;
        assert!(
            (centre.length() - top).abs() < 0.003 && centre.x.abs() < 0.06 && centre.z.abs() < 0.06,
            "{method}: centre particle at {centre}, expected on the sphere's top"
        );
        assert!(
            centre_speed < 0.01,
            "{method}: centre moves at {centre_speed} m/s"
        );
        assert!(
            ke < 1e-3 * released,
            "{method}: kinetic energy {ke} J is not small against the {released} J released"
        );
    }
}
