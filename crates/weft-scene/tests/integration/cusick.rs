//! `disc_radius` and `clamp_radius`: a grid cut to the Cusick drape test's disc and clamped on
//! its support, and bad values named by line and key.

use crate::common;

use weft_scene::DirFiles;

const DISC: &str = r#"[cloth.specimen]
resolution = [25, 25]
size = [0.3, 0.3]
orientation = "horizontal"
center = [0.0, 0.5, 0.0]
held = [0]
disc_radius = 0.15
clamp_radius = 0.09
"#;

#[test]
fn a_disc_is_cut_from_the_grid_and_clamped_on_its_support() {
    let files = DirFiles(common::scenes_dir());
    let scene = weft_scene::from_text("t.toml", DISC, &[], &files).expect("valid");
    let mesh = &scene.cloths[0].mesh;
    let center = weft_solver::glam::DVec3::new(0.0, 0.5, 0.0);
    let full = std::f64::consts::PI * 0.15 * 0.15;
    assert!(mesh.grid.is_none());
    assert!(
        mesh.area() > 0.97 * full && mesh.area() < full,
        "{}",
        mesh.area()
    );
    assert!(
        mesh.positions
            .iter()
            .all(|p| p.distance(center) <= 0.15 + 1e-12)
    );
    // The clamp, and nothing else: vertex 0 of the grid (a corner) was cut away with its
    // `held` entry.
    let clamped: Vec<u32> = (0..mesh.len() as u32)
        .filter(|&i| mesh.positions[i as usize].distance(center) <= 0.09)
        .collect();
    assert!(clamped.len() > 100, "{}", clamped.len());
    assert_eq!(mesh.pinned, clamped);
    assert!(scene.cloths[0].held.is_empty());
    // The shipped test loads as a disc too.
    let shipped = weft_scene::load(&common::scenes_dir().join("cusick.toml"), &[]).expect("valid");
    assert!(shipped.cloths[0].mesh.grid.is_none());
}

#[test]
fn bad_disc_keys_name_their_line_and_key() {
    let with = |radius: &str, clamp: &str| {
        DISC.replace("disc_radius = 0.15", radius)
            .replace("clamp_radius = 0.09", clamp)
    };
    common::assert_errors(&[
        (
            with("disc_radius = 0.2", "clamp_radius = 0.09"),
            7,
            "cloth.specimen.disc_radius",
            "at most half the grid's shorter side",
        ),
        (
            with("disc_radius = -0.1", "clamp_radius = 0.0"),
            7,
            "cloth.specimen.disc_radius",
            "> 0",
        ),
        (
            with("disc_radius = nan", "clamp_radius = 0.09"),
            7,
            "cloth.specimen.disc_radius",
            "finite",
        ),
        (
            with("disc_radius = 0.15", "clamp_radius = 0.15"),
            8,
            "cloth.specimen.clamp_radius",
            "less than disc_radius",
        ),
        (
            with("", "clamp_radius = 0.09"),
            8,
            "cloth.specimen.clamp_radius",
            "without a `disc_radius`",
        ),
    ]);
}
