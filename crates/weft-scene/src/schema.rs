//! The scene file as written: serde structures mirroring the TOML, before validation.
//!
//! Every table denies unknown keys, so a typo is an error rather than a silently ignored value.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use weft_solver::Family;

use crate::family::Setting;

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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f64; 3]>,
    /// The `model`'s rotation as XYZ Euler angles in degrees (e.g. `[-90, 0, 0]` for a z-up
    /// file), applied after `scale`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
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
    pub edges: [i64; 2],
    /// The part of that run to attach, as fractions of its vertices from its first corner
    /// to its last (default `[0, 1]`: all of it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub span: Option<[f64; 2]>,
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
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Global velocity damping rate (1/s).
    #[serde(default)]
    pub damping: f64,
    /// A particle farther than this from the origin (m) means divergence.
    #[serde(default = "default_bound")]
    pub divergence_bound: f64,
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
        }
    }
}

/// `[wind]`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WindSection {
    /// Wind velocity (m/s).
    #[serde(default)]
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

/// The plane of a grid cloth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OrientationName {
    /// x–y plane, hanging.
    #[default]
    Vertical,
    /// x–z plane, lying.
    Horizontal,
}

/// A pin: a corner or edge name (`top-left`, `top`, …) or a vertex index.
#[derive(Clone, Debug, PartialEq)]
pub enum PinSpec {
    /// A corner or edge of a grid.
    Named(String),
    /// A vertex index.
    Index(i64),
}

impl Serialize for PinSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            PinSpec::Named(n) => s.serialize_str(n),
            PinSpec::Index(i) => s.serialize_i64(*i),
        }
    }
}

impl<'de> Deserialize<'de> for PinSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = PinSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a corner or edge name (\"top-left\", \"top\", …) or a vertex index")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<PinSpec, E> {
                Ok(PinSpec::Index(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<PinSpec, E> {
                i64::try_from(v)
                    .map(PinSpec::Index)
                    .map_err(|_| E::custom("vertex index too large"))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<PinSpec, E> {
                Ok(PinSpec::Named(v.to_owned()))
            }
        }
        d.deserialize_any(V)
    }
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
        velocity: [f64; 3],
    },
    /// x₀ + A sin(2π f t).
    Oscillate {
        /// Amplitude (m).
        amplitude: [f64; 3],
        /// Frequency (Hz).
        frequency: f64,
    },
    /// Rotation about an axis through a pivot.
    Rotate {
        /// A point on the axis (m).
        pivot: [f64; 3],
        /// Axis direction.
        axis: [f64; 3],
        /// Angular velocity (rad/s).
        angular_velocity: f64,
    },
}

