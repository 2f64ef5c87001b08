//! The scene file as written: serde structures mirroring the TOML, before validation.
//!
//! Every table denies unknown keys, so a typo is an error rather than a silently ignored value.
//!
//! Its modules:
//!
//! - `character`: `[character]` and a garment's `attach` entries.
//! - `cloth`: `[cloth.<name>]`: its own keys and the keys of each constraint family.
//! - `collider`: `[[collider]]` and the parts of a compound.
//! - `exact`: fixed-length arrays read exactly, so that a short array is an error.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

mod character;
mod cloth;
mod collider;
mod exact;

pub use character::{AnimationKey, AttachSection, CharacterSection, WrapName};
pub use cloth::{
    ClothSection, DEFAULT_RESOLUTION, DEFAULT_SIZE, DEFAULT_THICKNESS, OrientationName, PinSpec,
    RESOLUTION_RANGE,
};
pub use collider::{ColliderSection, PartSection, ShapeKind};

/// A whole scene file.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[sim]`: method, time step, substeps, iterations, gravity, damping.
    #[serde(default)]
    pub sim: SimSection,
    /// `[wind]`: uniform wind and optional aerodynamics.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindSection>,
    /// `[cloth.<name>]`: one or more named cloths (sorted by name).
    #[serde(default)]
    pub cloth: BTreeMap<String, ClothSection>,
    /// `[[collider]]`: obstacles.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub collider: Vec<ColliderSection>,
    /// `[self_collision]`: particle–particle collision among cloths.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub self_collision: Option<SelfCollisionSection>,
    /// `[character]`: an animated skeleton and its body, which garments are attached to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character: Option<CharacterSection>,
}

/// A method name: `xpbd`, `pbd`, `mass-spring` or `implicit-mass-spring` (alias `implicit`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MethodName {
    /// XPBD.
    #[default]
    Xpbd,
    /// PBD.
    Pbd,
    /// Mass-spring.
    MassSpring,
    /// Implicit (backward Euler) mass-spring.
    #[serde(alias = "implicit")]
    ImplicitMassSpring,
}

impl From<MethodName> for weft_solver::Method {
    fn from(m: MethodName) -> Self {
        match m {
            MethodName::Xpbd => weft_solver::Method::Xpbd,
            MethodName::Pbd => weft_solver::Method::Pbd,
            MethodName::MassSpring => weft_solver::Method::MassSpring,
            MethodName::ImplicitMassSpring => weft_solver::Method::ImplicitMassSpring,
        }
    }
}

/// A time in seconds, written as a number (`0.0166`) or a fraction (`"1/60"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seconds(pub f64);

impl Serialize for Seconds {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.0)
    }
}

