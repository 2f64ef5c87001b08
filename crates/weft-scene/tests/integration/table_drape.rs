//! The shipped `table_drape.toml`: the tablecloth falls on the table (a compound: a top and
//! four legs), stays on its top and hangs over its edges without entering it.

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
    let (worst, _) = common::closest_approach(g, 0, 150);
    let p = g.solver.particles();
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
