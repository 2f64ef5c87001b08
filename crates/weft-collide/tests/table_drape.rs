//! A square cloth falls on a box, stays on its top and hangs over its edges without entering it.

mod common;

use weft_collide::scenarios::{TABLE_HALF_EXTENTS, THICKNESS, table_drape};
use weft_solver::Method;

#[test]
fn cloth_drapes_over_the_table_edges() {
    let (mut solver, mut world) = table_drape(Method::Xpbd, 20).expect("scenario builds");
    let table = world.colliders()[0].clone();
    let top = 2.0 * TABLE_HALF_EXTENTS.y;
    let mut worst = f64::INFINITY;
    common::run(&mut solver, &mut world, 150, |_, p| {
        for x in &p.positions {
            if let Some(s) = table.closest(*x, 1.0) {
                worst = worst.min(s.distance);
            }
        }
    });
    let p = solver.particles();
    let middle = p.positions[10 * 20 + 10];
    let lowest = p.positions.iter().map(|x| x.y).fold(f64::MAX, f64::min);
    println!(
        "closest approach to the box {worst:.5} m; middle at y = {:.4} (top + thickness = \
         {:.4}); lowest particle {lowest:.3} m; KE {:.2e} J",
        middle.y,
        top + THICKNESS,
        p.kinetic_energy()
    );
    assert!(
        worst >= 0.9 * THICKNESS,
        "a particle came {worst} m from the box"
    );
    assert!(
        (middle.y - (top + THICKNESS)).abs() < 1e-3,
        "middle at {middle}"
    );
    // 1.4 m cloth on a 0.8 m table: 0.3 m hangs over each side.
    assert!(
        lowest < top - 0.2,
        "edges do not hang: lowest particle at {lowest}"
    );
}
