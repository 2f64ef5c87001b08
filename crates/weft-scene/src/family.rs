//! Per-family constraint parameters as flat cloth keys: `<family>_<field>`, e.g.
//! `stretch_compliance`, `bend_dihedral_enabled`, `tether_spring_stiffness`.

use weft_solver::{ClothParams, Family, FamilyParams};

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
    /// Every field, in the order of a family's keys.
    pub const ALL: [Field; 6] = [
        Field::Enabled,
        Field::Compliance,
        Field::Damping,
        Field::PbdStiffness,
        Field::SpringStiffness,
        Field::SpringDamping,
    ];

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

    /// The range check of the field's values: weft-solver's, the one authority on them (a
    /// flag is always allowed).
    pub fn rule(self) -> fn(f64) -> Result<(), &'static str> {
        match self {
            Field::Enabled => |_| Ok(()),
            Field::PbdStiffness => FamilyParams::check_pbd_stiffness,
            _ => FamilyParams::check_non_negative,
        }
    }
}

/// The flat key of `field` in `family`, e.g. `stretch_compliance`.
pub fn key(family: Family, field: Field) -> String {
    format!("{}_{}", family.name(), field.name())
}

/// The value of one per-family key, typed as it is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// `<family>_enabled`.
    Enabled(bool),
    /// `<family>_compliance`.
    Compliance(f64),
    /// `<family>_damping`.
    Damping(f64),
    /// `<family>_pbd_stiffness`.
    PbdStiffness(f64),
    /// `<family>_spring_stiffness`.
    SpringStiffness(f64),
    /// `<family>_spring_damping`.
    SpringDamping(f64),
}

impl Setting {
    /// The field this value sets.
    pub fn field(self) -> Field {
        match self {
            Setting::Enabled(_) => Field::Enabled,
            Setting::Compliance(_) => Field::Compliance,
            Setting::Damping(_) => Field::Damping,
            Setting::PbdStiffness(_) => Field::PbdStiffness,
            Setting::SpringStiffness(_) => Field::SpringStiffness,
            Setting::SpringDamping(_) => Field::SpringDamping,
        }
    }

    /// The value as a number (`None` for a flag).
    pub fn number(self) -> Option<f64> {
        match self {
            Setting::Enabled(_) => None,
            Setting::Compliance(v)
            | Setting::Damping(v)
            | Setting::PbdStiffness(v)
            | Setting::SpringStiffness(v)
            | Setting::SpringDamping(v) => Some(v),
        }
    }
}

/// Applies `(family, setting)` pairs to `params` (values unchecked).
pub fn apply(settings: &[(Family, Setting)], params: &mut ClothParams) {
    for &(family, setting) in settings {
        let p = params.get_mut(family);
        match setting {
            Setting::Enabled(on) => p.enabled = on,
            Setting::Compliance(v) => p.compliance = v,
            Setting::Damping(v) => p.damping = v,
            Setting::PbdStiffness(v) => p.pbd_stiffness = v,
            Setting::SpringStiffness(v) => p.spring_stiffness = v,
            Setting::SpringDamping(v) => p.spring_damping = v,
        }
    }
}
