//! `[cloth.<name>]`: its own keys and the six keys of each constraint family.

use std::fmt;

use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use weft_solver::Family;

use super::{AttachSection, MethodName, MotionSpec, exact};
use crate::family::Setting;

/// A grid cloth's `resolution` when the file gives none.
pub const DEFAULT_RESOLUTION: [i64; 2] = [20, 20];
/// The particle counts along a grid's side that a `resolution` may give.
pub const RESOLUTION_RANGE: std::ops::RangeInclusive<i64> = 2..=4096;
/// A grid cloth's `size` (m) when the file gives none.
pub const DEFAULT_SIZE: [f64; 2] = [1.0, 1.0];
/// A cloth's collision `thickness` (m) when the file gives none.
pub const DEFAULT_THICKNESS: f64 = 0.005;

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
        #[serde(
            default,
            deserialize_with = "exact::option",
            skip_serializing_if = "Option::is_none"
        )]
        pub resolution: Option<[i64; 2]>,
        /// Grid size `[width, height]` (m).
        #[serde(
            default,
            deserialize_with = "exact::option",
            skip_serializing_if = "Option::is_none"
        )]
        pub size: Option<[f64; 2]>,
        /// Grid plane: `vertical` or `horizontal`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub orientation: Option<OrientationName>,
        /// The grid cut to a disc of this radius around its centre (m): the Cusick drape
        /// test's specimen.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub disc_radius: Option<f64>,
        /// Every particle of the disc within this distance of its centre pinned (m): the
        /// Cusick tester's clamped support.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub clamp_radius: Option<f64>,
        /// OBJ mesh file, relative to the scene file (instead of a grid).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub mesh: Option<String>,
        /// Scale applied to the OBJ mesh's vertices.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub scale: Option<f64>,
        /// Centre of a grid, or translation of a mesh (m).
        #[serde(
            default,
            deserialize_with = "exact::option",
            skip_serializing_if = "Option::is_none"
        )]
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
        /// Pinned particles that stay where they are while `motion` drives `pins`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub held: Option<Vec<PinSpec>>,
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
        BendIsometric: bend_isometric_enabled, bend_isometric_compliance,
            bend_isometric_damping, bend_isometric_pbd_stiffness,
            bend_isometric_spring_stiffness, bend_isometric_spring_damping;
        Tether: tether_enabled, tether_compliance, tether_damping,
            tether_pbd_stiffness, tether_spring_stiffness, tether_spring_damping;
    }
}
