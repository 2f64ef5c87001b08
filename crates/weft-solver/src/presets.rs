//! Fabric presets in physical units, from published Kawabata (KES-F) measurements.
//!
//! KES-F reports, per fabric: weight W (mg/cm²), tensile strain EMT (%) at the test's 500 gf/cm
//! load, shear rigidity G (gf/(cm·deg)) and bending rigidity B (gf·cm²/cm). Converted:
//!
//! * density: 1 mg/cm² = 10 g/m² = 0.01 kg/m²;
//! * stretch: the secant membrane stiffness to the test load, 500 gf/cm / EMT
//!   = 490.3 N/m / EMT (e.g. EMT = 4 % → 12,300 N/m);
//! * shear: 1 gf/(cm·deg) = 0.9807 N/m per degree = 56.2 N/m per radian;
//! * bending: 1 gf·cm²/cm = 9.807 × 10⁻⁵ N·m.
//!
//! The values are representative of the ranges tabulated for each fabric class (warp/weft
//! averages), not one measured sample: Kawabata & Niwa 1989, "Fabric performance in clothing
//! and clothing manufacture", J. Textile Inst. 80(1), 19–50 (KES-F ranges of suitings and
//! shirtings, cotton and wool); Wang, O'Brien & Ramamoorthi 2011, "Data-driven elastic models
//! for cloth", ACM TOG 30(4) (ten measured fabrics incl. cotton, denim, silk, wool, knits);
//! Miguel et al. 2012, "Data-driven estimation of cloth simulation models", Comput. Graph.
//! Forum 31(2) (cotton, denim, knits); Clyde, Teran & Tamstorf 2017, "Modeling and data-driven
//! parameter estimation for woven fabrics", SCA (denim, charmeuse silk, cotton, wool coating).
//! Leather is not a KES textile: its entry uses garment leather (about 1 mm) values of the same
//! quantities, an order-of-magnitude estimate.

use crate::material::Material;

/// `(name, material, source in words)` of every preset, in the order `weft` lists them.
pub const PRESETS: [(&str, Material, &str); 6] = [
    (
        "cotton",
        Material {
            density: 0.13,
            stretch: 12_000.0,
            shear: 56.0,
            bending: 7.8e-6,
        },
        "cotton shirting: W 13 mg/cm², EMT 4 %, G 1.0 gf/(cm·deg), B 0.08 gf·cm²/cm",
    ),
    (
        "denim",
        Material {
            density: 0.40,
            stretch: 16_000.0,
            shear: 170.0,
            bending: 9.8e-5,
        },
        "denim (12 oz): W 40 mg/cm², EMT 3 %, G 3.0 gf/(cm·deg), B 1.0 gf·cm²/cm",
    ),
    (
        "silk",
        Material {
            density: 0.06,
            stretch: 8_000.0,
            shear: 22.0,
            bending: 2.9e-6,
        },
        "silk crêpe de chine/charmeuse: W 6 mg/cm², EMT 6 %, G 0.4 gf/(cm·deg), B 0.03 gf·cm²/cm",
    ),
    (
        "jersey",
        Material {
            density: 0.18,
            stretch: 1_200.0,
            shear: 34.0,
            bending: 4.9e-6,
        },
        "cotton single jersey (knit): W 18 mg/cm², EMT 40 %, G 0.6 gf/(cm·deg), B 0.05 gf·cm²/cm",
    ),
    (
        "wool",
        Material {
            density: 0.25,
            stretch: 10_000.0,
            shear: 45.0,
            bending: 1.2e-5,
        },
        "worsted wool suiting: W 25 mg/cm², EMT 5 %, G 0.8 gf/(cm·deg), B 0.12 gf·cm²/cm",
    ),
    (
        "leather",
        Material {
            density: 0.60,
            stretch: 50_000.0,
            shear: 1_000.0,
            bending: 1.0e-3,
        },
        "garment leather, about 1 mm: 600 g/m², estimate (not KES-F)",
    ),
];

/// The preset called `name`, if any.
pub fn preset(name: &str) -> Option<Material> {
    PRESETS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, m, _)| *m)
}

/// The preset names, comma-separated (for messages).
pub fn preset_names() -> String {
    PRESETS.map(|(n, _, _)| n).join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_valid_and_found_by_name() {
        for (name, m, _) in PRESETS {
            m.validate().expect("valid");
            assert_eq!(preset(name), Some(m));
        }
        assert_eq!(preset("tweed"), None);
        // Knits stretch far more than wovens; denim bends far harder than silk.
        let get = |n| preset(n).expect("preset");
        assert!(get("jersey").stretch * 5.0 < get("cotton").stretch);
        assert!(get("denim").bending > 10.0 * get("silk").bending);
    }
}