impl<'de> Deserialize<'de> for Seconds {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Seconds;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number of seconds or a fraction such as \"1/60\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Seconds, E> {
                Ok(Seconds(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Seconds, E> {
                Ok(Seconds(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Seconds, E> {
                Ok(Seconds(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Seconds, E> {
                let parse = |s: &str| s.trim().parse::<f64>().ok();
                let value = match v.split_once('/') {
                    Some((a, b)) => parse(a).zip(parse(b)).map(|(a, b)| a / b),
                    None => parse(v),
                };
                value.map(Seconds).ok_or_else(|| {
                    E::custom(format!(
                        "expected a number of seconds or a fraction such as \"1/60\", got \"{v}\""
                    ))
                })
            }
        }
        d.deserialize_any(V)
    }
}

/// `[sim]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SimSection {
    /// Default method of every cloth: `xpbd`, `pbd`, `mass-spring` or `implicit-mass-spring`.
    #[serde(default)]
    pub method: MethodName,
    /// Frame time step (s); a number or `"1/60"`.
    #[serde(default = "default_dt")]
    pub dt: Seconds,
    /// Substeps per frame.
    #[serde(default = "default_substeps")]
    pub substeps: i64,
    /// Constraint sweeps per substep.
    #[serde(default = "default_iterations")]
    pub iterations: i64,
    /// Gravitational acceleration (m/s²).
    #[serde(default = "default_gravity", deserialize_with = "exact::array")]
    pub gravity: [f64; 3],
    /// Global velocity damping rate (1/s).
    #[serde(default)]
    pub damping: f64,
    /// A particle farther than this from the origin (m) means divergence.
    #[serde(default = "default_bound")]
    pub divergence_bound: f64,
    /// Implicit mass-spring: conjugate-gradient iterations at most per substep.
    #[serde(default = "default_cg_max_iterations")]
    pub cg_max_iterations: i64,
    /// Implicit mass-spring: relative residual ‖b − A Δv‖ / ‖b‖ its linear solve stops at.
    #[serde(default = "default_cg_tolerance")]
    pub cg_tolerance: f64,
}

fn default_dt() -> Seconds {
    Seconds(weft_solver::Settings::default().dt)
}
fn default_substeps() -> i64 {
    weft_solver::Settings::default().substeps.into()
}
fn default_iterations() -> i64 {
    weft_solver::Settings::default().iterations.into()
}
fn default_gravity() -> [f64; 3] {
    weft_solver::Forces::default().gravity.to_array()
}
fn default_bound() -> f64 {
    weft_solver::Settings::default().divergence_bound
}
fn default_cg_max_iterations() -> i64 {
    weft_solver::DEFAULT_CG_MAX_ITERATIONS.into()
}
fn default_cg_tolerance() -> f64 {
    weft_solver::DEFAULT_CG_TOLERANCE
}

impl Default for SimSection {
    fn default() -> Self {
        Self {
            method: MethodName::Xpbd,
            dt: default_dt(),
            substeps: default_substeps(),
            iterations: default_iterations(),
            gravity: default_gravity(),
            damping: 0.0,
            divergence_bound: default_bound(),
            cg_max_iterations: default_cg_max_iterations(),
            cg_tolerance: default_cg_tolerance(),
        }
    }
}

/// `[wind]`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WindSection {
    /// Wind velocity (m/s).
    #[serde(default, deserialize_with = "exact::array")]
    pub velocity: [f64; 3],
    /// Uniform drag rate (1/s).
    #[serde(default)]
    pub drag: f64,
    /// `[wind.aero]`: per-triangle drag and lift; present means on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aero: Option<AeroSection>,
}

/// `[wind.aero]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AeroSection {
    /// Air density (kg/m³).
    #[serde(default = "default_air_density")]
    pub air_density: f64,
    /// Drag coefficient.
    #[serde(default = "default_drag_coefficient")]
    pub drag_coefficient: f64,
    /// Lift coefficient.
    #[serde(default = "default_lift_coefficient")]
    pub lift_coefficient: f64,
}

fn default_air_density() -> f64 {
    weft_solver::Aero::default().air_density
}
fn default_drag_coefficient() -> f64 {
    weft_solver::Aero::default().drag_coefficient
}
fn default_lift_coefficient() -> f64 {
    weft_solver::Aero::default().lift_coefficient
}

/// A prescribed motion (for a cloth's pins or a collider).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum MotionSpec {
    /// Does not move.
    Static,
    /// Constant velocity (m/s).
    Linear {
        /// Velocity (m/s).
        #[serde(deserialize_with = "exact::array")]
        velocity: [f64; 3],
    },
    /// x₀ + A sin(2π f t).
    Oscillate {
        /// Amplitude (m).
        #[serde(deserialize_with = "exact::array")]
        amplitude: [f64; 3],
        /// Frequency (Hz).
        frequency: f64,
    },
    /// Rotation about an axis through a pivot.
    Rotate {
        /// A point on the axis (m).
        #[serde(deserialize_with = "exact::array")]
        pivot: [f64; 3],
        /// Axis direction.
        #[serde(deserialize_with = "exact::array")]
        axis: [f64; 3],
        /// Angular velocity (rad/s).
        angular_velocity: f64,
    },
}

/// `[self_collision]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SelfCollisionSection {
    /// On or off.
    #[serde(default = "yes")]
    pub enabled: bool,
    /// Cloths that collide with themselves and each other (default: all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cloths: Option<Vec<String>>,
    /// Static friction between particles.
    #[serde(default = "default_self_static")]
    pub static_friction: f64,
    /// Dynamic friction between particles.
    #[serde(default = "default_self_dynamic")]
    pub dynamic_friction: f64,
    /// Largest per-substep displacement as a fraction of thickness.
    #[serde(default = "default_max_displacement")]
    pub max_displacement: f64,
    /// Extra candidate search radius as a fraction of thickness (the starting one, when
    /// `adaptive_search_margin` is on).
    #[serde(default = "default_search_margin")]
    pub search_margin: f64,
    /// Whether the search margin follows the cloth's motion (changes cost only).
    #[serde(default = "yes")]
    pub adaptive_search_margin: bool,
    /// What keeps the cloths apart: `particles` or `mesh`.
    #[serde(default)]
    pub contact: ContactKind,
}

/// `[self_collision] contact`: what keeps cloth apart from cloth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactKind {
    /// Particles kept a thickness apart: holds while the thickness is near the particle
    /// spacing (no particle can slip between its neighbours); cheaper for such thick cloth.
    Particles,
    /// Vertex–triangle and edge–edge contact within the thickness, whatever the spacing, with
    /// no substep creating a crossing (the default).
    #[default]
    Mesh,
}

fn yes() -> bool {
    true
}
fn default_self_static() -> f64 {
    0.3
}
fn default_self_dynamic() -> f64 {
    0.2
}
fn default_max_displacement() -> f64 {
    0.45
}
fn default_search_margin() -> f64 {
    0.5
}

#[cfg(test)]
mod tests {
    use weft_solver::Family;

    use super::*;
    use crate::family::{self, Field, Setting};

    #[test]
    fn every_family_key_reads_back_as_its_family_and_field() {
        // Every `<family>_<field>` key set to a value of its own (flags alternate), in the
        // order of the families and fields: the settings must name the same family and field
        // with the same value, in the same order.
        let mut text = String::new();
        let mut expected = Vec::new();
        for (i, family) in Family::ALL.into_iter().enumerate() {
            for (j, field) in Field::ALL.into_iter().enumerate() {
                let key = family::key(family, field);
                let v = (10 * i + j) as f64;
                let setting = match field {
                    Field::Enabled => Setting::Enabled(i % 2 == 0),
                    Field::Compliance => Setting::Compliance(v),
                    Field::Damping => Setting::Damping(v),
                    Field::PbdStiffness => Setting::PbdStiffness(v),
                    Field::SpringStiffness => Setting::SpringStiffness(v),
                    Field::SpringDamping => Setting::SpringDamping(v),
                };
                match setting {
                    Setting::Enabled(on) => text.push_str(&format!("{key} = {on}\n")),
                    _ => text.push_str(&format!("{key} = {v:?}\n")),
                }
                expected.push((family, setting));
            }
        }
        let section: ClothSection = toml_edit::de::from_str(&text).expect("every key is known");
        assert_eq!(section.family_settings(), expected);
        assert!(ClothSection::default().family_settings().is_empty());
    }
}
