//! The shipped garments (assets/garments), as the walker's scenes use them: each builds, the
//! T-shirt has at least 8,000 particles, every panel starts at least 1 cm outside the
//! walker's body at t = 0, and each seam pairs vertices at the same distance apart along its
//! whole length where the panels are parallel (sides, shoulders, sleeves) or close (armholes).

use std::path::PathBuf;

use weft_character::Character;
use weft_character::garment::{Garment, build_garment};

fn garment(name: &str) -> Garment {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/garments")
        .join(format!("{name}.toml"));
    let spec = weft_character::files::read_garment(&path).expect("garment file");
    build_garment(&spec).expect("garment")
}

/// Smallest and largest distance between the pairs of each seam.
fn seam_gaps(g: &Garment) -> Vec<(f64, f64)> {
    g.seams
        .iter()
        .map(|r| {
            g.seam_pairs[r.clone()]
                .iter()
                .map(|&[a, b]| g.mesh.positions[a as usize].distance(g.mesh.positions[b as usize]))
                .fold((f64::INFINITY, 0.0f64), |(lo, hi), d| {
                    (lo.min(d), hi.max(d))
                })
        })
        .collect()
}

#[test]
fn shipped_garments_start_outside_the_walker() {
    let start = Character::walker().state(0.0);
    for (name, panels, seams) in [("skirt", 2, 2), ("tshirt", 6, 12), ("cape", 1, 0)] {
        let g = garment(name);
        assert_eq!(g.panels.len(), panels, "{name}");
        assert_eq!(g.seams.len(), seams, "{name}");
        for p in &g.panels {
            let d = p
                .vertices
                .clone()
                .map(|v| start.signed_distance(g.mesh.positions[v as usize]))
                .fold(f64::INFINITY, f64::min);
            assert!(d > 0.01, "{name}, panel {}: {d} m from the body", p.name);
        }
    }
    let shirt = garment("tshirt");
    assert!(
        shirt.mesh.positions.len() >= 8000,
        "{}",
        shirt.mesh.positions.len()
    );
    let gaps = seam_gaps(&shirt);
    // Sides and shoulders: front and back 0.31 m apart; sleeve seams: halves 0.24 m apart.
    for (k, &(lo, hi)) in gaps.iter().enumerate() {
        let expect = match k {
            0..=3 => Some(0.31),
            4..=7 => Some(0.24),
            _ => None,
        };
        match expect {
            Some(e) => assert!((lo - e).abs() < 1e-9 && (hi - e).abs() < 1e-9, "seam {k}"),
            None => assert!(hi < 0.07, "armhole seam {k}: pairs up to {hi} m apart"),
        }
    }
    let skirt = seam_gaps(&garment("skirt"));
    assert!(
        skirt
            .iter()
            .all(|&(lo, hi)| (lo - 0.28).abs() < 1e-9 && (hi - 0.28).abs() < 1e-9)
    );
}
