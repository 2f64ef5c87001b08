//! `[[collider]]` and the parts of a compound.

use serde::{Deserialize, Serialize};

use super::{MotionSpec, exact};

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
            #[serde(
                default,
                deserialize_with = "exact::option",
                skip_serializing_if = "Option::is_none"
            )]
            pub half_extents: Option<[f64; 3]>,
            /// Capsule half height of the core segment (m).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub half_height: Option<f64>,
            /// Plane outward normal.
            #[serde(
                default,
                deserialize_with = "exact::option",
                skip_serializing_if = "Option::is_none"
            )]
            pub normal: Option<[f64; 3]>,
            /// Convex hull points (m).
            #[serde(
                default,
                deserialize_with = "exact::option_list",
                skip_serializing_if = "Option::is_none"
            )]
            pub points: Option<Vec<[f64; 3]>>,
            $($middle)*
            /// Position in the parent frame (the world for a collider) (m).
            #[serde(default, deserialize_with = "exact::array")]
            pub position: [f64; 3],
            /// Rotation as XYZ Euler angles in degrees.
            #[serde(default, deserialize_with = "exact::array")]
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

pub(super) fn default_static_friction() -> f64 {
    0.5
}
pub(super) fn default_dynamic_friction() -> f64 {
    0.4
}
