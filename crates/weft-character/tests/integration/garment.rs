//! Garments from flat panels: triangulation to a target edge length, preserved panel areas,
//! seam vertex pairs matched in order and count, and errors that name their line.

use crate::common;

use common::tube_garment;
use glam::DVec2;
use weft_character::files::{LoadError, read_garment};
use weft_character::garment::{Garment, GarmentError, GarmentSpec, build_garment};

/// A tube: front and back rectangles (0.4 m × 0.5 m) facing each other 0.3 m apart, sewn
/// at both sides.
fn tube() -> String {
    tube_garment(0.2, 0.5, 0.5, 0.15, 0.15)
}

fn build(text: &str) -> Garment {
    build_garment(&GarmentSpec::from_toml(text).expect("valid garment")).expect("garment")
}

fn edge_lengths(g: &Garment) -> Vec<f64> {
    g.mesh
        .stretch
        .iter()
        .map(|&[a, b]| (g.mesh.positions[a as usize] - g.mesh.positions[b as usize]).length())
        .collect()
}

fn polygon_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    0.5 * (0..n)
        .map(|k| p[k].perp_dot(p[(k + 1) % n]))
        .sum::<f64>()
        .abs()
}

#[test]
fn panels_are_triangulated_to_the_target_edge_length() {
    let g = build(&tube());
    let h = 0.03;
    let lengths = edge_lengths(&g);
    let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
    let max = lengths.iter().copied().fold(0.0, f64::max);
    let min = lengths.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(mean > 0.9 * h && mean < 1.1 * h, "mean edge {mean}");
    assert!(max < 1.8 * h, "longest edge {max}");
    assert!(min > 0.5 * h, "shortest edge {min}");
    // Refinement removes slivers: no angle under 20° (spade aims at 25°).
    for t in &g.mesh.triangles {
        let p = t.map(|i| g.mesh.positions[i as usize]);
        for k in 0..3 {
            let angle = (p[(k + 1) % 3] - p[k]).angle_between(p[(k + 2) % 3] - p[k]);
            assert!(
                angle.to_degrees() > 20.0,
                "a {}° corner",
                angle.to_degrees()
            );
        }
    }
    // Finer target, more triangles, shorter edges: the length is a real control.
    let fine = build(&tube().replace("edge_length = 0.03", "edge_length = 0.015"));
    let fine_mean = edge_lengths(&fine).iter().sum::<f64>() / fine.mesh.stretch.len() as f64;
    assert!(
        (fine_mean / mean - 0.5).abs() < 0.1,
        "{fine_mean} vs {mean}"
    );
    assert!(fine.mesh.triangles.len() > 3 * g.mesh.triangles.len());
}

#[test]
fn panel_areas_and_masses_are_preserved() {
    let g = build(&tube());
    assert!(
        (g.mesh.area() - 2.0 * 0.4 * 0.5).abs() < 1e-12,
        "{}",
        g.mesh.area()
    );
    assert!((g.mesh.total_mass() - 0.15 * 0.4).abs() < 1e-12);
    // A non-convex outline: a T-shirt front, body and sleeves, sleeves sloping.
    let shirt = r#"edge_length = 0.025
[[panel]]
name = "front"
outline = [[-0.25, 0.0], [0.25, 0.0], [0.25, 0.45], [0.45, 0.35], [0.52, 0.5],
           [0.22, 0.68], [-0.22, 0.68], [-0.52, 0.5], [-0.45, 0.35], [-0.25, 0.45]]
"#;
    let g = build(shirt);
    let spec = GarmentSpec::from_toml(shirt).expect("spec");
    let outline: Vec<DVec2> = spec.panels[0]
        .outline
        .iter()
        .map(|&c| DVec2::from_array(c))
        .collect();
    let want = polygon_area(&outline);
    assert!(
        (g.mesh.area() - want).abs() < 1e-12 * want.max(1.0),
        "{} vs {want}",
        g.mesh.area()
    );
    // Every triangle lies in the panel's plane with its front (+z) facing out.
    for t in &g.mesh.triangles {
        let [a, b, c] = t.map(|i| g.mesh.positions[i as usize]);
        assert!((b - a).cross(c - a).z > 0.0);
    }
    // The flat coordinates are the outline samples first, in order.
    assert_eq!(g.panels[0].flat[0], outline[0]);
    assert!(g.panels[0].boundary >= outline.len());
}

