//! A material in physical units behaves the same at any resolution: the constraint parameters
//! it derives (Van Gelder springs, discrete-shell bending, XPBD α = 1/k) make a curtain stretch
//! as continuum mechanics says, and a preset cloth sag the same at 16², 32² and 64², under XPBD
//! and under implicit mass-spring.

use crate::common;

use common::*;
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothMesh, ClothParams, Corner, Edge, Forces, GridDesc, Mass, Material, Method, Orientation,
    Pin, Solver, preset,
};

const DT: f64 = 1.0 / 60.0;

fn grid(n: usize, pins: Vec<Pin>, density: f64) -> ClothMesh {
    GridDesc {
        resolution: (n, n),
        size: (1.0, 1.0),
        center: DVec3::ZERO,
        orientation: Orientation::Vertical,
        mass: Mass::Density(density),
        pins,
    }
    .build()
    .expect("valid grid")
}

/// Settles `mesh` of `material` under `method` and returns the solver.
fn settle(method: Method, mesh: &ClothMesh, material: &Material, frames: usize) -> Solver {
    let (substeps, iterations) = match method {
        Method::ImplicitMassSpring => (2, 1),
        _ => (10, 10),
    };
    let settings = settings(method, DT, substeps, iterations);
    let params = material.params(mesh, &settings, &ClothParams::default());
    let forces = Forces {
        damping: 4.0,
        ..Forces::default()
    };
    let mut s = solver(settings, forces, mesh, params);
    run(&mut s, frames);
    s
}

/// A soft membrane, so its stretch is large enough to measure.
const SOFT: Material = Material::isotropic(0.2, 20.0, 2.0, 1e-6);

#[test]
fn a_curtain_stretches_as_a_membrane_under_its_own_weight_at_every_resolution() {
    // Pinned along its top edge, the curtain carries σ(y) = ρ g (L − y) at depth y; with
    // free sides, ε = σ / E₁ (E₁ = (C₁₁² − C₁₂²)/C₁₁ = E (1 − (G/E)²), uniaxial), so the bottom
    // edge drops by ∫ε dy = ρ g L² / (2 E₁).
    let e1 = SOFT.stretch * (1.0 - (SOFT.shear / SOFT.stretch).powi(2));
    let expected = SOFT.density * 9.81 / (2.0 * e1);
    for method in [Method::Xpbd, Method::ImplicitMassSpring] {
        let mut drops = Vec::new();
        for n in [16, 32, 64] {
            let mesh = grid(n, vec![Pin::Edge(Edge::Top)], SOFT.density);
            let s = settle(method, &mesh, &SOFT, 180);
            // The bottom row's mean drop below its rest height.
            let row = (n - 1) * n..n * n;
            let drop: f64 = row
                .clone()
                .map(|i| mesh.positions[i].y - s.particles().positions[i].y)
                .sum::<f64>()
                / n as f64;
            println!(
                "{method} {n}²: bottom edge dropped {drop:.4} m (membrane theory {expected:.4} m)"
            );
            drops.push(drop);
        }
        // Each within 8 % of the membrane, converging on it as the grid refines (the boundary
        // edges, which Van Gelder gives half the interior stiffness, share the interior value:
        // an O(1/n) stiffening), and within 5 % of each other.
        for (d, n) in drops.iter().zip([16, 32, 64]) {
            assert!(
                (d - expected).abs() < 0.08 * expected,
                "{method} {n}²: drop {d}, expected {expected}"
            );
        }
        assert!(
            (drops[2] - expected).abs() < (drops[0] - expected).abs(),
            "{method}: no convergence, {drops:?}"
        );
        let spread = drops.iter().copied().fold(f64::NAN, f64::max)
            - drops.iter().copied().fold(f64::NAN, f64::min);
        assert!(spread < 0.05 * expected, "{method}: drops {drops:?}");
    }
}

#[test]
fn a_preset_cloth_hangs_the_same_at_every_resolution() {
    let jersey = preset("jersey").expect("preset");
    for method in [Method::Xpbd, Method::ImplicitMassSpring] {
        let mut sags = Vec::new();
        for n in [16, 32, 64] {
            let pins = vec![Pin::Corner(Corner::TopLeft), Pin::Corner(Corner::TopRight)];
            let mesh = grid(n, pins, jersey.density);
            let s = settle(method, &mesh, &jersey, 180);
            let sag = 0.5 - lowest_y(&s);
            println!("{method} {n}²: jersey sags {sag:.4} m");
            sags.push(sag);
        }
        let spread = sags.iter().copied().fold(f64::NAN, f64::max)
            - sags.iter().copied().fold(f64::NAN, f64::min);
        assert!(spread < 0.03 * sags[0], "{method}: sags {sags:?}");
    }
}
