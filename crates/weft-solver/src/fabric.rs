//! A user's own fabric from a textile lab's measurements, and the virtual cantilever that
//! checks it: what a fabric kit's physical tester does for a garment simulator.
//!
//! * **Bending** from the cantilever bending length c of ASTM D1388 (the strip overhangs 2c
//!   when its chord falls at 41.5°): B = w c³ with w = ρ g the weight per area (Peirce 1930;
//!   [`crate::elastica`]), along the warp and the weft; the bias, which the test does not
//!   measure, takes their geometric mean (ASTM D1388's "overall" rigidity √(B_warp B_weft)).
//! * **Stretch** from the extension ε at a tensile load F per unit width (KES-F's 500 gf/cm =
//!   490.3 N/m, or a strip test's load over its width): the secant stiffness F/ε, as the
//!   KES-F presets take it ([`crate::presets`]).
//! * **Shear** as given (N/m), since neither test measures it.
//!
//! [`virtual_cantilever`] then cuts a strip of the material along the warp or the weft,
//! overhangs it by 2c on the solver, lets it settle, and reads the bending length back from
//! the chord angle through the exact elastica.

use std::sync::atomic::{AtomicBool, Ordering};

use thiserror::Error;

use crate::cantilever::Cantilever;
use crate::elastica::{Elastica, MAX_LOAD};
use crate::material::Material;
use crate::params::{ClothParams, Direction};
use crate::settings::Settings;
use crate::{Forces, Method, SolverBuilder};

/// The ASTM D1388 test strip's length: an overhang of 2c must fit on it (m).
pub const ASTM_STRIP_LENGTH: f64 = 0.2;

/// KES-F's tensile test load, 500 gf/cm (N/m).
pub const KES_LOAD: f64 = 490.3;

/// A fabric as a textile lab measures it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FabricMeasurements {
    /// Areal weight (g/m²).
    pub weight: f64,
    /// Cantilever bending length c along the warp and along the weft (cm).
    pub bending_length: [f64; 2],
    /// Extension at `load` along the warp and along the weft (%).
    pub extension: [f64; 2],
    /// The tensile load the extensions were measured at, per unit width (N/m).
    pub load: f64,
    /// In-plane shear stiffness (N/m).
    pub shear: f64,
}

/// A measurement that cannot make a fabric.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{field}: {message}")]
pub struct FabricError {
    /// The measurement, e.g. `bending_length_warp`.
    pub field: &'static str,
    /// What is wrong with it.
    pub message: String,
}

impl FabricMeasurements {
    /// The material these measurements describe (see the module documentation), or the first
    /// measurement that is zero, negative, not finite, or a bending length whose 2c overhang is
    /// longer than the test strip.
    pub fn material(&self, g: f64) -> Result<Material, FabricError> {
        let [c_warp, c_weft] = self.bending_length;
        let [e_warp, e_weft] = self.extension;
        for (field, value) in [
            ("weight", self.weight),
            ("bending_length_warp", c_warp),
            ("bending_length_weft", c_weft),
            ("extension_warp", e_warp),
            ("extension_weft", e_weft),
            ("load", self.load),
            ("shear", self.shear),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(FabricError {
                    field,
                    message: format!("must be finite and > 0, got {value}"),
                });
            }
        }
        for (field, c) in [
            ("bending_length_warp", c_warp),
            ("bending_length_weft", c_weft),
        ] {
            if 2.0 * c * 1e-2 > ASTM_STRIP_LENGTH {
                return Err(FabricError {
                    field,
                    message: format!(
                        "{c} cm needs a {} cm overhang, longer than the ASTM D1388 strip \
                         ({} cm): was the overhang length given instead of c (half of it)?",
                        2.0 * c,
                        ASTM_STRIP_LENGTH * 1e2
                    ),
                });
            }
        }
        let density = self.weight * 1e-3;
        let bending = |c_cm: f64| density * g * (c_cm * 1e-2).powi(3);
        let (b_warp, b_weft) = (bending(c_warp), bending(c_weft));
        Ok(Material {
            density,
            stretch: self.load / (e_warp * 1e-2),
            shear: self.shear,
            bending: b_warp,
            stretch_weft: self.load / (e_weft * 1e-2),
            bending_weft: b_weft,
            bending_bias: (b_warp * b_weft).sqrt(),
        })
    }
}

/// What the virtual cantilever read on one strip.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CantileverReading {
    /// The strip's direction.
    pub direction: Direction,
    /// The material's bending length along it, c = (B/w)^(1/3) (m).
    pub bending_length: f64,
    /// The bending length read back from the settled strip's chord angle (m).
    pub measured: f64,
    /// The settled strip's chord angle below the horizontal (degrees).
    pub chord_angle: f64,
    /// The exact elastica's chord angle for the strip (degrees).
    pub elastica_angle: f64,
}

