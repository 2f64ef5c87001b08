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

/// Width of the test strip: ASTM D1388 cuts 25 mm; 2 cm keeps the meshes small (the elastica
/// is per unit width, so the width does not change the angle).
pub const STRIP_WIDTH: f64 = 0.02;

/// A strip clamped level along its first two columns, overhanging along +x in the x–z plane;
/// the clamp's edge (midway between columns 0 and 1) at the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cantilever {
    /// The overhang L from the clamp's edge (midway between columns 0 and 1) to the tip (m).
    pub overhang: f64,
    /// Grid cells from the last clamped column to the tip (≥ 1); the overhang is half a cell
    /// more.
    pub segments: usize,
    /// Grid segments across the strip (≥ 1); the cells are square.
    pub across: usize,
}

impl Cantilever {
    /// The strip of `material` overhanging `lengths` bending lengths c = (B/w)^(1/3) under
    /// gravity `g` (m/s²), meshed with `segments` square cells along the overhang and as many
    /// across as make the width nearest [`STRIP_WIDTH`] (at least 2).
    pub fn of_material(material: &Material, g: f64, lengths: f64, segments: usize) -> Self {
        let c = bending_length(material.bending, material.density * g);
        let overhang = lengths * c;
        let segments = segments.max(1);
        let cell = overhang / (segments as f64 + 0.5);
        let across = ((STRIP_WIDTH / cell).round() as usize).max(2);
        Self {
            overhang,
            segments,
            across,
        }
    }

    /// The cell size (m): the overhang is `segments` + ½ cells (see the module documentation).
    pub fn cell(&self) -> f64 {
        self.overhang / (self.segments as f64 + 0.5)
    }

    /// Particles along x (columns) and across (rows).
    pub fn resolution(&self) -> (usize, usize) {
        (self.segments + 2, self.across + 1)
    }

    /// Size of the grid: the overhang plus the clamped half cell, by the width (m).
    pub fn size(&self) -> (f64, f64) {
        let h = self.cell();
        (self.overhang + 0.5 * h, self.across as f64 * h)
    }

    /// The clamped particles: every row's columns 0 and 1 (`row * columns + column`).
    pub fn clamp(&self) -> Vec<u32> {
        let (cols, rows) = self.resolution();
        (0..rows)
            .flat_map(|r| [0, 1].map(|c| (r * cols + c) as u32))
            .collect()
    }

    /// The strip as a horizontal grid of areal density `density` with its clamp's edge at the
    /// origin (columns 0 and 1 at x = ∓ half a cell).
    pub fn grid(&self, density: f64) -> GridDesc {
        let size = self.size();
        GridDesc {
            resolution: self.resolution(),
            size,
            center: DVec3::new(0.5 * size.0 - 0.5 * self.cell(), 0.0, 0.0),
            orientation: Orientation::Horizontal,
            mass: Mass::Density(density),
            pins: self.clamp().into_iter().map(Pin::Index).collect(),
        }
    }

    /// Angle (rad) below the horizontal of the chord from the clamp's edge (midway between
    /// columns 0 and 1) to the tip (the last column), each taken at its mean over the rows, for
    /// the grid's `positions`.
    pub fn chord_angle(&self, positions: &[DVec3]) -> f64 {
        let (cols, rows) = self.resolution();
        let mean =
            |c: usize| (0..rows).map(|r| positions[r * cols + c]).sum::<DVec3>() / rows as f64;
        let (root, tip) = (0.5 * (mean(0) + mean(1)), mean(cols - 1));
        let d = tip - root;
        (-d.y).atan2(d.x.hypot(d.z))
    }

    /// The exact elastica of this overhang for `material` under gravity `g`, or `None` where
    /// its load is out of the solver's range.
    pub fn elastica(&self, material: &Material, g: f64) -> Option<Elastica> {
        Elastica::of_strip(material.bending, material.density * g, self.overhang)
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
}
