//! Coulomb friction for position-based contacts.

use glam::DVec3;

use crate::error::ShapeError;

/// Coulomb friction coefficients of a contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Static coefficient μs: tangential slip below μs · depth is cancelled (sticking).
    pub static_coefficient: f64,
    /// Dynamic (kinetic) coefficient μk: otherwise slip is reduced by μk · depth (sliding).
    pub dynamic_coefficient: f64,
}

impl Default for Friction {
    fn default() -> Self {
        Self {
            static_coefficient: 0.6,
            dynamic_coefficient: 0.4,
        }
    }
}

impl Friction {
    /// Frictionless contact.
    pub const NONE: Self = Self {
        static_coefficient: 0.0,
        dynamic_coefficient: 0.0,
    };

    /// Friction with coefficients μs and μk.
    pub fn new(static_coefficient: f64, dynamic_coefficient: f64) -> Self {
        Self {
            static_coefficient,
            dynamic_coefficient,
        }
    }

    /// Checks both coefficients are finite and ≥ 0.
    pub fn validate(&self) -> Result<(), ShapeError> {
        for (name, value) in [
            ("friction.static_coefficient", self.static_coefficient),
            ("friction.dynamic_coefficient", self.dynamic_coefficient),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ShapeError::InvalidParameter {
                    name,
                    value,
                    expected: "finite and >= 0",
                });
            }
        }
        Ok(())
    }

    /// The position correction to *subtract* from the relative tangential displacement
    /// `tangential` of a contact that was pushed out by `depth` this substep.
    ///
    /// Position-based Coulomb friction, Macklin et al. 2014, "Unified Particle Physics for
    /// Real-Time Applications", §6.1, eq. (24): with Δx⊥ the relative tangential displacement
    /// over the substep and d the penetration depth,
    /// Δx = Δx⊥ if |Δx⊥| < μs d (static: the slip is cancelled), else
    /// Δx = Δx⊥ · min(μk d / |Δx⊥|, 1) (dynamic: the slip is reduced by μk d).
    ///
    /// The static case, a resting contact's usual one, compares squares: no square root on
    /// its path.
    #[inline]
    pub fn correction(&self, tangential: DVec3, depth: f64) -> DVec3 {
        let slip2 = tangential.length_squared();
        let grip = self.static_coefficient * depth;
        if depth <= 0.0 || slip2 <= 0.0 {
            DVec3::ZERO
        } else if slip2 < grip * grip {
            tangential
        } else {
            tangential * (self.dynamic_coefficient * depth / slip2.sqrt()).min(1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_cancels_and_dynamic_reduces() {
        let f = Friction::new(0.5, 0.25);
        let t = DVec3::new(0.01, 0.0, 0.0);
        assert_eq!(f.correction(t, 0.03), t);
        let c = f.correction(t, 0.01);
        assert!((c.x - 0.0025).abs() < 1e-7, "{c}");
        assert_eq!(Friction::NONE.correction(t, 1.0), DVec3::ZERO);
    }
}
