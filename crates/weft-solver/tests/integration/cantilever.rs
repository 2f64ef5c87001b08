//! The cantilever bending test (ASTM D1388) against the heavy elastica: a strip of every preset
//! overhanging twice its bending length should bend so that the chord from the clamp to the tip
//! falls at 41.5°, under XPBD and implicit mass-spring at their default settings, at 8, 16 and
//! 32 segments along the overhang.
//!
//! Not met yet (issue 56; the causes are in docs/validation.md): the test is ignored until the
//! bending model and XPBD's convergence are fixed. `cargo test -p weft-solver --test integration
//! cantilever -- --ignored --nocapture` prints the table (several minutes: the implicit
//! method's conjugate gradients take most of it on the finest strips).

use crate::common::*;
use weft_solver::{Cantilever, ClothParams, Forces, Material, Method, PRESETS, Settings};

/// Frames to settle (10 s at 60 Hz) and the damping (1/s) that settles the strip in them.
const FRAMES: usize = 600;
const DAMPING: f64 = 3.0;
const G: f64 = 9.81;

/// The settled chord angle and the elastica's (degrees) of `material`'s strip of `segments`
/// under `method` at the default 10 substeps × 1 iteration.
fn chord_angles(material: &Material, method: Method, segments: usize) -> (f64, f64) {
    let strip = Cantilever::of_material(material, G, 2.0, segments);
    let mesh = strip.grid(material.density).build().expect("grid");
    let settings = Settings {
        method,
        ..Settings::default()
    };
    let params = material.params(&mesh, &settings, &ClothParams::default());
    let forces = Forces {
        damping: DAMPING,
        ..Forces::default()
    };
    let mut s = solver(settings, forces, &mesh, params);
    run(&mut s, FRAMES);
    let want = strip.elastica(material, G).expect("in range").chord_angle();
    let got = strip.chord_angle(&s.particles().positions);
    (got.to_degrees(), want.to_degrees())
}

#[test]
#[ignore = "issue 56: the bending gaps are diagnosed, not fixed"]
fn every_preset_bends_as_the_elastica_at_every_resolution() {
    let mut worst: (f64, String) = (0.0, String::new());
    for (name, m, _) in PRESETS {
        for method in [Method::Xpbd, Method::ImplicitMassSpring] {
            let mut row = format!("| {name} | {method} |");
            for n in [8, 16, 32] {
                let (got, want) = chord_angles(&m, method, n);
                row += &format!(" {got:.1}° |");
                if (got - want).abs() > worst.0 {
                    worst = (
                        (got - want).abs(),
                        format!("{name} {method} {n}: {got:.2}°"),
                    );
                }
            }
            println!("{row}");
        }
    }
    assert!(worst.0 < 2.0, "worst {} against 41.49°", worst.1);
}
