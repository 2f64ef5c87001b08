//! Spring constants that scale with the cloth: stable defaults for the explicit springs.
//!
//! A fixed spring constant (N/m) is stable only above some particle mass: the highest mode of
//! the springs rings at ω ~ √(Σ 2k / m) ([`crate::StabilityBound`]), so a finer or lighter
//! cloth passes semi-implicit Euler's limit h < 2/ω at the same k. The defaults here keep the
//! proportions of the families and pick their scale from the cloth's own Gershgorin bound so
//! that h·ω = [`DEFAULT_SPRING_HW`] at h = [`DEFAULT_SPRING_SUBSTEP`]: they grow with the
//! particle mass and stay stable at every substep up to 1/600 s, whatever the resolution.

use crate::builder::SolverBuilder;
use crate::cloth::ClothMesh;
use crate::error::BuildError;
use crate::forces::Forces;
use crate::params::{ClothParams, Family};
use crate::settings::Settings;
use crate::topology::Topology;

/// The substep the default spring constants are chosen for (s): dt = 1/60 s in 10 substeps.
pub const DEFAULT_SPRING_SUBSTEP: f64 = 1.0 / 600.0;

/// h·ω the default springs reach at [`DEFAULT_SPRING_SUBSTEP`] (semi-implicit Euler needs < 2;
/// the margin covers spring damping, stretched tethers and springs a user sets by hand).
pub const DEFAULT_SPRING_HW: f64 = 1.0;

/// Relative spring constant of each family (stretch 1); the bending families' are per m² of edge.
fn weight(family: Family, mean_edge: f64) -> f64 {
    match family {
        Family::Stretch | Family::Tether => 1.0,
        Family::Shear => 0.4,
        Family::BendDistance => 0.01,
        Family::BendDihedral | Family::BendIsometric => 0.01 * mean_edge * mean_edge,
    }
}

/// `params` with the spring stiffness of each of `families` replaced by the stable default for
/// `mesh` (see the module documentation); the other families are left as they are. `topology`
/// is the mesh's (`Topology::new(&mesh.triangles)`), built once by a loader for this and the
/// solver's build.
pub fn stable_spring_defaults(
    mesh: &ClothMesh,
    topology: &Topology,
    params: &ClothParams,
    families: &[Family],
) -> Result<ClothParams, BuildError> {
    let mean_edge = if mesh.stretch.is_empty() {
        0.0
    } else {
        mesh.stretch
            .iter()
            .map(|&[a, b]| mesh.positions[a as usize].distance(mesh.positions[b as usize]))
            .sum::<f64>()
            / mesh.stretch.len() as f64
    };
    let mut probe = *params;
    for f in Family::ALL {
        let p = probe.get_mut(f);
        p.spring_damping = 0.0;
        p.spring_stiffness = if families.contains(&f) {
            weight(f, mean_edge)
        } else {
            0.0
        };
    }
    let omega = probe_omega(mesh, topology, probe)?;
    let mut out = *params;
    if omega > 0.0 {
        let scale = (DEFAULT_SPRING_HW / (DEFAULT_SPRING_SUBSTEP * omega)).powi(2);
        for &f in families {
            out.get_mut(f).spring_stiffness = weight(f, mean_edge) * scale;
        }
    }
    Ok(out)
}

/// The Gershgorin bound on ω of `mesh` with `params` alone in a solver.
fn probe_omega(
    mesh: &ClothMesh,
    topology: &Topology,
    params: ClothParams,
) -> Result<f64, BuildError> {
    let mut b = SolverBuilder::new(Settings::default(), Forces::default())?;
    let cloth = b.add_cloth_with_topology("probe", mesh, topology, params, 0.0)?;
    Ok(b.spring_omega(cloth))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GridDesc, Mass};

    fn grid(n: usize, mass: f64) -> ClothMesh {
        GridDesc {
            resolution: (n, n),
            mass: Mass::Total(mass),
            ..GridDesc::default()
        }
        .build()
        .expect("grid")
    }

    const FAMILIES: [Family; 3] = [Family::Stretch, Family::Shear, Family::BendDistance];

    fn defaults(mesh: &ClothMesh) -> ClothParams {
        let topo = Topology::new(&mesh.triangles);
        stable_spring_defaults(mesh, &topo, &ClothParams::default(), &FAMILIES).expect("ok")
    }

    #[test]
    fn defaults_put_the_bound_at_the_chosen_substep_and_grow_with_mass() {
        let mesh = grid(24, 0.5);
        let topo = Topology::new(&mesh.triangles);
        let p =
            stable_spring_defaults(&mesh, &topo, &ClothParams::default(), &FAMILIES).expect("ok");
        let omega = probe_omega(&mesh, &topo, p).expect("ok");
        assert!((DEFAULT_SPRING_SUBSTEP * omega - DEFAULT_SPRING_HW).abs() < 1e-9);
        let heavy = defaults(&grid(24, 2.0));
        let (k, k4) = (
            p.get(Family::Stretch).spring_stiffness,
            heavy.get(Family::Stretch).spring_stiffness,
        );
        assert!((k4 / k - 4.0).abs() < 1e-9, "k ∝ m: {k} vs {k4}");
        // Same mass, 4× the particles: each is 4× lighter, so is each spring.
        let fine = defaults(&grid(47, 0.5));
        let ratio = k / fine.get(Family::Stretch).spring_stiffness;
        assert!((3.5..4.5).contains(&ratio), "{ratio}");
    }
}
