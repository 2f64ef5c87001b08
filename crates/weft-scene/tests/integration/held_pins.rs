//! `held`: pinned particles that stay still while the cloth's `motion` drives its `pins` (one
//! edge held, the other turned, as in `twist.toml`), and bad entries named by line and key.

use crate::common;

use weft_scene::DirFiles;
use weft_solver::glam::DVec3;

/// A 6 × 4 grid, its right edge turned about x at a quarter turn a second, its left edge held.
const TURNED: &str = r#"[cloth.strip]
resolution = [6, 4]
size = [1.0, 0.5]
orientation = "horizontal"
center = [0.0, 1.0, 0.0]
pins = ["right"]
held = ["left", 8]
motion = { kind = "rotate", pivot = [0.0, 1.0, 0.0], axis = [1.0, 0.0, 0.0], angular_velocity = 1.5707963267948966 }
"#;

#[test]
fn held_pins_stay_put_while_the_moving_pins_turn() {
    let files = DirFiles(common::scenes_dir());
    let scene = weft_scene::from_text("t.toml", TURNED, &[], &files).expect("valid");
    let cloth = &scene.cloths[0];
    // The left column of a 6-wide grid, and vertex 8 (row 1, column 2).
    assert_eq!(cloth.held, vec![0, 6, 8, 12, 18]);
    let start = cloth.mesh.positions.clone();
    let mut groups = scene.build().expect("builds");
    let g = &mut groups[0];
    for _ in 0..60 {
        g.step().expect("steps");
    }
    let x = &g.solver.particles().positions;
    for &v in &cloth.held {
        assert_eq!(x[v as usize], start[v as usize], "held vertex {v} moved");
        assert_eq!(g.solver.particles().inv_masses[v as usize], 0.0);
    }
    // After 1 s the right edge has turned a quarter turn about +x (right-handed) through the
    // centre: a point at (0.5, 1, z) goes to (0.5, 1 − z, 0).
    for row in 0..4 {
        let v = row * 6 + 5;
        let (a, b) = (start[v], x[v]);
        let turned = DVec3::new(a.x, 1.0 - a.z, 0.0);
        assert!(
            b.distance(turned) < 1e-9,
            "right-edge vertex {v}: {b} (from {a}), expected {turned}"
        );
    }
}

#[test]
fn bad_held_entries_name_their_line_and_key() {
    let bad = |entry: &str| TURNED.replace("held = [\"left\", 8]", &format!("held = [{entry}]"));
    common::assert_errors(&[
        (
            bad("\"middle\""),
            7,
            "cloth.strip.held[0]",
            "unknown pin `middle`",
        ),
        (
            bad("\"left\", 24"),
            7,
            "cloth.strip.held[1]",
            "vertex 24 does not exist (the grid has 24)",
        ),
    ]);
}
