//! The cantilever bending test (ASTM D1388) as a grid: a level strip clamped by its first two
//! columns of particles, overhanging by a multiple of the fabric's bending length, and the
//! chord angle measured on it, to compare with the heavy elastica ([`crate::Elastica`]).
//!
//! Where a pinned boundary is clamped: a hinge on a grid line stands for the bending of the
//! cloth within half a cell on either side of it (its fold θ ≈ κ L, the midpoint rule, as the
//! grid lumps each particle's mass over the same half cells). The hinge on the last pinned
//! column (column 1) therefore bends the half cell towards column 0 too, and the strip of
//! pinned columns acts as a clamp whose edge lies midway between columns 0 and 1: the
//! overhang is measured from there, N + ½ cells to the tip, and the discrete strip is then a
//! second-order model of the clamped one. Measured from column 1 instead, every hinge is
//! read half a cell early (a left Riemann sum of the decreasing curvature) and the strip
//! looks softer by O(1/N): 0.69 B, 0.75 B, 0.78 B at 8, 16, 32 segments in a linear solve.

use glam::DVec3;

use crate::cloth::Mass;
use crate::elastica::{Elastica, bending_length};
use crate::grid::{GridDesc, Orientation, Pin};
use crate::material::Material;
use crate::params::Direction;

/// Width of the test strip: ASTM D1388 cuts 25 mm; 2 cm keeps the meshes small (the elastica
/// is per unit width, so the width does not change the angle).
pub const STRIP_WIDTH: f64 = 0.02;

/// A strip clamped level along its first two columns (rows, cut along the weft), overhanging
/// along +x (+z) in the x–z plane; the clamp's edge (midway between the two clamped lines) at
/// the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cantilever {
    /// The overhang L from the clamp's edge (midway between columns 0 and 1) to the tip (m).
    pub overhang: f64,
    /// Grid cells from the last clamped column to the tip (≥ 1); the overhang is half a cell
    /// more.
    pub segments: usize,
    /// Grid segments across the strip (≥ 1); the cells are square.
    pub across: usize,
    /// The material direction the strip runs along: [`Direction::Warp`] along the grid's
    /// rows (+x), [`Direction::Weft`] along its columns (+z). Not the bias.
    pub direction: Direction,
}

impl Cantilever {
    /// The strip of `material` overhanging `lengths` bending lengths c = (B/w)^(1/3) under
    /// gravity `g` (m/s²), meshed with `segments` square cells along the overhang and as many
    /// across as make the width nearest [`STRIP_WIDTH`] (at least 2).
    pub fn of_material(material: &Material, g: f64, lengths: f64, segments: usize) -> Self {
        Self::of_material_along(material, Direction::Warp, g, lengths, segments)
    }

    /// [`Cantilever::of_material`] for a strip cut along `direction` (the bias is taken as
    /// the warp: a grid has no diagonal strip).
    pub fn of_material_along(
        material: &Material,
        direction: Direction,
        g: f64,
        lengths: f64,
        segments: usize,
    ) -> Self {
        let direction = match direction {
            Direction::Weft => Direction::Weft,
            _ => Direction::Warp,
        };
        let bending = material.along(direction).bending;
        let c = bending_length(bending, material.density * g);
        let overhang = lengths * c;
        let segments = segments.max(1);
        let cell = overhang / (segments as f64 + 0.5);
        let across = ((STRIP_WIDTH / cell).round() as usize).max(2);
        Self {
            overhang,
            segments,
            across,
            direction,
        }
    }

    /// Whether the strip runs along the grid's columns.
    fn weft(&self) -> bool {
        self.direction == Direction::Weft
    }

    /// The particle `along` cells from column 0 of the clamp and `across` cells from the
    /// strip's side.
    fn index(&self, along: usize, across: usize) -> usize {
        let (cols, _) = self.resolution();
        if self.weft() {
            along * cols + across
        } else {
            across * cols + along
        }
    }

    /// The cell size (m): the overhang is `segments` + ½ cells (see the module documentation).
    pub fn cell(&self) -> f64 {
        self.overhang / (self.segments as f64 + 0.5)
    }

    /// The grid's (columns, rows): along × across the strip, or across × along for a weft
    /// strip.
    pub fn resolution(&self) -> (usize, usize) {
        let (along, across) = (self.segments + 2, self.across + 1);
        if self.weft() {
            (across, along)
        } else {
            (along, across)
        }
    }

    /// Size of the grid, in the order of [`Cantilever::resolution`]: the overhang plus the
    /// clamped half cell, and the width (m).
    pub fn size(&self) -> (f64, f64) {
        let h = self.cell();
        let (along, across) = (self.overhang + 0.5 * h, self.across as f64 * h);
        if self.weft() {
            (across, along)
        } else {
            (along, across)
        }
    }

