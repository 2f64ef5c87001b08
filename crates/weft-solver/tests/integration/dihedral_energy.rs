//! Stiff dihedral bending does not create energy: a free cloth bent into a cylinder and let go,
//! with no gravity and no damping, never holds more kinetic plus bending energy than it started
//! with. (A forward-only Gauss–Seidel sweep of the dihedrals gained 30× here.)

use crate::common::hinges;
use weft_solver::constraints::Dihedral;
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothParams, Family, Forces, GridDesc, Mass, Method, Orientation, Settings, SolverBuilder,
};

#[test]
fn stiff_dihedral_bending_does_not_gain_energy_in_a_free_bent_cloth() {
    // 20² over 1.6 m with α = 1 rad/(N·m) at 10 substeps of 1/60 s is the stiff regime
    // (Σ w|∇C|² ≫ α/h²) where the gain appeared; radius 5 m keeps every angle small.
    let (n, alpha, radius) = (20, 1.0, 5.0);
    let mesh = GridDesc {
        resolution: (n, n),
        size: (1.6, 1.6),
        center: DVec3::ZERO,
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.4),
        pins: vec![],
    }
    .build()
    .expect("valid grid");
    let hinges = hinges(&mesh.triangles);
    // Bending energy Σ ½ θ²/α about the flat rest shape (stretch is inextensible: no energy).
    let bending = |x: &[DVec3]| -> f64 {
        hinges
            .iter()
            .filter_map(|h| Dihedral::angle(&h.map(|i| x[i as usize])))
            .map(|theta| 0.5 * theta * theta / alpha)
            .sum()
    };
    for method in [Method::Xpbd, Method::Pbd] {
        let params = ClothParams::default()
            .edit(Family::BendDistance, |f| f.enabled = false)
            .edit(Family::BendDihedral, |f| {
                f.enabled = true;
                f.compliance = alpha;
                f.pbd_stiffness = 1.0;
            });
        let settings = Settings {
            method,
            ..Settings::default()
        };
        let forces = Forces {
            gravity: DVec3::ZERO,
            damping: 0.0,
            ..Forces::default()
        };
        let mut b = SolverBuilder::new(settings, forces).expect("valid settings");
        b.add_cloth("c", &mesh, params, 0.0).expect("valid cloth");
        let mut s = b.build();
        // Wrap the sheet onto a cylinder about z, keeping arc length: bent, at rest.
        for x in s.particles_mut().positions.iter_mut() {
            let a = x.x / radius;
            *x = DVec3::new(radius * a.sin(), radius * (a.cos() - 1.0), x.z);
        }
        let start = bending(&s.particles().positions);
        assert!(start > 0.04, "{method}: bent start holds {start} J");
        let mut most = 0.0f64;
        for frame in 0..360 {
            if let Err(e) = s.step() {
                panic!("{method}: frame {frame}: {e}");
            }
            let p = s.particles();
            most = most.max(p.kinetic_energy() + bending(&p.positions));
        }
        println!("{method}: bending energy at start {start:.4} J, most KE + bending {most:.4} J");
        assert!(
            most <= 1.02 * start,
            "{method}: kinetic + bending energy reached {most} J from {start} J"
        );
    }
}
