//! Seams closing in the solver: a tube sewn from two flat panels 0.2 m apart, under each
//! method. The seam's rest length ramps to zero over the closing time T (the gap at T/2 is
//! about half the initial one), then the seam holds the pair closed (below 1 mm).

use crate::common;

use common::tube_garment;
use weft_character::garment::{Garment, GarmentSpec, build_garment};
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothParams, Family, FamilyParams, Forces, Method, Settings, Solver, SolverBuilder, Topology,
    stable_spring_defaults,
};

/// Closing time (s).
const T: f64 = 0.5;

fn tube() -> Garment {
    // 0.2 m wide, 0.15 m tall panels facing each other 0.2 m apart.
    let spec = GarmentSpec::from_toml(&tube_garment(0.1, 0.15, 0.0, 0.1, 0.2)).expect("spec");
    build_garment(&spec).expect("tube")
}

fn solver(method: Method, g: &Garment) -> Solver {
    let settings = Settings {
        method,
        substeps: 20,
        ..Settings::default()
    };
    // No gravity: nothing but the cloth and its seams; a little air drag so the spring
    // methods settle.
    let forces = Forces {
        gravity: DVec3::ZERO,
        damping: 2.0,
        ..Forces::default()
    };
    let mut params = stable_spring_defaults(
        &g.mesh,
        &Topology::new(&g.mesh.triangles),
        &ClothParams::default(),
        &[Family::Stretch, Family::Shear, Family::BendDistance],
    )
    .expect("springs");
    for f in [Family::Stretch, Family::Shear] {
        params.get_mut(f).spring_damping = 1e-3;
    }
    let mut seam = FamilyParams::seam_default();
    seam.spring_stiffness = params.get(Family::Stretch).spring_stiffness;
    seam.spring_damping = 1e-3;
    let mut b = SolverBuilder::new(settings, forces).expect("builder");
    let cloth = b.add_cloth("tube", &g.mesh, params, 0.002).expect("cloth");
    b.add_seams(cloth, &g.seam_pairs, T, seam).expect("seams");
    b.build()
}

/// Steps until time `t` (s).
fn run_to(s: &mut Solver, t: f64) {
    while s.time() < t - 1e-9 {
        s.step().expect("step");
    }
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn seams_close_over_the_closing_time_then_stay_closed_under_every_method() {
    let g = tube();
    for method in Method::ALL {
        let mut s = solver(method, &g);
        let start = s.seam_gaps();
        assert_eq!(start.len(), g.seam_pairs.len());
        assert!(
            (mean(&start) - 0.2).abs() < 1e-9,
            "{method}: {}",
            mean(&start)
        );
        run_to(&mut s, T / 2.0);
        let half = mean(&s.seam_gaps()) / mean(&start);
        run_to(&mut s, T + 1.0);
        let closed = max(&s.seam_gaps());
        eprintln!("{method}: gap at T/2 {half:.3} of the start, after closing {closed:.2e} m");
        assert!(
            (half - 0.5).abs() < 0.05,
            "{method}: gap at T/2 is {half} of the start"
        );
        assert!(closed < 1e-3, "{method}: a seam is still {closed} m open");
    }
}