/// Defines [`ClothSection`]: its own keys as written, then six keys per family in the order
/// of [`Field`](crate::family::Field) (`<family>_enabled`, `_compliance`, `_damping`,
/// `_pbd_stiffness`, `_spring_stiffness`, `_spring_damping`), and
/// [`ClothSection::family_settings`], which reads those keys back. One list of names yields
/// both; a unit test checks each name against [`crate::family::key`].
macro_rules! cloth_section {
    (
        $(#[$meta:meta])*
        pub struct ClothSection {
            $($own:tt)*
        }
        families {
            $($family:ident: $enabled:ident, $compliance:ident, $damping:ident,
                $pbd_stiffness:ident, $spring_stiffness:ident, $spring_damping:ident;)*
        }
    ) => {
        $(#[$meta])*
        pub struct ClothSection {
            $($own)*
            $(
                #[doc = concat!("`", stringify!($enabled), "`: whether the family's constraints are created.")]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $enabled: Option<bool>,
                #[doc = concat!("`", stringify!($compliance), "`: XPBD compliance.")]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $compliance: Option<f64>,
                #[doc = concat!("`", stringify!($damping), "`: XPBD constraint damping (s).")]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $damping: Option<f64>,
                #[doc = concat!("`", stringify!($pbd_stiffness), "`: PBD stiffness in [0, 1].")]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $pbd_stiffness: Option<f64>,
                #[doc = concat!("`", stringify!($spring_stiffness), "`: mass-spring stiffness.")]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $spring_stiffness: Option<f64>,
                #[doc = concat!("`", stringify!($spring_damping), "`: mass-spring damping (N·s/m).")]
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $spring_damping: Option<f64>,
            )*
        }

        impl ClothSection {
            /// The per-family keys that are set, as `(family, setting)` pairs in key order.
            pub fn family_settings(&self) -> Vec<(Family, Setting)> {
                let mut set = Vec::new();
                $(
                    let family = Family::$family;
                    set.extend(self.$enabled.map(|v| (family, Setting::Enabled(v))));
                    set.extend(self.$compliance.map(|v| (family, Setting::Compliance(v))));
                    set.extend(self.$damping.map(|v| (family, Setting::Damping(v))));
                    set.extend(self.$pbd_stiffness.map(|v| (family, Setting::PbdStiffness(v))));
                    set.extend(
                        self.$spring_stiffness
                            .map(|v| (family, Setting::SpringStiffness(v))),
                    );
                    set.extend(self.$spring_damping.map(|v| (family, Setting::SpringDamping(v))));
                )*
                set
            }
        }
    };
}

cloth_section! {
    /// `[cloth.<name>]`.
    #[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    pub struct ClothSection {
        /// Method of this cloth, overriding `sim.method` (a scene yields one solver per method).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub method: Option<MethodName>,
        /// Grid particles `[columns, rows]` (grid cloths).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub resolution: Option<[i64; 2]>,
        /// Grid size `[width, height]` (m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub size: Option<[f64; 2]>,
        /// Grid plane: `vertical` or `horizontal`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub orientation: Option<OrientationName>,
        /// OBJ mesh file, relative to the scene file (instead of a grid).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub mesh: Option<String>,
        /// Scale applied to the OBJ mesh's vertices.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub scale: Option<f64>,
        /// Centre of a grid, or translation of a mesh (m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub center: Option<[f64; 3]>,
        /// Total mass (kg); give this or `density`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub mass: Option<f64>,
        /// Areal density (kg/m²); give this or `mass`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub density: Option<f64>,
        /// Pinned particles.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub pins: Option<Vec<PinSpec>>,
        /// Motion the pins follow (default: static).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub motion: Option<MotionSpec>,
        /// Collision thickness (m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub thickness: Option<f64>,
        /// Fabric in physical units: a preset name or a table (see [`crate::material`]); the
        /// family keys override what it derives.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub material: Option<crate::material::MaterialSpec>,
        /// A garment file (panels and seams, weft-character's format) instead of a grid or
        /// mesh, relative to the scene.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub garment: Option<String>,
        /// Time over which the garment's seams close (s, default 0.5).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub seam_time: Option<f64>,
        /// Garment vertices attached to the character's bones.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub attach: Option<Vec<AttachSection>>,
    }
    families {
        Stretch: stretch_enabled, stretch_compliance, stretch_damping,
            stretch_pbd_stiffness, stretch_spring_stiffness, stretch_spring_damping;
        Shear: shear_enabled, shear_compliance, shear_damping,
            shear_pbd_stiffness, shear_spring_stiffness, shear_spring_damping;
        BendDistance: bend_distance_enabled, bend_distance_compliance, bend_distance_damping,
            bend_distance_pbd_stiffness, bend_distance_spring_stiffness,
            bend_distance_spring_damping;
        BendDihedral: bend_dihedral_enabled, bend_dihedral_compliance, bend_dihedral_damping,
            bend_dihedral_pbd_stiffness, bend_dihedral_spring_stiffness,
            bend_dihedral_spring_damping;
        Tether: tether_enabled, tether_compliance, tether_damping,
            tether_pbd_stiffness, tether_spring_stiffness, tether_spring_damping;
    }
}

/// A collider's shape kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShapeKind {
    /// `radius`.
    Sphere,
    /// `half_extents`.
    Cuboid,
    /// `half_height` (along local y) and `radius`.
    Capsule,
    /// A half-space below the plane through `position` with outward `normal`.
    Plane,
    /// The convex hull of `points`.
    ConvexHull,
    /// An OBJ triangle mesh (`mesh`, `scale`).
    Mesh,
    /// Several convex `parts`.
    Compound,
}

/// Declares a section with the geometry keys a collider and a compound part share — `shape`,
/// the shape parameters, then (after the section's own `$middle` keys) `position` and
/// `rotation_deg` — between its `$lead` and `$trail` keys, in that order (the order the
/// effective scene is written in).
macro_rules! shape_section {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            lead { $($lead:tt)* }
            middle { $($middle:tt)* }
            trail { $($trail:tt)* }
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            $($lead)*
            /// The shape kind.
            pub shape: ShapeKind,
            /// Sphere and capsule radius (m).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub radius: Option<f64>,
            /// Cuboid half extents (m).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub half_extents: Option<[f64; 3]>,
            /// Capsule half height of the core segment (m).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub half_height: Option<f64>,
            /// Plane outward normal.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub normal: Option<[f64; 3]>,
            /// Convex hull points (m).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub points: Option<Vec<[f64; 3]>>,
            $($middle)*
            /// Position in the parent frame (the world for a collider) (m).
            #[serde(default)]
            pub position: [f64; 3],
            /// Rotation as XYZ Euler angles in degrees.
            #[serde(default)]
            pub rotation_deg: [f64; 3],
            $($trail)*
        }
    };
}

shape_section! {
    /// A part of a compound collider: the geometry keys alone.
    pub struct PartSection {
        lead {}
        middle {}
        trail {}
    }
}

shape_section! {
    /// `[[collider]]`.
    pub struct ColliderSection {
        lead {
            /// Name (for logs); defaults to `collider<i>`.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub name: Option<String>,
        }
        middle {
            /// OBJ file for `mesh`, relative to the scene file.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub mesh: Option<String>,
            /// Scale of the OBJ mesh.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub scale: Option<f64>,
            /// Parts of a compound.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub parts: Option<Vec<PartSection>>,
        }
        trail {
            /// Coulomb static friction coefficient.
            #[serde(default = "default_static_friction")]
            pub static_friction: f64,
            /// Coulomb dynamic friction coefficient (≤ static).
            #[serde(default = "default_dynamic_friction")]
            pub dynamic_friction: f64,
            /// Kinematic motion (default static).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub motion: Option<MotionSpec>,
        }
    }
}

fn default_static_friction() -> f64 {
    0.5
}
fn default_dynamic_friction() -> f64 {
    0.4
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
    use super::*;
    use crate::family::{self, Field};

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
