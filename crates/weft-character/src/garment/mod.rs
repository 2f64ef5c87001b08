//! Garments sewn from flat panels: outlines triangulated to a chosen edge length, placed
//! around the body, and seams given as matched vertex pairs, as a weft-solver [`ClothMesh`].
//!
//! Its modules:
//!
//! - `outline`: panel outlines sampled to the target edge length, a seam's two sides alike.
//! - `sew`: building a garment: panels triangulated, placed around the body, merged and seamed.
//! - `spec`: the garment file: flat panels, their placement around the body, and their seams.
//! - `triangulate`: a sampled outline triangulated and refined to the target edge length.

mod outline;
mod sew;
mod spec;
mod triangulate;

use std::ops::Range;

use glam::DVec2;
use thiserror::Error;
use weft_solver::{ClothMesh, MeshError};

pub use sew::{MAX_COORDINATE, MAX_CORNERS, MAX_GARMENT_VERTICES, MIN_EDGE_LENGTH, build_garment};
pub use spec::{GarmentSpec, PanelSpec, SeamSide, SeamSpec};

/// A garment ready for a solver: one mesh of all panels (unsewn) and the seams to close.
#[derive(Clone, Debug)]
pub struct Garment {
    /// All panels' vertices and triangles, placed around the body; area-density masses.
    pub mesh: ClothMesh,
    /// Each panel's part of the mesh.
    pub panels: Vec<PanelMesh>,
    /// Vertex pairs to sew together (mesh indices), seam after seam, each seam in order
    /// along its side a.
    pub seam_pairs: Vec<[u32; 2]>,
    /// For each seam of the file, its range in `seam_pairs`.
    pub seams: Vec<Range<usize>>,
}

/// One panel's part of a garment mesh.
#[derive(Clone, Debug)]
pub struct PanelMesh {
    /// The panel's name.
    pub name: String,
    /// Its vertices in the mesh; the outline's samples come first, in outline order.
    pub vertices: Range<u32>,
    /// How many of them lie on the outline.
    pub boundary: usize,
    /// Its triangles in the mesh.
    pub triangles: Range<usize>,
    /// Flat (2-D) rest coordinates of its vertices (m), in `vertices` order.
    pub flat: Vec<DVec2>,
    /// For each outline edge, the index (among the boundary samples) of its first sample.
    pub edge_starts: Vec<usize>,
}

impl PanelMesh {
    /// The mesh vertices along outline edges `first..=last` (forward, wrapping past the last
    /// corner), from the run's first corner to its last inclusive; `None` if an edge does not
    /// exist.
    pub fn edge_run(&self, first: usize, last: usize) -> Option<Vec<u32>> {
        let m = self.edge_starts.len();
        if first >= m || last >= m {
            return None;
        }
        let mut out = Vec::new();
        let mut k = first;
        loop {
            let end = if k + 1 == m {
                self.boundary
            } else {
                self.edge_starts[k + 1]
            };
            out.extend((self.edge_starts[k]..end).map(|j| self.vertices.start + j as u32));
            if k == last {
                out.push(self.vertices.start + (end % self.boundary) as u32);
                return Some(out);
            }
            k = (k + 1) % m;
        }
    }
}

impl Garment {
    /// The panel called `name`.
    pub fn panel(&self, name: &str) -> Option<&PanelMesh> {
        self.panels.iter().find(|p| p.name == name)
    }
}

/// A garment that cannot be built; names the line and key where it can.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum GarmentError {
    /// The text is not valid TOML or not a garment.
    #[error("{}{message}", at(.line))]
    Toml {
        /// 1-based line, when known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A value that does not make a garment.
    #[error("{}{place}, key `{key}`: {message}", at(.line))]
    Key {
        /// 1-based line, when known.
        line: Option<usize>,
        /// Which panel or seam (e.g. "panel 2 (`back`)").
        place: String,
        /// The key at fault.
        key: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The panels do not make a valid cloth mesh.
    #[error("the garment's mesh: {0}")]
    Mesh(#[from] MeshError),
}

fn at(line: &Option<usize>) -> String {
    line.map(|l| format!("line {l}: ")).unwrap_or_default()
}
