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
    // Skirt: front and back hems 2 × 0.218 m apart, each panel leaning in 10° over its
    // 0.45 m up to the waist, so 0.436 − 2 · 0.45 sin 10° (about 0.28 m) apart there.
    let waist = 0.436 - 2.0 * 0.45 * 10f64.to_radians().sin();
    let skirt = seam_gaps(&garment("skirt"));
    assert!(
        skirt
            .iter()
            .all(|&(lo, hi)| (lo - waist).abs() < 1e-9 && (hi - 0.436).abs() < 1e-9),
        "{skirt:?}"
    );
}

#[test]
fn an_edge_run_holds_the_outline_samples_from_corner_to_corner() {
    let skirt = garment("skirt");
    let front = skirt.panel("front").expect("front");
    // The waistband (edge 2) runs from (0.20, 0.45) to (-0.20, 0.45), sampled about every
    // 15 mm; edges 1..=2 start at the hem's right corner; edges 3..=0 wrap past the last corner.
    let band = front.edge_run(2, 2).expect("edge 2");
    let flat = |v: u32| front.flat[(v - front.vertices.start) as usize];
    assert_eq!(flat(band[0]), weft_solver::glam::DVec2::new(0.20, 0.45));
    assert_eq!(
        flat(*band.last().expect("end")),
        weft_solver::glam::DVec2::new(-0.20, 0.45)
    );
    assert!(band.iter().all(|&v| (flat(v).y - 0.45).abs() < 1e-12));
    assert_eq!(band.len(), (0.40f64 / 0.015).ceil() as usize + 1);
    let side_and_band = front.edge_run(1, 2).expect("edges 1-2");
    assert_eq!(
        flat(side_and_band[0]),
        weft_solver::glam::DVec2::new(0.40, 0.0)
    );
    assert_eq!(side_and_band.last(), band.last());
    let wrap = front.edge_run(3, 0).expect("edges 3-0");
    assert_eq!(
        flat(*wrap.last().expect("end")),
        weft_solver::glam::DVec2::new(0.40, 0.0)
    );
    assert!(front.edge_run(4, 4).is_none());
}
