//! `[character]` and a garment's `attach` entries.

use serde::{Deserialize, Serialize};

use super::collider::{default_dynamic_friction, default_static_friction};
use super::exact;

/// How a clip continues past its end: `loop` or `clamp`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WrapName {
    /// Repeat the clip.
    #[default]
    Loop,
    /// Hold the last frame.
    Clamp,
}

impl From<WrapName> for weft_character::Wrap {
    fn from(w: WrapName) -> Self {
        match w {
            WrapName::Loop => weft_character::Wrap::Loop,
            WrapName::Clamp => weft_character::Wrap::Clamp,
        }
    }
}

/// `[character]`: the skeleton and clip (the built-in `walker` or a BVH file), the body table
/// (built-in `walker` or `cmu`, or a file) and how the clip plays; or, with `model`, a skinned
/// glTF/GLB character whose deforming mesh is the body.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CharacterSection {
    /// `walker` (the procedural walk cycle) or a BVH file, relative to the scene.
    #[serde(default = "default_walker")]
    pub skeleton: String,
    /// The file's length unit in metres (a BVH file or a `model`; e.g. 0.01 for centimetres).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// A skinned glTF (`.gltf`) or GLB (`.glb`) file, relative to the scene: its skinned mesh
    /// is the body (instead of `skeleton` and `body`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// The `model`'s animation to play: its name or index (default: the first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<AnimationKey>,
    /// Where the `model`'s origin goes (m, after `scale` and `rotation_deg`).
    #[serde(
        default,
        deserialize_with = "exact::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub position: Option<[f64; 3]>,
    /// The `model`'s rotation as XYZ Euler angles in degrees (e.g. `[-90, 0, 0]` for a z-up
    /// file), applied after `scale`.
    #[serde(
        default,
        deserialize_with = "exact::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub rotation_deg: Option<[f64; 3]>,
    /// `walker`, `cmu` (built-in body tables) or a body-table TOML file.
    #[serde(default = "default_walker")]
    pub body: String,
    /// `loop` or `clamp`.
    #[serde(default)]
    pub wrap: WrapName,
    /// Static friction between the body and cloth.
    #[serde(default = "default_static_friction")]
    pub static_friction: f64,
    /// Dynamic friction between the body and cloth.
    #[serde(default = "default_dynamic_friction")]
    pub dynamic_friction: f64,
}

/// A glTF animation, by name or by index.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(
    untagged,
    expecting = "an animation name (a string) or index (an integer)"
)]
pub enum AnimationKey {
    /// The animation's index in the file.
    Index(i64),
    /// The animation's name.
    Name(String),
}

fn default_walker() -> String {
    "walker".into()
}

/// One attachment of a garment cloth: the vertices along outline edges of a panel, pinned to
/// a bone of the `[character]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AttachSection {
    /// The bone (joint name in the skeleton).
    pub bone: String,
    /// The panel (name in the garment file).
    pub panel: String,
    /// First and last outline edge, inclusive (as in the garment's seams).
    #[serde(deserialize_with = "exact::array")]
    pub edges: [i64; 2],
    /// The part of that run to attach, as fractions of its vertices from its first corner
    /// to its last (default `[0, 1]`: all of it).
    #[serde(
        default,
        deserialize_with = "exact::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub span: Option<[f64; 2]>,
}
