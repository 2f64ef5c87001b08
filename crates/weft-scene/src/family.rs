//! Per-family constraint parameters as flat cloth keys: `<family>_<field>`, e.g.
//! `stretch_compliance`, `bend_dihedral_enabled`, `tether_spring_stiffness`.

use weft_solver::{ClothParams, Family};

/// A field of [`weft_solver::FamilyParams`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// `enabled` (bool).
    Enabled,
    /// `compliance` (XPBD, ≥ 0).
    Compliance,
    /// `damping` (XPBD constraint damping, ≥ 0).
    Damping,
    /// `pbd_stiffness` (PBD, in [0, 1]).
    PbdStiffness,
    /// `spring_stiffness` (mass-spring, ≥ 0).
    SpringStiffness,
    /// `spring_damping` (mass-spring, ≥ 0).
    SpringDamping,
}

impl Field {
    /// The field's name inside a key.
    pub fn name(self) -> &'static str {
        match self {
            Field::Enabled => "enabled",
            Field::Compliance => "compliance",
            Field::Damping => "damping",
            Field::PbdStiffness => "pbd_stiffness",
            Field::SpringStiffness => "spring_stiffness",
            Field::SpringDamping => "spring_damping",
        }
    }

    /// Whether `v` is allowed, and what is expected otherwise.
    pub fn check(self, v: f64) -> Result<(), &'static str> {
        match self {
            Field::Enabled => Ok(()),
            Field::PbdStiffness if !(v.is_finite() && (0.0..=1.0).contains(&v)) => {
                Err("must be finite and in [0, 1]")
            }
            _ if !(v.is_finite() && v >= 0.0) => Err("must be finite and >= 0"),
            _ => Ok(()),
        }
    }
}

/// The flat key of `field` in `family`, e.g. `stretch_compliance`.
pub fn key(family: Family, field: Field) -> String {
    format!("{}_{}", family.name(), field.name())
}

/// Applies `(family, field, value)` entries that are set to `params` (values unchecked).
pub fn apply(entries: &[(Family, Field, Option<f64>)], params: &mut ClothParams) {
    for &(family, field, value) in entries {
        let Some(v) = value else { continue };
        let p = params.get_mut(family);
        match field {
            Field::Enabled => p.enabled = v != 0.0,
            Field::Compliance => p.compliance = v,
            Field::Damping => p.damping = v,
            Field::PbdStiffness => p.pbd_stiffness = v,
            Field::SpringStiffness => p.spring_stiffness = v,
            Field::SpringDamping => p.spring_damping = v,
        }
    }
}
