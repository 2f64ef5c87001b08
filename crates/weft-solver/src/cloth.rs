//! Cloth geometry before it enters a solver: a triangle mesh with masses and pins.

use glam::DVec3;

use crate::error::MeshError;
use crate::topology::Topology;

/// How a cloth's mass is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mass {
    /// Total mass of the cloth (kg), spread by lumped triangle area.
    Total(f64),
    /// Areal density (kg/m²), lumped per vertex as a third of each adjacent triangle's area.
    Density(f64),
}

/// A cloth as geometry: rest positions, triangles, per-vertex masses, pins and constraint pairs.
///
/// Built by [`crate::GridDesc::build`] or [`ClothMesh::from_triangles`]; consumed by
/// [`crate::SolverBuilder::add_cloth`].
#[derive(Clone, Debug)]
pub struct ClothMesh {
    /// Rest (and initial) positions (m).
    pub positions: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from the front face.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex masses (kg).
    pub masses: Vec<f64>,
    /// Pinned vertices (given inverse mass 0).
    pub pinned: Vec<u32>,
    /// Stretch pairs: mesh edges (grid lines for grids).
    pub stretch: Vec<[u32; 2]>,
    /// Shear pairs: both diagonals of each quad (grids only; empty for general meshes).
    pub shear: Vec<[u32; 2]>,
    /// Grid resolution `(columns, rows)` when the cloth is a grid.
    pub grid: Option<(usize, usize)>,
}

impl ClothMesh {
    /// Builds a cloth from any triangle mesh; stretch pairs are the mesh edges.
    ///
    /// Rejects empty meshes, out-of-range indices, non-finite vertices, degenerate
    /// (zero-area or repeated-index) triangles and non-manifold edges.
    pub fn from_triangles(
        positions: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        mass: Mass,
        pinned: Vec<u32>,
    ) -> Result<Self, MeshError> {
        validate(&positions, &triangles, mass, &pinned)?;
        let topo = Topology::new(&triangles);
        if let Some(&[a, b]) = topo.non_manifold_edges.first() {
            return Err(MeshError::NonManifoldEdge { a, b });
        }
        let masses = lumped_masses(&positions, &triangles, mass);
        Ok(Self {
            positions,
            triangles,
            masses,
            pinned,
            stretch: topo.edges,
            shear: Vec::new(),
            grid: None,
        })
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether the mesh has no vertex.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.masses.iter().sum()
    }

    /// Total area of the triangles (m²).
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| triangle_area(&self.positions, t))
            .sum()
    }
}

/// Area of triangle `t` (m²).
pub(crate) fn triangle_area(p: &[DVec3], t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| p[i as usize]);
    0.5 * (b - a).cross(c - a).length()
}

/// Lumped vertex masses: each triangle gives a third of its mass to each corner.
pub(crate) fn lumped_masses(p: &[DVec3], triangles: &[[u32; 3]], mass: Mass) -> Vec<f64> {
    let area: f64 = triangles.iter().map(|t| triangle_area(p, t)).sum();
    let density = match mass {
        Mass::Total(m) => m / area,
        Mass::Density(d) => d,
    };
    let mut masses = vec![0.0; p.len()];
    for t in triangles {
        let share = density * triangle_area(p, t) / 3.0;
        for &i in t {
            masses[i as usize] += share;
        }
    }
    masses
}

fn validate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    mass: Mass,
    pinned: &[u32],
) -> Result<(), MeshError> {
    if triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::NonFiniteVertex { vertex: i as u32 });
    }
    let n = positions.len();
    for (k, t) in triangles.iter().enumerate() {
        if let Some(&i) = t.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::IndexOutOfRange {
                triangle: k,
                index: i,
                vertices: n,
            });
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || triangle_area(positions, t) <= 1e-12 {
            return Err(MeshError::DegenerateTriangle { triangle: k });
        }
    }
    if let Some(&i) = pinned.iter().find(|&&i| i as usize >= n) {
        return Err(MeshError::PinOutOfRange {
            index: i,
            vertices: n,
        });
    }
    let value = match mass {
        Mass::Total(m) | Mass::Density(m) => m,
    };
    if !(value.is_finite() && value > 0.0) {
        return Err(MeshError::InvalidMass { value });
    }
    let mut used = vec![false; n];
    triangles
        .iter()
        .flatten()
        .for_each(|&i| used[i as usize] = true);
    if let Some(i) = used.iter().position(|u| !u) {
        return Err(MeshError::UnusedVertex { vertex: i as u32 });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        (
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
            vec![[0, 1, 2], [2, 1, 3]],
        )
    }

    #[test]
    fn mesh_masses_sum_to_total() {
        let (p, t) = quad();
        let m = ClothMesh::from_triangles(p, t, Mass::Total(2.0), vec![]).expect("valid mesh");
        assert!((m.total_mass() - 2.0).abs() < 1e-6);
        assert_eq!(m.stretch.len(), 5);
        assert!((m.area() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bad_meshes_are_rejected_with_the_reason() {
        let (mut p, t) = quad();
        let err = |p: Vec<DVec3>, t: Vec<[u32; 3]>, m| {
            ClothMesh::from_triangles(p, t, m, vec![]).expect_err("must be rejected")
        };
        assert_eq!(err(p.clone(), vec![], Mass::Total(1.0)), MeshError::Empty);
        assert!(matches!(
            err(p.clone(), vec![[0, 1, 9]], Mass::Total(1.0)),
            MeshError::IndexOutOfRange { index: 9, .. }
        ));
        assert!(matches!(
            err(p.clone(), vec![[0, 1, 1], [0, 2, 3]], Mass::Total(1.0)),
            MeshError::DegenerateTriangle { triangle: 0 }
        ));
        assert!(matches!(
            err(p.clone(), t.clone(), Mass::Total(f64::NAN)),
            MeshError::InvalidMass { .. }
        ));
        p[3].x = f64::NAN;
        assert!(matches!(
            err(p, t, Mass::Total(1.0)),
            MeshError::NonFiniteVertex { vertex: 3 }
        ));
    }
}
