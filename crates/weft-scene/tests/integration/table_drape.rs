//! The shipped `table_drape.toml`: the tablecloth falls on the table (a compound: a top and
//! four legs), stays on its top and hangs over its edges without entering it, and its drawn
//! surface (the flat triangles between the particles) stays out of the table too.

use crate::common;

use weft_collide::{CompoundPart, ShapeDesc};
use weft_solver::Method;

#[test]
fn the_shipped_tablecloth_drapes_over_the_table_edges() {
    let path = common::scenes_dir().join("table_drape.toml");
    let scene = common::load(&path, &[]);
    let table = &scene.colliders[0];
    let ShapeDesc::Compound(parts) = &table.shape else {
        panic!("the table is a compound");
    };
    // The table's top is its first part, a cuboid.
    let CompoundPart {
        position: at,
        shape: ShapeDesc::Cuboid { half_extents },
        ..
    } = &parts[0]
    else {
        panic!("the table's first part is its top, a cuboid");
    };
    let top = table.position.y + at.y + half_extents.y;
    let thickness = scene.cloths[0].thickness;
    let mut groups = common::with_method(&path, Method::Xpbd, &[]);
    let g = &mut groups[0];
    let (worst, table) = common::closest_approach(g, 0, 150);
    let p = g.solver.particles();
    // The drawn cloth: every triangle's centre and edge midpoints lie outside the table. With
    // the top's edges square, the triangles across an edge cut its corner (the edge showed
    // through the cloth as a dashed line): 6.1 mm inside at worst.
    let x = &p.positions;
    let mut deepest = f64::INFINITY;
    for t in &g.solver.cloths()[0].triangles {
        let [a, b, c] = t.map(|i| x[i as usize]);
        for q in [
            (a + b + c) / 3.0,
            (a + b) / 2.0,
            (b + c) / 2.0,
            (c + a) / 2.0,
        ] {
            if let Some(s) = table.closest(q, 1.0) {
                deepest = deepest.min(s.distance);
            }
        }
    }
    assert!(
        deepest > 0.0,
        "the drawn cloth enters the table by {} m",
        -deepest
    );
    let middle = common::middle_particle(p);
    let lowest = p.positions.iter().map(|x| x.y).fold(f64::MAX, f64::min);
    println!(
        "closest approach to the table {worst:.5} m; middle at y = {:.4} (top + thickness = \
         {:.4}); lowest particle {lowest:.3} m; KE {:.2e} J",
        middle.y,
        top + thickness,
        p.kinetic_energy()
    );
    assert!(
        worst >= 0.9 * thickness,
        "a particle came {worst} m from the table"
    );
    assert!(
        (middle.y - (top + thickness)).abs() < 1e-3,
        "middle at {middle}"
    );
    // A 1.8 m cloth on a 1.0 m table top: 0.4 m hangs over each side.
    assert!(
        lowest < top - 0.3,
        "edges do not hang: lowest particle at {lowest}"
    );
}
