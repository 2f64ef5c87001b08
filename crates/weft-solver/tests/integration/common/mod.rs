//! Fixtures shared by the physics tests.
//!
//! - `flag`: the windy flag the determinism tests run, on a given thread count, fused or general.
#![allow(dead_code)]

pub mod flag;

use std::collections::HashMap;

use weft_solver::glam::DVec3;
use weft_solver::{
    ClothMesh, ClothParams, Corner, Edge, Family, Forces, GridDesc, Mass, Material, Method,
    Orientation, Pin, Settings, Solver, SolverBuilder,
};

/// Cloth parameters with every family switched off.
pub fn no_families() -> ClothParams {
    let mut p = ClothParams::default();
    for f in Family::ALL {
        p.get_mut(f).enabled = false;
    }
    p
}

/// Stretch (and shear, on grids) only, with the given XPBD compliance, PBD stiffness and spring stiffness.
pub fn in_plane(compliance: f64, pbd_stiffness: f64, spring_stiffness: f64) -> ClothParams {
    let mut p = no_families();
    for f in [Family::Stretch, Family::Shear] {
        let fp = p.get_mut(f);
        fp.enabled = true;
        fp.compliance = compliance;
        fp.pbd_stiffness = pbd_stiffness;
        fp.spring_stiffness = spring_stiffness;
    }
    p
}

/// A polyline of particles joined by stretch constraints; `pinned` get inverse mass 0.
pub fn chain(points: &[DVec3], masses: &[f64], pinned: &[u32]) -> ClothMesh {
    ClothMesh {
        positions: points.to_vec(),
        triangles: vec![],
        masses: masses.to_vec(),
        pinned: pinned.to_vec(),
        stretch: (0..points.len() as u32 - 1).map(|i| [i, i + 1]).collect(),
        shear: vec![],
        grid: None,
    }
}

/// Settings for `method` with frame step `dt`, `substeps` and `iterations`.
pub fn settings(method: Method, dt: f64, substeps: u32, iterations: u32) -> Settings {
    Settings {
        method,
        dt,
        substeps,
        iterations,
        ..Settings::default()
    }
}

/// A solver holding one cloth.
pub fn solver(settings: Settings, forces: Forces, mesh: &ClothMesh, params: ClothParams) -> Solver {
    let mut b = SolverBuilder::new(settings, forces).expect("valid settings");
    b.add_cloth("cloth", mesh, params, 0.0)
        .expect("valid cloth");
    b.build()
}

/// A vertical `n`×`n` 1 m cloth of 1 kg pinned at its two top corners.
pub fn hanging_grid(n: usize) -> ClothMesh {
    GridDesc {
        resolution: (n, n),
        size: (1.0, 1.0),
        center: DVec3::ZERO,
        orientation: Orientation::Vertical,
        mass: Mass::Total(1.0),
        pins: vec![Pin::Corner(Corner::TopLeft), Pin::Corner(Corner::TopRight)],
    }
    .build()
    .expect("valid grid")
}

/// A default grid of `resolution` particles pinned along its top edge.
pub fn top_pinned_grid(resolution: (usize, usize)) -> ClothMesh {
    GridDesc {
        resolution,
        pins: vec![Pin::Edge(Edge::Top)],
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid")
}

/// `material` with its bending in every direction scaled by `scale`.
pub fn bending_scaled(material: &Material, scale: f64) -> Material {
    Material {
        bending: material.bending * scale,
        bending_weft: material.bending_weft * scale,
        bending_bias: material.bending_bias * scale,
        ..*material
    }
}

/// Steps `frames` frames, panicking with the solver's error if it diverges.
pub fn run(s: &mut Solver, frames: usize) {
    for _ in 0..frames {
        s.step().expect("simulation stays finite");
    }
}

/// Lowest y of any particle.
pub fn lowest_y(s: &Solver) -> f64 {
    s.particles()
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min)
}

/// Every interior edge of `triangles` as `[wing_a, wing_b, edge_0, edge_1]`.
pub fn hinges(triangles: &[[u32; 3]]) -> Vec<[u32; 4]> {
    let mut open: HashMap<(u32, u32), (u32, u32, u32)> = HashMap::new();
    let mut out = Vec::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b, opposite) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            match open.remove(&(a.min(b), a.max(b))) {
                Some((wing, e0, e1)) => out.push([wing, opposite, e0, e1]),
                None => {
                    open.insert((a.min(b), a.max(b)), (opposite, a, b));
                }
            }
        }
    }
    out
}
