//! The table that sizes a mannequin body: one `[[shape]]` per collision shape, read from
//! TOML (serde), each on a bone of the skeleton.
//!
//! ```toml
//! [[shape]]
//! name = "left forearm"   # optional, defaults to the bone's name
//! bone = "LeftForeArm"    # the joint whose frame carries the shape
//! kind = "round-cone"     # "round-cone" (r0, r1), "capsule" (radius) or "sphere" (radius)
//! r0 = 0.045              # radius at the start (m)
//! r1 = 0.035              # radius at the end (m)
//! to = "LeftHand"         # end at this child joint (default: the bone's only child)
//! start = [0.0, 0.0, 0.0] # start (sphere: centre) in the bone's frame, m (default: origin)
//! end = [0.0, -0.2, 0.0]  # end in the bone's frame, m (instead of `to`)
//! ```

use serde::Deserialize;

use crate::error::BodyError;
use crate::toml_lines::{array_key_lines, line_at, line_in};

/// Kind of a body shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShapeKind {
    /// Two spheres (radii `r0`, `r1`) joined by a tangent cone.
    RoundCone,
    /// A capsule of one `radius`.
    Capsule,
    /// A sphere of `radius` centred at `start`.
    Sphere,
}

/// One `[[shape]]` entry, as written.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeSpec {
    /// Display name (defaults to the bone's).
    #[serde(default)]
    pub name: Option<String>,
    /// The joint whose frame carries the shape.
    pub bone: String,
    /// Round cone, capsule or sphere.
    pub kind: ShapeKind,
    /// Round cone: radius at the start (m).
    #[serde(default)]
    pub r0: Option<f64>,
    /// Round cone: radius at the end (m).
    #[serde(default)]
    pub r1: Option<f64>,
    /// Capsule or sphere radius (m).
    #[serde(default)]
    pub radius: Option<f64>,
    /// Child joint where the shape ends (default: the bone's only child).
    #[serde(default)]
    pub to: Option<String>,
    /// Start point (sphere: centre) in the bone's frame (m); default the joint itself.
    #[serde(default)]
    pub start: Option<[f64; 3]>,
    /// End point in the bone's frame (m), instead of `to`.
    #[serde(default)]
    pub end: Option<[f64; 3]>,
}

/// The file: a list of shapes, plus where each key sits in the text (for errors).
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyTable {
    /// The shapes, in file order.
    #[serde(default, rename = "shape")]
    pub shapes: Vec<ShapeSpec>,
    /// Per shape: 1-based line of each key, and of the `[[shape]]` header under "".
    #[serde(skip)]
    lines: Vec<Vec<(String, usize)>>,
}

/// The default table of the procedural walker ([`crate::walk`]).
const WALKER: &str = include_str!("../bodies/walker.toml");

/// The default table of the CMU motion-capture skeleton (joint names of 01_01.bvh).
const CMU: &str = include_str!("../bodies/cmu.toml");

impl BodyTable {
    /// A table from its shapes (no line information).
    pub fn new(shapes: Vec<ShapeSpec>) -> Self {
        Self {
            shapes,
            lines: Vec::new(),
        }
    }

    /// Parses TOML text; errors carry the line.
    pub fn from_toml(text: &str) -> Result<Self, BodyError> {
        let mut table: BodyTable = toml_edit::de::from_str(text).map_err(|e| BodyError::Toml {
            line: e.span().map(|s| line_at(text, s.start)),
            message: e.message().lines().next().unwrap_or("").trim().to_owned(),
        })?;
        table.lines = array_key_lines(text, "shape");
        Ok(table)
    }

    /// The built-in body of the procedural walker.
    pub fn walker() -> Self {
        Self::from_toml(WALKER).expect("the built-in walker body table parses")
    }

    /// The built-in body of the CMU motion-capture skeleton, for clips read with
    /// [`crate::CMU_SCALE`] (e.g. `assets/characters/cmu_01_01_4s.bvh`).
    pub fn cmu() -> Self {
        Self::from_toml(CMU).expect("the built-in CMU body table parses")
    }

    /// 1-based line of `key` in shape `index` (or of the shape's header), when known.
    pub fn line_of(&self, index: usize, key: &str) -> Option<usize> {
        line_in(&self.lines, index, key)
    }
}
