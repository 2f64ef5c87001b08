//! The shipped `mesh_drape.toml`: a cloth falls on a still triangle mesh (the bumpy blob) and
//! rests on its top a thickness off, never nearer the surface than the thickness, with the
//! mesh's contacts inside the solver's fused frame (through its contact grid).

use crate::common;

use weft_solver::{Method, SubstepHook};

#[test]
fn the_shipped_cloth_drapes_on_the_blob_a_thickness_off() {
    let path = common::scenes_dir().join("mesh_drape.toml");
    let scene = common::load(&path, &[]);
    let thickness = scene.cloths[0].thickness;
    let mut groups = common::with_method(&path, Method::Xpbd, &[]);
    let g = &mut groups[0];
    let (worst, blob) = common::closest_approach(g, 0, 150);
    let fused = g
        .world
        .as_ref()
        .is_some_and(|w| w.particle_contacts().is_some());
    let p = g.solver.particles();
    let middle = common::middle_particle(p);
    // The middle particle rests on the blob's top, a thickness above it.
    let rest = blob.closest(middle, 1.0).expect("near the blob").distance;
    let centre = scene.colliders[0].position;
    println!(
        "closest approach to the blob {worst:.5} m; the middle particle {rest:.5} m off it, \
         {:.3} m above its centre; KE {:.2e} J; fused {fused}",
        middle.y - centre.y,
        p.kinetic_energy()
    );
    assert!(fused, "a still mesh's contacts run in the fused frame");
    assert!(
        worst >= 0.9 * thickness,
        "a particle came {worst} m from the blob"
    );
    assert!(
        (rest - thickness).abs() < 1e-3 && middle.y > centre.y + 0.3,
        "middle at {middle}, {rest} m off the blob"
    );
}