#[test]
fn seam_pairs_match_in_order_and_count() {
    let g = build(&tube());
    let h = 0.03;
    let pieces = (0.5_f64 / h).ceil() as usize;
    assert_eq!(g.seams.len(), 2);
    for seam in &g.seams {
        assert_eq!(
            seam.len(),
            pieces + 1,
            "one pair per vertex along the 0.5 m side"
        );
        let pairs = &g.seam_pairs[seam.clone()];
        let direction = if seam.start == 0 { 1.0 } else { -1.0 };
        let mut last_y = f64::NEG_INFINITY;
        for &[a, b] in pairs {
            let (pa, pb) = (g.mesh.positions[a as usize], g.mesh.positions[b as usize]);
            // Paired vertices face each other across the tube: same x and y, 0.3 m apart.
            assert!(
                (pa.x - pb.x).abs() < 1e-12 && (pa.y - pb.y).abs() < 1e-12,
                "{pa} {pb}"
            );
            assert!(((pa.z - pb.z).abs() - 0.3).abs() < 1e-12);
            // Side a of seam 1 runs up the front's right edge, of seam 2 down its left.
            assert!(direction * pa.y > last_y, "pairs run in order along side a");
            last_y = direction * pa.y;
        }
        // Consecutive pairs are one piece apart along the seam.
        let step = (g.mesh.positions[pairs[1][0] as usize]
            - g.mesh.positions[pairs[0][0] as usize])
            .length();
        assert!((step - 0.5 / pieces as f64).abs() < 1e-12);
    }
    let a: Vec<u32> = g.seam_pairs.iter().map(|p| p[0]).collect();
    assert!(
        a.iter().all(|&v| v < g.panels[0].vertices.end),
        "side a is the front"
    );
}

#[test]
fn sides_of_different_lengths_get_the_same_count_spread_by_length() {
    // A gathered seam: the front's 0.5 m top edge to the 0.35 m + 0.15 m of the back's top
    // two edges (a notch corner in the back's top).
    let text = r#"edge_length = 0.04
[[panel]]
name = "front"
outline = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.3], [0.0, 0.3]]
[[panel]]
name = "back"
outline = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.3], [0.35, 0.3], [0.0, 0.3]]
position = [0.0, 0.0, -0.1]
[[seam]]
a = { panel = "front", edges = [2, 2] }
b = { panel = "back", edges = [2, 3] }
"#;
    let g = build(text);
    let pairs = &g.seam_pairs[g.seams[0].clone()];
    let n = (0.5_f64 / 0.04).ceil() as usize;
    assert_eq!(pairs.len(), n + 1);
    for (i, &[a, b]) in pairs.iter().enumerate() {
        let (pa, pb) = (g.mesh.positions[a as usize], g.mesh.positions[b as usize]);
        // Both sides run from x = 0.5 to x = 0 along y = 0.3.
        assert!((pa.y - 0.3).abs() < 1e-12 && (pb.y - 0.3).abs() < 1e-12);
        assert!((pa.x - 0.5 * (1.0 - i as f64 / n as f64)).abs() < 1e-12);
    }
    let back_x: Vec<f64> = pairs
        .iter()
        .map(|p| g.mesh.positions[p[1] as usize].x)
        .collect();
    assert!(
        back_x.iter().any(|&x| (x - 0.35).abs() < 1e-12),
        "{back_x:?}"
    );
    assert!(back_x.windows(2).all(|w| w[1] < w[0]), "{back_x:?}");
}

fn error_of(text: &str) -> GarmentError {
    let spec = match GarmentSpec::from_toml(text) {
        Ok(s) => s,
        Err(e) => return e,
    };
    match build_garment(&spec) {
        Ok(_) => panic!("bad garment accepted:\n{text}"),
        Err(e) => e,
    }
}

fn key_line(e: &GarmentError) -> (&'static str, Option<usize>) {
    match e {
        GarmentError::Key { key, line, .. } => (key, *line),
        other => panic!("expected a key error, got {other}"),
    }
}