/// Overhangs a strip of `material` cut along `direction` by two bending lengths, with
/// `segments` cells along the overhang, under `method` at its defaults with damping 3/s for
/// 10 s, and reads its bending length back (see [`CantileverReading`]); `None` when the
/// elastica of the strip is out of range, a step fails, or `stop` is raised (polled every
/// frame).
pub fn virtual_cantilever(
    material: &Material,
    direction: Direction,
    method: Method,
    segments: usize,
    g: f64,
    stop: &AtomicBool,
) -> Option<CantileverReading> {
    let strip = Cantilever::of_material_along(material, direction, g, 2.0, segments);
    let mesh = strip.grid(material.density).build().ok()?;
    let settings = Settings {
        method,
        ..Settings::default()
    };
    let params = material.params(&mesh, &settings, &ClothParams::default());
    let forces = Forces {
        damping: 3.0,
        ..Forces::default()
    };
    let mut b = SolverBuilder::new(settings, forces).ok()?;
    b.add_cloth("strip", &mesh, params, 0.0).ok()?;
    let mut solver = b.build();
    for _ in 0..(10.0 / settings.dt).round() as usize {
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        solver.step().ok()?;
    }
    let angle = strip.chord_angle(&solver.particles().positions);
    let elastica = strip.elastica(material, g)?.chord_angle();
    let load = load_at_chord(angle)?;
    Some(CantileverReading {
        direction: strip.direction,
        bending_length: strip.overhang / 2.0,
        measured: strip.overhang / load.cbrt(),
        chord_angle: angle.to_degrees(),
        elastica_angle: elastica.to_degrees(),
    })
}

/// The load parameter λ = (L/c)³ whose elastica's chord falls at `angle` (rad), by bisection
/// (the chord falls further as λ grows); `None` beyond [`MAX_LOAD`]'s angle or below zero.
pub fn load_at_chord(angle: f64) -> Option<f64> {
    let chord = |load: f64| Elastica::solve(load).map(|e| e.chord_angle());
    if !(angle > 0.0 && angle <= chord(MAX_LOAD)?) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, MAX_LOAD);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if chord(mid)? < angle {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 9.81;

    fn lab() -> FabricMeasurements {
        FabricMeasurements {
            weight: 130.0,
            bending_length: [2.0, 1.5],
            extension: [4.0, 8.0],
            load: KES_LOAD,
            shear: 56.0,
        }
    }

    #[test]
    fn measurements_become_the_material_astm_and_kes_define() {
        let m = lab().material(G).expect("valid");
        assert_eq!(m.density, 0.13);
        // B = ρ g c³: 0.13 · 9.81 · 0.02³ = 1.02e-5 N·m along the warp.
        assert!((m.bending - 0.13 * G * 8e-6).abs() < 1e-18);
        assert!((m.bending_weft - 0.13 * G * 0.015f64.powi(3)).abs() < 1e-18);
        assert!((m.bending_bias - (m.bending * m.bending_weft).sqrt()).abs() < 1e-18);
        // 490.3 N/m at 4 % and 8 %.
        assert!((m.stretch - 12_257.5).abs() < 1e-9);
        assert!((m.stretch_weft - 6_128.75).abs() < 1e-9);
        // The bending length comes back from B.
        let c = crate::elastica::bending_length(m.bending, m.density * G);
        assert!((c - 0.02).abs() < 1e-15);
    }

    #[test]
    fn bad_measurements_name_what_is_wrong() {
        let bad = |edit: &dyn Fn(&mut FabricMeasurements)| {
            let mut m = lab();
            edit(&mut m);
            m.material(G).expect_err("invalid")
        };
        assert_eq!(bad(&|m| m.weight = 0.0).field, "weight");
        assert_eq!(bad(&|m| m.extension[1] = -3.0).field, "extension_weft");
        assert_eq!(
            bad(&|m| m.bending_length[0] = f64::NAN).field,
            "bending_length_warp"
        );
        assert_eq!(bad(&|m| m.load = f64::INFINITY).field, "load");
        assert_eq!(bad(&|m| m.shear = 0.0).field, "shear");
        let long = bad(&|m| m.bending_length[1] = 12.0);
        assert_eq!(long.field, "bending_length_weft");
        assert!(long.message.contains("24 cm overhang"), "{}", long.message);
        // 10 cm (a 20 cm overhang) still fits.
        let mut m = lab();
        m.bending_length = [10.0, 10.0];
        assert!(m.material(G).is_ok());
    }

    #[test]
    fn the_load_at_a_chord_inverts_the_elastica() {
        // ASTM D1388's plane: 41.49° at λ = 8 (an overhang of 2c).
        let load = load_at_chord(41.49f64.to_radians()).expect("in range");
        assert!((load - 8.0).abs() < 0.01, "{load}");
        for l in [0.5, 3.0, 20.0, 90.0] {
            let angle = Elastica::solve(l).expect("in range").chord_angle();
            let back = load_at_chord(angle).expect("in range");
            assert!((back - l).abs() < 1e-6 * l.max(1.0), "{l}: {back}");
        }
        assert_eq!(load_at_chord(0.0), None);
        let steepest = Elastica::solve(MAX_LOAD).expect("in range").chord_angle();
        assert_eq!(load_at_chord(steepest + 1e-3), None);
    }
}
