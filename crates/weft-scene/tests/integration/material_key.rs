//! `cloth.<name>.material`: presets, per-field overrides, family keys on top, and errors that
//! name the key and line.

use weft_scene::{MapFiles, from_text};
use weft_solver::{Family, HINGE_RELAXATION, preset};

fn scene(cloth: &str) -> Result<weft_scene::Scene, weft_scene::SceneErrors> {
    let text = format!("[sim]\nsubsteps = 10\n\n[cloth.c]\nresolution = [16, 16]\n{cloth}\n");
    from_text("t.toml", &text, &[], &MapFiles::default())
}

#[test]
fn a_preset_sets_mass_and_every_method_and_turns_isometric_bending_on() {
    let s = scene("material = \"denim\"").expect("valid");
    let c = &s.cloths[0];
    let denim = preset("denim").expect("preset");
    assert!(
        (c.mesh.total_mass() - denim.density).abs() < 1e-12,
        "1 m² of 400 g/m²"
    );
    let p = c.params;
    // Soft per substep at this resolution: isometric bending with stiffness B (times the
    // grid's relaxation factor, which makes a free strip bend at B), no other.
    assert!(p.get(Family::BendIsometric).enabled && !p.get(Family::BendDistance).enabled);
    assert!(!p.get(Family::BendDihedral).enabled);
    assert_eq!(
        p.get(Family::BendIsometric).spring_stiffness,
        HINGE_RELAXATION * denim.bending
    );
    let st = p.get(Family::Stretch);
    // Square cells: k = E − G per grid line; XPBD gets 1/k.
    assert!((st.spring_stiffness - (denim.stretch - denim.shear)).abs() < 1e-6);
    assert!((st.compliance * st.spring_stiffness - 1.0).abs() < 1e-12);
}

#[test]
fn fields_and_family_keys_override_the_preset() {
    let s = scene(
        "material = { preset = \"cotton\", bending = 2e-5, density = 200 }\nshear_compliance = 0.5",
    )
    .expect("valid");
    let c = &s.cloths[0];
    assert!((c.mesh.total_mass() - 0.2).abs() < 1e-12);
    let p = c.params;
    assert_eq!(
        p.get(Family::BendIsometric).spring_stiffness,
        HINGE_RELAXATION * 2e-5
    );
    assert_eq!(p.get(Family::Shear).compliance, 0.5);
}

#[test]
fn bad_materials_are_named_with_their_key_and_line() {
    let e = scene("material = \"tweed\"")
        .expect_err("unknown preset")
        .to_string();
    assert!(
        e.contains("cloth.c.material") && e.contains("tweed") && e.contains("cotton"),
        "{e}"
    );
    assert!(e.contains("t.toml:6"), "{e}");
    let e = scene("material = { stretch = 100.0 }")
        .expect_err("incomplete")
        .to_string();
    assert!(
        e.contains("cloth.c.material.density") && e.contains("missing"),
        "{e}"
    );
    let e = scene("material = { preset = \"silk\", shear = -1.0 }")
        .expect_err("negative")
        .to_string();
    assert!(e.contains("cloth.c.material.shear"), "{e}");
}

#[test]
fn a_measured_preset_and_direction_keys_make_the_cloth_anisotropic() {
    // The jeans of Wang et al. 2011: stiffer along the weft in stretch, along the warp in
    // bending; the ratios go to the solver's weft and bias groups.
    let s = scene("material = \"11oz-black-denim\"").expect("valid");
    let jeans = preset("11oz-black-denim").expect("preset");
    let a = s.cloths[0].params.anisotropy;
    let stretch = a[Family::Stretch.index()];
    let e = |v: f64| (v - jeans.shear).max(0.1 * v);
    assert!((stretch.weft - e(jeans.stretch_weft) / e(jeans.stretch)).abs() < 1e-12);
    // The hinges of a grid are set so that each strip bends at its own B (`grid_hinges`).
    let hinges = jeans.grid_hinges();
    let bend = a[Family::BendIsometric.index()];
    assert!((bend.weft - hinges.bending_weft / hinges.bending).abs() < 1e-12);
    assert!((bend.bias - hinges.bending_bias / hinges.bending).abs() < 1e-12);
    assert!(bend.weft < 1.0 && bend.bias < 1.0, "{bend:?}");
    // `bending` sets every direction; a direction's own key wins over it.
    let s =
        scene("material = { preset = \"11oz-black-denim\", bending = 2e-5, bending_weft = 1e-5 }")
            .expect("valid");
    let p = s.cloths[0].params;
    let given = weft_solver::Material {
        bending: 2e-5,
        bending_weft: 1e-5,
        bending_bias: 2e-5,
        ..jeans
    }
    .grid_hinges();
    assert_eq!(
        p.get(Family::BendIsometric).spring_stiffness,
        HINGE_RELAXATION * given.bending
    );
    let bend = p.anisotropy[Family::BendIsometric.index()];
    assert!((bend.weft - given.bending_weft / given.bending).abs() < 1e-12);
    assert!((bend.bias - 2e-5 / given.bending).abs() < 1e-12);
    // An isotropic preset stays isotropic.
    let s = scene("material = \"cotton\"").expect("valid");
    assert!(
        (s.cloths[0].params.anisotropy)
            .iter()
            .all(|a| *a == weft_solver::Anisotropy::ISOTROPIC)
    );
    let e = scene("material = { preset = \"cotton\", bending_weft = 0.0 }")
        .expect_err("zero")
        .to_string();
    assert!(e.contains("cloth.c.material.bending_weft"), "{e}");
}
