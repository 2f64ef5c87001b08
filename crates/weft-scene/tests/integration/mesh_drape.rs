//! The shipped `mesh_drape.toml`: a cloth falls on a still triangle mesh (the bumpy blob) and
//! rests on its top a thickness off, never nearer the surface than the thickness, as shipped
//! (cloth contact on) and with cloth contact off, when the mesh's contacts run inside the
//! solver's fused frame (through its contact grid).

use crate::common;

use weft_solver::{Method, SubstepHook};

/// The scene with `extra` overrides: the closest approach to the blob over 150 frames, the
/// middle particle's distance from it and height above its centre, and whether the mesh's
/// contacts ran in the fused frame.
fn drape(extra: &[String]) -> (f64, f64, f64, bool) {
    let path = common::scenes_dir().join("mesh_drape.toml");
    let scene = common::load(&path, extra);
    let mut groups = common::with_method(&path, Method::Xpbd, extra);
    let g = &mut groups[0];
    let (worst, blob) = common::closest_approach(g, 0, 150);
    let fused = g
        .world
        .as_ref()
        .is_some_and(|w| w.particle_contacts().is_some());
    let p = g.solver.particles();
    let middle = common::middle_particle(p);
    let rest = blob.closest(middle, 1.0).expect("near the blob").distance;
    let height = middle.y - scene.colliders[0].position.y;
    println!(
        "{extra:?}: closest approach to the blob {worst:.5} m; the middle particle {rest:.5} m \
         off it, {height:.3} m above its centre; KE {:.2e} J; fused {fused}",
        p.kinetic_energy()
    );
    (worst, rest, height, fused)
}

#[test]
fn the_shipped_cloth_drapes_on_the_blob_a_thickness_off() {
    let path = common::scenes_dir().join("mesh_drape.toml");
    let thickness = common::load(&path, &[]).cloths[0].thickness;
    let off = ["self_collision.enabled=false".to_string()];
    for (extra, fused_expected) in [(&[][..], false), (&off[..], true)] {
        let (worst, rest, height, fused) = drape(extra);
        // Cloth contact needs every projection's hook, which the fused frame does not call.
        assert_eq!(fused, fused_expected, "{extra:?}: fused frame");
        assert!(
            worst >= 0.9 * thickness,
            "{extra:?}: a particle came {worst} m from the blob"
        );
        // The middle particle rests on the blob's top, a thickness above it.
        assert!(
            (rest - thickness).abs() < 1e-3 && height > 0.3,
            "{extra:?}: middle {height} m above the centre, {rest} m off the blob"
        );
    }
}
