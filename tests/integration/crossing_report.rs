//! `weft run` says what cloth contact held: a warning before the run for cloth that starts
//! crossing, and a closing line counting the frames that crossed (the independent count of
//! `weft_sim::crossings`). A small sheet dropped onto a larger one, both 2 mm thick on a mesh
//! spacing of 4–7 cm: particle contact lets it through, mesh contact holds it.

use crate::common;

use common::{run, temp_dir, texts, write};

/// A 60 cm sheet held at its corners, and self-collision.
const LOWER: &str = r#"[sim]
dt = "1/60"
substeps = 10
damping = 0.5

[cloth.lower]
resolution = [10, 10]
size = [0.6, 0.6]
orientation = "horizontal"
center = [0.0, 1.0, 0.0]
mass = 0.1
pins = ["top-left", "top-right", "bottom-left", "bottom-right"]
thickness = 0.002

[self_collision]
enabled = true
"#;

/// A 30 cm sheet, 2 mm thick, lying (`horizontal`) or standing (`vertical`) at `y`.
fn upper(orientation: &str, y: f64) -> String {
    format!(
        "{LOWER}\n[cloth.upper]\nresolution = [8, 8]\nsize = [0.3, 0.3]\n\
         orientation = \"{orientation}\"\ncenter = [0.0, {y:.2}, 0.0]\nmass = 0.1\n\
         thickness = 0.002\n"
    )
}

fn drop(contact: &str) -> (String, String) {
    let dir = temp_dir(&format!("crossing-report-{contact}"));
    // Dropped from 5 cm above the lower sheet.
    let scene = write(&dir, "drop.toml", &upper("horizontal", 1.05));
    let set = format!("self_collision.contact=\"{contact}\"");
    let out = run(&["run", &scene, "--frames", "60", "--set", &set]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    (o, e)
}

#[test]
fn mesh_contact_holds_the_dropped_sheet_and_the_run_says_so() {
    let (o, _) = drop("mesh");
    assert!(
        o.contains("crossings: no cloth crossing in 60 measured frames; closest approach"),
        "{o}"
    );
}

#[test]
fn particle_contact_lets_the_sheet_through_and_the_run_counts_it() {
    let (o, _) = drop("particles");
    assert!(o.contains("crossings: cloth crossed in "), "{o}");
    assert!(o.contains("of 60 measured frames (most: "), "{o}");
}

#[test]
fn cloth_crossing_at_the_start_is_warned_about_and_the_run_goes_on() {
    // The upper sheet stands on its edge through the lower one.
    let dir = temp_dir("crossing-report-start");
    let scene = write(&dir, "crossed.toml", &upper("vertical", 1.0));
    let out = run(&["run", &scene, "--frames", "2"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "the run goes on: {o}{e}");
    let warning = e
        .find("weft: warning: cloths `lower` and `upper` start crossing each other (")
        .unwrap_or_else(|| panic!("no warning: {e}"));
    let started = e.find("cloth(s),").expect("the run's first line");
    assert!(warning < started, "the warning comes first: {e}");
    assert!(
        e.contains("contact cannot undo a crossing it did not cause"),
        "{e}"
    );
    assert!(o.contains("crossings: cloth crossed in "), "{o}");
    let out = run(&["check", &scene]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(
        o.contains("warning: cloths `lower` and `upper` start crossing each other ("),
        "check says it too: {o}"
    );
}
