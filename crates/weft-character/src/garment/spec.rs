//! The garment file: flat panels (2-D outlines in metres), their placement around the body,
//! and seams joining ranges of panel edges.
//!
//! ```toml
//! edge_length = 0.02        # target triangle edge length (m)
//! area_density = 0.15       # kg/m² (default 0.2)
//!
//! [[panel]]
//! name = "front"
//! outline = [[-0.2, 0.0], [0.2, 0.0], [0.2, 0.5], [-0.2, 0.5]]  # corners, either winding
//! position = [0.0, 0.5, 0.15]   # where the panel's origin goes (m)
//! rotation = [0.0, 0.0, 0.0]    # degrees about x, then y, then z (R = R_z R_y R_x)
//!
//! [[seam]]
//! a = { panel = "front", edges = [1, 1] }   # outline edges first..=last (edge k: corner k → k+1)
//! b = { panel = "back", edges = [3, 3] }
//! flip = true               # pair a's first vertex with b's last (default false)
//! ```

use serde::Deserialize;

use crate::toml_lines::{array_key_lines, line_at, line_in};

use super::GarmentError;

fn default_density() -> f64 {
    0.2
}

/// A garment file.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentSpec {
    /// Target edge length of the triangulation (m).
    pub edge_length: f64,
    /// Area density of the fabric (kg/m²).
    #[serde(default = "default_density")]
    pub area_density: f64,
    /// The panels.
    #[serde(rename = "panel")]
    pub panels: Vec<PanelSpec>,
    /// The seams.
    #[serde(default, rename = "seam")]
    pub seams: Vec<SeamSpec>,
    #[serde(skip)]
    panel_lines: Vec<Vec<(String, usize)>>,
    #[serde(skip)]
    seam_lines: Vec<Vec<(String, usize)>>,
    #[serde(skip)]
    top_lines: Vec<(String, usize)>,
}

/// One flat panel.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelSpec {
    /// Name, unique in the garment.
    pub name: String,
    /// Corners of the outline polygon (m), in order, either winding.
    pub outline: Vec<[f64; 2]>,
    /// Position of the panel's origin around the body (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Rotation of the panel (degrees about x, then y, then z); the panel's plane is local
    /// z = 0 and its front faces local +z.
    #[serde(default)]
    pub rotation: [f64; 3],
}

/// One seam: two runs of panel edges sewn together vertex by vertex.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamSpec {
    /// First side.
    pub a: SeamSide,
    /// Second side.
    pub b: SeamSide,
    /// Walk side b backwards (pair a's first vertex with b's last).
    #[serde(default)]
    pub flip: bool,
}

/// A run of consecutive outline edges of one panel.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamSide {
    /// The panel's name.
    pub panel: String,
    /// First and last edge of the run, inclusive, forward along the outline (wrapping past
    /// the last corner); edge k joins corner k to corner k + 1.
    pub edges: [usize; 2],
}

impl GarmentSpec {
    /// A garment from its parts (no line information).
    pub fn new(
        edge_length: f64,
        area_density: f64,
        panels: Vec<PanelSpec>,
        seams: Vec<SeamSpec>,
    ) -> Self {
        Self {
            edge_length,
            area_density,
            panels,
            seams,
            panel_lines: Vec::new(),
            seam_lines: Vec::new(),
            top_lines: Vec::new(),
        }
    }

    /// Parses TOML text; errors carry the line.
    pub fn from_toml(text: &str) -> Result<Self, GarmentError> {
        let mut spec: GarmentSpec =
            toml_edit::de::from_str(text).map_err(|e| GarmentError::Toml {
                line: e.span().map(|s| line_at(text, s.start)),
                message: e.message().lines().next().unwrap_or("").trim().to_owned(),
            })?;
        spec.panel_lines = array_key_lines(text, "panel");
        spec.seam_lines = array_key_lines(text, "seam");
        if let Ok(doc) = toml_edit::Document::parse(text.to_owned()) {
            let t = doc.as_table();
            spec.top_lines = ["edge_length", "area_density"]
                .iter()
                .filter_map(|k| {
                    let span = t.key(k).and_then(|key| key.span())?;
                    Some(((*k).to_owned(), line_at(text, span.start)))
                })
                .collect();
        }
        Ok(spec)
    }

    /// Line of a key of panel `index`.
    pub(crate) fn panel_line(&self, index: usize, key: &str) -> Option<usize> {
        line_in(&self.panel_lines, index, key)
    }

    /// Line of a key of seam `index`.
    pub(crate) fn seam_line(&self, index: usize, key: &str) -> Option<usize> {
        line_in(&self.seam_lines, index, key)
    }

    /// Line of a top-level key.
    pub(crate) fn top_line(&self, key: &str) -> Option<usize> {
        self.top_lines
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, l)| *l)
    }
}
