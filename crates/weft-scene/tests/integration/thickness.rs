//! A cloth's `thickness`: zero, negative, not finite, or larger than the cloth's own smallest
//! dimension is an error naming the file's line and the key; a thickness as large as that
//! dimension, or a thin one on a coarse mesh, is fine.

use crate::common;

use common::{assert_errors, scenes_dir};

/// A grid `cloth.sheet` of `size` with `thickness` on line 5 (a TOML value as written).
fn grid(size: &str, thickness: &str) -> String {
    format!(
        "[cloth.sheet]\nresolution = [8, 8]\nsize = {size}\norientation = \"horizontal\"\n\
         thickness = {thickness}\n"
    )
}

#[test]
fn a_thickness_of_zero_negative_or_not_finite_names_its_line_and_key() {
    let must = "must be finite and > 0 m";
    let cases: Vec<(String, usize, &str, &str)> = [
        ("0.0", "got 0"),
        ("-0.002", "got -0.002"),
        ("nan", "got NaN"),
        ("inf", "got inf"),
        ("-inf", "got -inf"),
    ]
    .into_iter()
    .map(|(t, got)| (grid("[1.0, 1.0]", t), 5, "cloth.sheet.thickness", got))
    .collect();
    assert_errors(&cases);
    let with_reason: Vec<(String, usize, &str, &str)> =
        vec![(grid("[1.0, 1.0]", "0.0"), 5, "cloth.sheet.thickness", must)];
    assert_errors(&with_reason);
    // The error is the only one, and says why.
    let errs = common::errors(&grid("[1.0, 1.0]", "0.0"));
    assert_eq!(errs.len(), 1, "{errs:?}");
    assert!(errs[0].2.contains("contact keeps cloth"), "{errs:?}");
}

#[test]
fn a_thickness_larger_than_the_cloth_names_the_dimension() {
    // A 0.6 m × 0.25 m sheet, flat or upright: the smallest dimension is its shorter side,
    // whichever way it lies; an OBJ mesh (the 0.8 m blob) by the middle side of its box.
    let cases: Vec<(String, usize, &str, &str)> = vec![
        (
            grid("[0.6, 0.25]", "0.3"),
            5,
            "cloth.sheet.thickness",
            "must not exceed the cloth's smallest dimension (0.25 m",
        ),
        (
            grid("[0.6, 0.25]", "0.3").replace("horizontal", "vertical"),
            5,
            "cloth.sheet.thickness",
            "got 0.3",
        ),
        (
            "[cloth.blob]\nmesh = \"../meshes/blob.obj\"\nmass = 0.1\nthickness = 5.0\n".into(),
            4,
            "cloth.blob.thickness",
            "must not exceed the cloth's smallest dimension",
        ),
    ];
    assert_errors(&cases);
}

#[test]
fn a_thickness_up_to_the_cloths_size_loads_and_a_thin_one_on_a_coarse_mesh_too() {
    let files = weft_scene::DirFiles(scenes_dir());
    for (size, t) in [("[0.6, 0.25]", "0.25"), ("[1.0, 1.0]", "0.001")] {
        let text = grid(size, t);
        let scene = weft_scene::from_text("ok.toml", &text, &[], &files)
            .unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(scene.cloths[0].thickness.to_string(), t);
    }
}
