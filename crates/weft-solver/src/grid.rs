//! Rectangular grid cloths: resolution, size, placement, mass and pins.

use glam::DVec3;

use crate::cloth::{ClothMesh, Mass, lumped_masses};
use crate::error::MeshError;

/// The plane a grid cloth lies in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Orientation {
    /// In the x–y plane, facing +z; row 0 is the top edge (largest y).
    #[default]
    Vertical,
    /// In the x–z plane, facing +y; row 0 is the far edge (smallest z).
    Horizontal,
}

/// A corner of a grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Corner {
    /// Row 0, column 0.
    TopLeft,
    /// Row 0, last column.
    TopRight,
    /// Last row, column 0.
    BottomLeft,
    /// Last row, last column.
    BottomRight,
}

/// An edge of a grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// Row 0.
    Top,
    /// The last row.
    Bottom,
    /// Column 0.
    Left,
    /// The last column.
    Right,
}

/// Which grid particles are pinned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pin {
    /// One corner.
    Corner(Corner),
    /// A whole edge.
    Edge(Edge),
    /// A particle by index (`row * columns + column`).
    Index(u32),
}

/// Description of a rectangular grid cloth.
#[derive(Clone, Debug, PartialEq)]
pub struct GridDesc {
    /// Particles along x (columns) and along the other axis (rows); each at least 2.
    pub resolution: (usize, usize),
    /// Width (along x) and height (along the other axis) in metres.
    pub size: (f64, f64),
    /// Centre of the cloth (m).
    pub center: DVec3,
    /// Plane of the cloth.
    pub orientation: Orientation,
    /// Total mass or areal density.
    pub mass: Mass,
    /// Pinned particles.
    pub pins: Vec<Pin>,
}

impl Default for GridDesc {
    fn default() -> Self {
        Self {
            resolution: (20, 20),
            size: (1.0, 1.0),
            center: DVec3::ZERO,
            orientation: Orientation::Vertical,
            mass: Mass::Total(1.0),
            pins: vec![Pin::Corner(Corner::TopLeft), Pin::Corner(Corner::TopRight)],
        }
    }
}

impl GridDesc {
    /// Index of the particle at `column`, `row`.
    pub fn index(&self, column: usize, row: usize) -> u32 {
        (row * self.resolution.0 + column) as u32
    }

