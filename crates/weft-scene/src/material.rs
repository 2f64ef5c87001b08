//! `cloth.<name>.material`: a fabric preset by name, or a table of physical values
//! (`density` in g/m², `stretch` and `shear` in N/m, `bending` in N·m) that may start from a
//! `preset` and override some of its fields. `stretch` and `bending` set every direction;
//! `stretch_warp`, `stretch_weft`, `bending_warp`, `bending_weft` and `bending_bias` set one
//! (warp along the grid's rows, weft along its columns; see `weft_solver::Direction`).

use std::fmt;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use weft_solver::Material;

/// A cloth's material as written.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum MaterialSpec {
    /// `material = "cotton"`.
    Preset(String),
    /// `material = { preset = "cotton", bending = 2e-5 }` or every field given.
    Table(MaterialTable),
}

/// `material = { … }`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialTable {
    /// The preset the other fields override.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Area density (g/m²).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Membrane stretch stiffness (N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch: Option<f64>,
    /// Membrane shear stiffness (N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear: Option<f64>,
    /// Bending stiffness (N·m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<f64>,
    /// Stretch stiffness along the warp (N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch_warp: Option<f64>,
    /// Stretch stiffness along the weft (N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch_weft: Option<f64>,
    /// Bending stiffness of a strip along the warp (N·m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_warp: Option<f64>,
    /// Bending stiffness of a strip along the weft (N·m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_weft: Option<f64>,
    /// Bending stiffness of a strip on the bias (N·m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_bias: Option<f64>,
}

impl<'de> Deserialize<'de> for MaterialSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = MaterialSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a preset name such as \"cotton\" or a table { preset, density, stretch, \
                     shear, bending, stretch_warp, stretch_weft, bending_warp, bending_weft, \
                     bending_bias }",
                )
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<MaterialSpec, E> {
                Ok(MaterialSpec::Preset(v.to_owned()))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<MaterialSpec, A::Error> {
                MaterialTable::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(MaterialSpec::Table)
            }
        }
        d.deserialize_any(V)
    }
}

/// The material a spec names, or `(field, message)` for the first thing wrong with it.
pub fn resolve(spec: &MaterialSpec) -> Result<Material, (String, String)> {
    let unknown = |n: &str| {
        (
            "material".to_owned(),
            format!(
                "unknown material `{n}`: expected one of {}",
                weft_solver::preset_names()
            ),
        )
    };
    let table = match spec {
        MaterialSpec::Preset(n) => return weft_solver::preset(n).ok_or_else(|| unknown(n)),
        MaterialSpec::Table(t) => t,
    };
    let base = match &table.preset {
        Some(n) => Some(weft_solver::preset(n).ok_or_else(|| unknown(n))?),
        None => None,
    };
    let field = |name: &str, v: Option<f64>, from: Option<f64>| match v.or(from) {
        Some(x) if x.is_finite() && x > 0.0 => Ok(x),
        Some(x) => Err((
            format!("material.{name}"),
            format!("must be finite and > 0, got {x}"),
        )),
        None => Err((
            format!("material.{name}"),
            "missing: give it or a `preset` to take it from".to_owned(),
        )),
    };
    // A direction's own key, else the key for every direction, else the preset's value.
    let directed =
        |name: &str, own: Option<f64>, all: (&str, Option<f64>), from: Option<f64>| match (
            own, all.1,
        ) {
            (Some(v), _) => field(name, Some(v), None),
            (None, Some(v)) => field(all.0, Some(v), None),
            (None, None) => field(all.0, None, from),
        };
    let stretch = ("stretch", table.stretch);
    let bending = ("bending", table.bending);
    Ok(Material {
        density: field("density", table.density, base.map(|b| b.density * 1e3))? * 1e-3,
        stretch: directed(
            "stretch_warp",
            table.stretch_warp,
            stretch,
            base.map(|b| b.stretch),
        )?,
        stretch_weft: directed(
            "stretch_weft",
            table.stretch_weft,
            stretch,
            base.map(|b| b.stretch_weft),
        )?,
        shear: field("shear", table.shear, base.map(|b| b.shear))?,
        bending: directed(
            "bending_warp",
            table.bending_warp,
            bending,
            base.map(|b| b.bending),
        )?,
        bending_weft: directed(
            "bending_weft",
            table.bending_weft,
            bending,
            base.map(|b| b.bending_weft),
        )?,
        bending_bias: directed(
            "bending_bias",
            table.bending_bias,
            bending,
            base.map(|b| b.bending_bias),
        )?,
    })
}