    /// The clamped particles: the first two lines of particles across the strip (columns 0
    /// and 1, or rows 0 and 1 of a weft strip; index `row * columns + column`).
    pub fn clamp(&self) -> Vec<u32> {
        (0..=self.across)
            .flat_map(|r| [0, 1].map(|c| self.index(c, r) as u32))
            .collect()
    }

    /// The strip as a horizontal grid of areal density `density` with its clamp's edge at the
    /// origin (the clamped lines at ∓ half a cell along the strip).
    pub fn grid(&self, density: f64) -> GridDesc {
        let size = self.size();
        let along = if self.weft() { size.1 } else { size.0 };
        let offset = 0.5 * along - 0.5 * self.cell();
        GridDesc {
            resolution: self.resolution(),
            size,
            center: if self.weft() {
                DVec3::new(0.0, 0.0, offset)
            } else {
                DVec3::new(offset, 0.0, 0.0)
            },
            orientation: Orientation::Horizontal,
            mass: Mass::Density(density),
            pins: self.clamp().into_iter().map(Pin::Index).collect(),
        }
    }

    /// Angle (rad) below the horizontal of the chord from the clamp's edge (midway between
    /// columns 0 and 1) to the tip (the last column), each taken at its mean over the rows, for
    /// the grid's `positions`.
    pub fn chord_angle(&self, positions: &[DVec3]) -> f64 {
        let n = self.across + 1;
        let mean = |c: usize| (0..n).map(|r| positions[self.index(c, r)]).sum::<DVec3>() / n as f64;
        let (root, tip) = (0.5 * (mean(0) + mean(1)), mean(self.segments + 1));
        let d = tip - root;
        (-d.y).atan2(d.x.hypot(d.z))
    }

    /// The exact elastica of this overhang for `material` under gravity `g`, or `None` where
    /// its load is out of the solver's range.
    pub fn elastica(&self, material: &Material, g: f64) -> Option<Elastica> {
        let bending = material.along(self.direction).bending;
        Elastica::of_strip(bending, material.density * g, self.overhang)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_strip_overhangs_by_its_length_from_a_level_clamp() {
        let m = crate::preset("cotton").expect("preset");
        let t = Cantilever::of_material(&m, 9.81, 2.0, 16);
        let c = (m.bending / (m.density * 9.81)).cbrt();
        assert!((t.overhang - 2.0 * c).abs() < 1e-15);
        let mesh = t.grid(m.density).build().expect("grid");
        let (cols, _) = t.resolution();
        // The clamp's edge at x = 0 midway between columns 0 and 1, the tip at x = L, all
        // level: chord angle 0.
        assert!((mesh.positions[0].x + mesh.positions[1].x).abs() < 1e-12);
        assert!((mesh.positions[1].x - 0.5 * t.cell()).abs() < 1e-12);
        assert!((mesh.positions[cols - 1].x - t.overhang).abs() < 1e-12);
        assert_eq!(t.chord_angle(&mesh.positions), 0.0);
        assert_eq!(mesh.pinned.len(), 2 * t.resolution().1);
        let e = t.elastica(&m, 9.81).expect("in range");
        assert!((e.chord_angle().to_degrees() - 41.49).abs() < 0.05);
    }

    #[test]
    fn a_weft_strip_runs_along_the_columns_with_the_wefts_bending_length() {
        let m = crate::preset("11oz-black-denim").expect("preset");
        let (warp, weft) = [Direction::Warp, Direction::Weft]
            .map(|d| Cantilever::of_material_along(&m, d, 9.81, 2.0, 8))
            .into();
        let c = |b: f64| (b / (m.density * 9.81)).cbrt();
        assert!((warp.overhang - 2.0 * c(m.bending)).abs() < 1e-15);
        assert!((weft.overhang - 2.0 * c(m.bending_weft)).abs() < 1e-15);
        let mesh = weft.grid(m.density).build().expect("grid");
        let (cols, rows) = weft.resolution();
        assert_eq!((cols, rows), (weft.across + 1, 10));
        // Rows 0 and 1 clamped, at z = ∓ half a cell; the tip row at z = L; level.
        assert!((mesh.positions[0].z + mesh.positions[cols].z).abs() < 1e-12);
        assert!((mesh.positions[(rows - 1) * cols].z - weft.overhang).abs() < 1e-12);
        assert_eq!(weft.chord_angle(&mesh.positions), 0.0);
        let mut pins = weft.clamp();
        pins.sort_unstable();
        assert_eq!(pins, (0..2 * cols as u32).collect::<Vec<_>>());
        // Tilting the tip row down by the elastica's chord reads that angle back.
        let mut bent = mesh.positions.clone();
        let tip = (rows - 1) * cols;
        for p in &mut bent[tip..tip + cols] {
            p.y = -p.z * 0.5f64.atan().tan();
        }
        assert!((weft.chord_angle(&bent) - 0.5f64.atan()).abs() < 1e-12);
    }
}