#[test]
fn bad_garments_name_their_key_and_line() {
    let e = error_of(&tube().replace(
        "b = { panel = \"back\", edges = [3, 3] }",
        "b = { panel = \"bak\", edges = [3, 3] }",
    ));
    assert_eq!(key_line(&e), ("b", Some(18)));
    assert!(
        e.to_string().contains("seam 1") && e.to_string().contains("bak"),
        "{e}"
    );
    let e = error_of(&tube().replace("edges = [3, 3] }\nflip", "edges = [4, 4] }\nflip"));
    assert_eq!(key_line(&e), ("b", Some(18)));
    let e = error_of(&tube().replace(
        "a = { panel = \"front\", edges = [3, 3] }",
        "a = { panel = \"front\", edges = [1, 1] }",
    ));
    assert_eq!(key_line(&e), ("a", Some(22)));
    assert!(e.to_string().contains("already in seam 1"), "{e}");
    let bow_tie = tube().replacen(
        "[[-0.2, 0.0], [0.2, 0.0], [0.2, 0.5], [-0.2, 0.5]]",
        "[[-0.2, 0.0], [0.2, 0.5], [0.2, 0.0], [-0.2, 0.5]]",
        1,
    );
    let e = error_of(&bow_tie);
    assert_eq!(key_line(&e), ("outline", Some(6)));
    assert!(e.to_string().contains("crosses itself"), "{e}");
    let repeated = tube().replacen("[[-0.2, 0.0], [0.2, 0.0],", "[[-0.2, 0.0], [-0.2, 0.0],", 1);
    assert_eq!(key_line(&error_of(&repeated)), ("outline", Some(6)));
    let two = tube().replacen(
        "[[-0.2, 0.0], [0.2, 0.0], [0.2, 0.5], [-0.2, 0.5]]",
        "[[-0.2, 0.0], [0.2, 0.0]]",
        1,
    );
    assert_eq!(key_line(&error_of(&two)), ("outline", Some(6)));
    let e = error_of(&tube().replace("edge_length = 0.03", "edge_length = -0.03"));
    assert_eq!(key_line(&e), ("edge_length", Some(1)));
    let e = error_of(&tube().replace("edge_length = 0.03", "edge_length = 1e-5"));
    assert_eq!(key_line(&e), ("edge_length", Some(1)));
    let e = error_of(&tube().replace("name = \"back\"", "name = \"front\""));
    assert_eq!(key_line(&e), ("name", Some(10)));
    for (text, line) in [
        (
            tube().replace("flip = true\n\n[[seam]]", "flip = 1\n\n[[seam]]"),
            19,
        ),
        (
            tube().replace("position = [0.0, 0.5, 0.15]", "position = [0.0, 0.5]"),
            7,
        ),
        (tube().replace("area_density = 0.15", "density = 0.15"), 2),
    ] {
        match error_of(&text) {
            GarmentError::Toml { line: Some(l), .. } => assert_eq!(l, line, "{text}"),
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn garment_files_name_the_file() {
    let dir = std::env::temp_dir().join(format!("weft-character-garment-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("tube.toml");
    std::fs::write(
        &path,
        tube().replace("edge_length = 0.03", "edge_length = \"fine\""),
    )
    .expect("write");
    let e = read_garment(&path).expect_err("bad garment accepted");
    assert!(matches!(e, LoadError::Garment { .. }));
    assert!(
        e.to_string().contains("tube.toml") && e.to_string().contains("line 1"),
        "{e}"
    );
    std::fs::write(&path, tube()).expect("write");
    let spec = read_garment(&path).expect("good garment");
    assert_eq!(spec.panels.len(), 2);
    std::fs::remove_dir_all(&dir).ok();
}

/// The tube with its front panel's third corner at `corner` and edge length `h`.
fn hostile(corner: &str, h: &str) -> String {
    tube()
        .replacen("[0.2, 0.5]", corner, 1)
        .replace("edge_length = 0.03", &format!("edge_length = {h}"))
}

#[test]
fn outlines_and_edge_lengths_beyond_physical_limits_are_refused_before_allocating() {
    // Each of these hung, aborted on a huge allocation or panicked on "capacity overflow".
    for (corner, h, key) in [
        ("[1e308, 0.8]", "0.03", "outline"),
        ("[1e11, 0.8]", "0.03", "outline"),
        ("[-1e6, 0.8]", "1e-300", "edge_length"),
        ("[0.2, 0.5]", "1e-9", "edge_length"),
        ("[0.2, 0.5]", "1e-8", "edge_length"),
        // Inside every limit on its own, but 99 m × 0.5 m at 1 mm is 1e8 vertices.
        ("[99.0, 0.5]", "1e-3", "edge_length"),
    ] {
        let text = hostile(corner, h);
        let e = error_of(&text);
        let line = if key == "edge_length" { 1 } else { 6 };
        assert_eq!(key_line(&e), (key, Some(line)), "{corner} {h}: {e}");
    }
    let e = error_of(&hostile("[1e11, 0.8]", "0.03")).to_string();
    assert!(e.contains("corner 2") && e.contains("100 m"), "{e}");
    let e = error_of(&hostile("[0.2, 0.5]", "1e-8")).to_string();
    assert!(e.contains("shortest edge"), "{e}");
    let e = error_of(&hostile("[99.0, 0.5]", "1e-3")).to_string();
    assert!(e.contains("vertices") && e.contains("2000000"), "{e}");
    // The largest panel the limits allow still builds at a sensible edge length.
    let big = build(&hostile("[0.2, 3.0]", "0.05").replacen("[-0.2, 0.5]", "[-0.2, 3.0]", 1));
    assert!(
        big.mesh.positions.len() > 200,
        "{}",
        big.mesh.positions.len()
    );
}
