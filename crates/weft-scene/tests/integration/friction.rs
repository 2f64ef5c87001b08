//! Coulomb friction is checked alike in every table that has it: both coefficients finite and
//! >= 0, the dynamic one no more than the static one, each error at its own line and key.

use crate::common;

/// A scene whose `[character]`, `[[collider]]` and `[self_collision]` each set
/// `static_friction` and `dynamic_friction`, at lines 3–4, 9–10 and 14–15.
fn scene(static_friction: &str, dynamic_friction: &str) -> String {
    let f = format!("static_friction = {static_friction}\ndynamic_friction = {dynamic_friction}");
    format!(
        "[character]\nskeleton = \"walker\"\n{f}\n\n[[collider]]\nshape = \"sphere\"\n\
         radius = 0.2\n{f}\n\n[self_collision]\nenabled = true\n{f}\n\n\
         [cloth.sheet]\nresolution = [4, 4]\ncenter = [3.0, 1.0, 0.0]\n"
    )
}

/// The tables of [`scene`] with the line of their `static_friction`.
const TABLES: [(usize, &str); 3] = [(3, "character"), (9, "collider[0]"), (14, "self_collision")];

#[test]
fn dynamic_friction_above_static_is_refused_in_every_table() {
    let text = scene("0.2", "0.3");
    let keys: Vec<(usize, String)> = TABLES
        .iter()
        .map(|(line, t)| (line + 1, format!("{t}.dynamic_friction")))
        .collect();
    let cases: Vec<(String, usize, &str, &str)> = keys
        .iter()
        .map(|(line, key)| {
            (
                text.clone(),
                *line,
                key.as_str(),
                "must not exceed static_friction",
            )
        })
        .collect();
    common::assert_errors(&cases);
}

#[test]
fn negative_or_nan_friction_is_refused_in_every_table() {
    let text = scene("-0.1", "nan");
    let keys: Vec<(usize, String, &str)> = TABLES
        .iter()
        .flat_map(|(line, t)| {
            [
                (*line, format!("{t}.static_friction"), ">= 0"),
                (line + 1, format!("{t}.dynamic_friction"), "finite"),
            ]
        })
        .collect();
    let cases: Vec<(String, usize, &str, &str)> = keys
        .iter()
        .map(|(line, key, message)| (text.clone(), *line, key.as_str(), *message))
        .collect();
    common::assert_errors(&cases);
}
