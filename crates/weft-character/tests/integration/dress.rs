//! The pieces together, as a solver will use them: a two-panel skirt sewn into a tube around
//! the walker's hips, starting outside the body, its waistband attached to the hips.

use crate::common;

use common::tube_garment;
use weft_character::garment::{GarmentSpec, build_garment};
use weft_character::{Attachment, Character};

/// A skirt: two 0.3 m × 0.3 m panels at hip height, 0.36 m apart, sewn at both sides.
fn skirt() -> String {
    tube_garment(0.15, 0.3, 0.65, 0.18, 0.2)
}

#[test]
fn a_skirt_starts_outside_the_walker_and_its_waistband_follows_the_hips() {
    let walker = Character::walker();
    let skirt = build_garment(&GarmentSpec::from_toml(&skirt()).expect("spec")).expect("skirt");
    // Dress the walker mid-stride, with the hips turned, so the binding needs the bone's full
    // transform (its inverse rotation too).
    let t0 = 0.3;
    let start = walker.state(t0);
    assert!(
        start.bones[0]
            .transform
            .rotation
            .angle_between(glam::DQuat::IDENTITY)
            > 0.05
    );
    for (i, p) in skirt.mesh.positions.iter().enumerate() {
        let d = start.signed_distance(*p);
        assert!(d > 0.005, "skirt vertex {i} at {p} is {d} m from the body");
    }
    // The waistband: every vertex on the panels' top edges (flat y = 0.3).
    let waist = common::flat_row(&skirt, 0.3);
    let per_panel = (0.3_f64 / 0.03).ceil() as usize + 1;
    assert_eq!(waist.len(), 2 * per_panel);
    let hips = walker.animation().skeleton().find("Hips").expect("hips");
    let band = Attachment::bind(
        hips,
        waist,
        &skirt.mesh.positions,
        &start.bones[hips].transform,
    )
    .expect("bind");
    let rest: Vec<glam::DVec3> = band
        .vertices()
        .iter()
        .map(|&v| {
            start.bones[hips]
                .transform
                .inverse()
                .transform_point(skirt.mesh.positions[v as usize])
        })
        .collect();
    for k in 1..50 {
        let state = walker.state(t0 + k as f64 * 0.05);
        let at = band.positions(&state.bones[hips].transform);
        let back = state.bones[hips].transform.inverse();
        for (p, r) in at.iter().zip(&rest) {
            assert!((back.transform_point(*p) - *r).length() < 1e-9);
        }
        // The band stays off the body while the walker moves.
        assert!(
            at.iter().all(|p| state.signed_distance(*p) > 0.0),
            "band touches at {k}"
        );
    }
}
