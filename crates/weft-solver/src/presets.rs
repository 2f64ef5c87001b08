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
//!
//! The ten presets after them are measured fabrics, each a single sample with its own warp,
//! weft and bias: Wang, O'Brien & Ramamoorthi 2011, "Data-driven elastic models for cloth:
//! modeling and measurement", ACM TOG 30(4), as distributed with ARCSim's `materials/*.json`
//! (named as there). Weft takes their small-strain, small-curvature values (see [`measured`]);
//! ARCSim's own model stiffens with strain and curvature, Weft's springs are linear, so these
//! knits stretch under their own weight as the measurement says they do at small strain.

use crate::material::Material;

/// `(name, material, source in words)` of every preset, in the order `weft` lists them.
pub const PRESETS: [(&str, Material, &str); 16] = [
    (
        "cotton",
        Material::isotropic(0.13, 12_000.0, 56.0, 7.8e-6),
        "cotton shirting: W 13 mg/cm², EMT 4 %, G 1.0 gf/(cm·deg), B 0.08 gf·cm²/cm",
    ),
    (
        "denim",
        Material::isotropic(0.40, 16_000.0, 170.0, 9.8e-5),
        "denim (12 oz): W 40 mg/cm², EMT 3 %, G 3.0 gf/(cm·deg), B 1.0 gf·cm²/cm",
    ),
    (
        "silk",
        Material::isotropic(0.06, 8_000.0, 22.0, 2.9e-6),
        "silk crêpe de chine/charmeuse: W 6 mg/cm², EMT 6 %, G 0.4 gf/(cm·deg), B 0.03 gf·cm²/cm",
    ),
    (
        "jersey",
        Material::isotropic(0.18, 1_200.0, 34.0, 4.9e-6),
        "cotton single jersey (knit): W 18 mg/cm², EMT 40 %, G 0.6 gf/(cm·deg), B 0.05 gf·cm²/cm",
    ),
    (
        "wool",
        Material::isotropic(0.25, 10_000.0, 45.0, 1.2e-5),
        "worsted wool suiting: W 25 mg/cm², EMT 5 %, G 0.8 gf/(cm·deg), B 0.12 gf·cm²/cm",
    ),
    (
        "leather",
        Material::isotropic(0.60, 50_000.0, 1_000.0, 1.0e-3),
        "garment leather, about 1 mm: 600 g/m², estimate (not KES-F)",
    ),
    measured(
        "11oz-black-denim",
        0.324,
        [205.352005, 1013.88629, 53.387184],
        [6.419646e-05, 7.338457e-05, 9.695158e-05],
        "jeans, 99 % cotton 1 % spandex",
    ),
    measured(
        "camel-ponte-roma",
        0.284,
        [31.146198, 44.028667, 31.896357],
        [3.634837e-05, 3.301325e-05, 3.715759e-05],
        "jacket, 60 % polyester 40 % rayon",
    ),
    measured(
        "gray-interlock",
        0.187,
        [16.593832, 34.477123, 36.860302],
        [2.319170e-05, 2.474996e-05, 1.426762e-05],
        "T-shirt, 60 % cotton 40 % polyester",
    ),
    measured(
        "ivory-rib-knit",
        0.276,
        [42.871021, 65.166023, 83.175644],
        [4.623759e-05, 3.001593e-05, 3.224389e-05],
        "underwear, 95 % cotton 5 % spandex",
    ),
    measured(
        "navy-sparkle-sweat",
        0.224,
        [12.486332, 3.272434, 17.616289],
        [5.946966e-05, 4.007228e-05, 4.562502e-05],
        "sweater, 96 % polyester 4 % spandex",
    ),
    measured(
        "pink-ribbon-brown",
        0.228,
        [151.503906, 244.830673, 30.250183],
        [1.170701e-04, 8.750977e-05, 5.977428e-05],
        "blanket, polyester",
    ),
    measured(
        "royal-target",
        0.22,
        [2016.55456, 2034.97644, 104.759674],
        [1.254098e-04, 1.079977e-04, 1.254098e-04],
        "pants, 65 % cotton 35 % polyester",
    ),
    measured(
        "tango-red-jet-set",
        0.113,
        [43.067627, 171.424835, 14.3147],
        [1.429381e-05, 2.195170e-05, 2.034565e-05],
        "jacket, polyester",
    ),
    measured(
        "white-dots-on-blk",
        0.128,
        [2002.08618, 2027.48559, 19.189022],
        [5.171381e-05, 4.065947e-05, 3.128282e-05],
        "tablecloth, polyester",
    ),
    measured(
        "white-swim-solid",
        0.204,
        [47.971176, 104.615456, 60.773663],
        [6.023794e-05, 5.880321e-05, 5.101883e-05],
        "swimsuit, 87 % nylon 13 % spandex",
    ),
];

/// One of Wang, O'Brien & Ramamoorthi 2011's measured fabrics, as distributed in ARCSim's
/// material files, at small strain and curvature: `stretching` its first row's
/// `[k₀, k₂, k₃]` and `bending` the first column of its rows (edges at 0°, 45° and 90° to
/// the warp). ARCSim doubles the stretching samples and stores
/// W = ½ (k₀ G₀₀² + 2k₁ G₀₀G₁₁ + k₂ G₁₁² + k₃ G₀₁²) per area (G the Green strain), so the
/// warp and weft moduli are 2k₀ and 2k₂ and the shear modulus 2k₃/4 (k₁, the Poisson
/// coupling, has no counterpart in Weft's springs). Its hinge energy ke |e|² θ²/(8 A_e)
/// equals ½ B |e|²/A_e θ² at B = ke/4; a hinge on an edge along the warp bends a strip that
/// runs along the weft, so the 0° edges give the weft's bending and the 90° edges the warp's.
const fn measured(
    name: &'static str,
    density: f64,
    stretching: [f64; 3],
    bending: [f64; 3],
    source: &'static str,
) -> (&'static str, Material, &'static str) {
    let [k0, k2, k3] = stretching;
    let [edge_warp, edge_bias, edge_weft] = bending;
    (
        name,
        Material {
            density,
            stretch: 2.0 * k0,
            shear: 2.0 * k3 / 4.0,
            bending: edge_weft / 4.0,
            stretch_weft: 2.0 * k2,
            bending_weft: edge_warp / 4.0,
            bending_bias: edge_bias / 4.0,
        },
        source,
    )
}

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
        // The KES presets are isotropic, the measured ones are not; the jeans are five times
        // stiffer along the weft than along the warp (2 · 1013.9 against 2 · 205.4 N/m).
        assert!(PRESETS[..6].iter().all(|(_, m, _)| m.is_isotropic()));
        assert!(PRESETS[6..].iter().all(|(_, m, _)| !m.is_isotropic()));
        let jeans = get("11oz-black-denim");
        assert!((jeans.stretch_weft - 2027.77258).abs() < 1e-3);
        assert!((jeans.bending - 9.695158e-5 / 4.0).abs() < 1e-12);
        assert!((jeans.bending_weft - 6.419646e-5 / 4.0).abs() < 1e-12);
    }
}