    /// Builds the grid: alternating-diagonal triangles, grid-line stretch pairs, quad-diagonal shear pairs.
    pub fn build(&self) -> Result<ClothMesh, MeshError> {
        let (nx, ny) = self.resolution;
        if nx < 2 || ny < 2 {
            return Err(MeshError::GridTooSmall {
                columns: nx,
                rows: ny,
            });
        }
        let (w, h) = self.size;
        if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0) {
            return Err(MeshError::InvalidSize {
                width: w,
                height: h,
            });
        }
        if !self.center.is_finite() {
            return Err(MeshError::NonFiniteVertex { vertex: 0 });
        }
        let (dx, dy) = (w / (nx - 1) as f64, h / (ny - 1) as f64);
        let mut positions = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let u = -0.5 * w + i as f64 * dx;
                let v = 0.5 * h - j as f64 * dy;
                positions.push(
                    self.center
                        + match self.orientation {
                            Orientation::Vertical => DVec3::new(u, v, 0.0),
                            Orientation::Horizontal => DVec3::new(u, 0.0, -v),
                        },
                );
            }
        }
        let mut triangles = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
        let mut stretch = Vec::with_capacity(2 * nx * ny);
        let mut shear = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
        for j in 0..ny {
            for i in 0..nx {
                let a = self.index(i, j);
                if i + 1 < nx {
                    stretch.push([a, self.index(i + 1, j)]);
                }
                if j + 1 < ny {
                    stretch.push([a, self.index(i, j + 1)]);
                }
                if i + 1 < nx && j + 1 < ny {
                    let (b, c, d) = (
                        self.index(i + 1, j),
                        self.index(i, j + 1),
                        self.index(i + 1, j + 1),
                    );
                    if (i + j) % 2 == 0 {
                        triangles.extend([[a, c, d], [a, d, b]]);
                    } else {
                        triangles.extend([[a, c, b], [b, c, d]]);
                    }
                    shear.extend([[a, d], [b, c]]);
                }
            }
        }
        let mass_value = match self.mass {
            Mass::Total(m) | Mass::Density(m) => m,
        };
        if !(mass_value.is_finite() && mass_value > 0.0) {
            return Err(MeshError::InvalidMass { value: mass_value });
        }
        let masses = lumped_masses(&positions, &triangles, self.mass);
        let pinned = self.pin_indices(&self.pins)?;
        Ok(ClothMesh {
            positions,
            triangles,
            masses,
            pinned,
            stretch,
            shear,
            grid: Some((nx, ny)),
        })
    }

    /// The particles `pins` name on this grid, ascending, each once.
    pub fn pin_indices(&self, pins: &[Pin]) -> Result<Vec<u32>, MeshError> {
        let (nx, ny) = self.resolution;
        let mut pinned = Vec::new();
        for pin in pins {
            match *pin {
                Pin::Corner(c) => pinned.push(match c {
                    Corner::TopLeft => self.index(0, 0),
                    Corner::TopRight => self.index(nx - 1, 0),
                    Corner::BottomLeft => self.index(0, ny - 1),
                    Corner::BottomRight => self.index(nx - 1, ny - 1),
                }),
                Pin::Edge(Edge::Top) => pinned.extend((0..nx).map(|i| self.index(i, 0))),
                Pin::Edge(Edge::Bottom) => pinned.extend((0..nx).map(|i| self.index(i, ny - 1))),
                Pin::Edge(Edge::Left) => pinned.extend((0..ny).map(|j| self.index(0, j))),
                Pin::Edge(Edge::Right) => pinned.extend((0..ny).map(|j| self.index(nx - 1, j))),
                Pin::Index(i) if i as usize >= nx * ny => {
                    return Err(MeshError::PinOutOfRange {
                        index: i,
                        vertices: nx * ny,
                    });
                }
                Pin::Index(i) => pinned.push(i),
            }
        }
        pinned.sort_unstable();
        pinned.dedup();
        Ok(pinned)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_counts_match_the_reference_workload() {
        let n = 32;
        let g = GridDesc {
            resolution: (n, n),
            pins: vec![Pin::Edge(Edge::Top)],
            ..GridDesc::default()
        }
        .build()
        .expect("valid grid");
        assert_eq!(g.len(), n * n);
        assert_eq!(g.stretch.len(), 2 * n * (n - 1));
        assert_eq!(g.shear.len(), 2 * (n - 1) * (n - 1));
        assert_eq!(g.stretch.len() + g.shear.len(), 3906);
        assert_eq!(g.pinned.len(), n);
        assert!((g.total_mass() - 1.0).abs() < 1e-4);
    }

    #[test]
    fn triangles_face_the_stated_normal() {
        for (o, normal) in [
            (Orientation::Vertical, DVec3::Z),
            (Orientation::Horizontal, DVec3::Y),
        ] {
            let g = GridDesc {
                resolution: (4, 3),
                orientation: o,
                ..GridDesc::default()
            }
            .build()
            .expect("valid grid");
            for t in &g.triangles {
                let [a, b, c] = t.map(|i| g.positions[i as usize]);
                assert!(
                    (b - a).cross(c - a).normalize().dot(normal) > 0.999,
                    "{o:?} {t:?}"
                );
            }
        }
    }

    #[test]
    fn corners_pin_the_right_particles() {
        let g = GridDesc {
            resolution: (5, 4),
            pins: vec![
                Pin::Corner(Corner::TopRight),
                Pin::Corner(Corner::BottomLeft),
            ],
            ..GridDesc::default()
        }
        .build()
        .expect("valid grid");
        assert_eq!(g.pinned, vec![4, 15]);
        assert!(g.positions[4].x > 0.0 && g.positions[4].y > 0.0);
        assert!(g.positions[15].x < 0.0 && g.positions[15].y < 0.0);
    }

    #[test]
    fn bad_grids_are_rejected() {
        let bad = |d: GridDesc| d.build().expect_err("must be rejected");
        assert!(matches!(
            bad(GridDesc {
                resolution: (1, 5),
                ..GridDesc::default()
            }),
            MeshError::GridTooSmall { .. }
        ));
        assert!(matches!(
            bad(GridDesc {
                size: (f64::NAN, 1.0),
                ..GridDesc::default()
            }),
            MeshError::InvalidSize { .. }
        ));
        assert!(matches!(
            bad(GridDesc {
                pins: vec![Pin::Index(400)],
                ..GridDesc::default()
            }),
            MeshError::PinOutOfRange { index: 400, .. }
        ));
    }
}
