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

/// The push-out and friction of `L` contacts side by side against a still surface, every
/// branch a select so that the compiler keeps them in vector registers: each lane's position
/// `x` moved by `depth` along its unit `normal`, then its slip since `prev` across the normal
/// corrected as [`Friction::correction`] does (Macklin et al. 2014, eq. 24), operation for
/// operation. Returns the new positions (a lane whose `push` is false keeps its own) and each
/// pushed lane's correction, squared (a lane not pushed reads as sticking).
#[inline(always)]
#[allow(clippy::needless_range_loop)]
pub(crate) fn push_lanes<const L: usize>(
    friction: Friction,
    x: &[[f64; L]; 3],
    prev: &[[f64; L]; 3],
    normal: [&[f64; L]; 3],
    depth: &[f64; L],
    push: &[bool; L],
) -> ([[f64; L]; 3], [f64; L]) {
    let mut moved = [[0.0; L]; 3];
    let mut rel = [[0.0; L]; 3];
    for a in 0..3 {
        for l in 0..L {
            moved[a][l] = x[a][l] + normal[a][l] * depth[l];
            rel[a][l] = moved[a][l] - prev[a][l];
        }
    }
    let mut along = [0.0; L];
    for l in 0..L {
        along[l] = normal[0][l] * rel[0][l] + normal[1][l] * rel[1][l] + normal[2][l] * rel[2][l];
    }
    let mut t = [[0.0; L]; 3];
    for a in 0..3 {
        for l in 0..L {
            t[a][l] = rel[a][l] - normal[a][l] * along[l];
        }
    }
    let mut scale = [1.0; L];
    let mut no_slip = [false; L];
    let mut t2 = [0.0; L];
    let mut stick = [true; L];
    for l in 0..L {
        t2[l] = t[0][l] * t[0][l] + t[1][l] * t[1][l] + t[2][l] * t[2][l];
        let grip = friction.static_coefficient * depth[l];
        stick[l] = t2[l] < grip * grip;
        no_slip[l] = t2[l] <= 0.0;
    }
    // Sticking: t itself (t · 1 = t exactly). The square root and the division only where a
    // pushed lane slides (a block at rest sticks throughout).
    if (0..L).any(|l| push[l] & !stick[l]) {
        for l in 0..L {
            let sliding = (friction.dynamic_coefficient * depth[l] / t2[l].sqrt()).min(1.0);
            scale[l] = if stick[l] { 1.0 } else { sliding };
        }
    }
    let mut out = *x;
    let mut slip2 = [0.0; L];
    for a in 0..3 {
        for l in 0..L {
            // No slip: the correction is +0 (t · 0 may be −0, which would turn a −0
            // position into +0).
            let correction = if no_slip[l] { 0.0 } else { t[a][l] * scale[l] };
            slip2[l] += correction * correction;
            out[a][l] = if push[l] {
                moved[a][l] - correction
            } else {
                x[a][l]
            };
        }
    }
    (out, slip2)
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
