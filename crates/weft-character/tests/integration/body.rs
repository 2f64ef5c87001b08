//! The mannequin body: table parsing and its errors, shapes following their bones, surface
//! velocities against finite differences.

use glam::DVec3;
use weft_character::files::{LoadError, read_body_table};
use weft_character::{Body, BodyError, BodyTable, Character, Geometry, walker_skeleton};

#[test]
fn the_walker_body_resolves_and_its_forearm_spans_elbow_to_wrist() {
    let walker = Character::walker();
    assert_eq!(walker.body().shapes().len(), 20);
    let skel = walker.animation().skeleton();
    let elbow = skel.find("LeftForeArm").expect("bone");
    let wrist = skel.find("LeftHand").expect("bone");
    let forearm = walker
        .body()
        .shapes()
        .iter()
        .position(|s| s.name == "left forearm")
        .expect("shape");
    for k in 0..7 {
        let t = 0.173 * k as f64;
        let state = walker.state(t);
        let world = walker.animation().world(t);
        let Geometry::RoundCone(c) = state.shapes[forearm].geometry else {
            panic!("the forearm is a round cone");
        };
        assert!((c.a - world[elbow].translation).length() < 1e-12);
        assert!((c.b - world[wrist].translation).length() < 1e-12);
        assert_eq!((c.ra, c.rb), (0.04, 0.03));
    }
}

#[test]
fn the_walker_body_covers_its_skeleton_all_through_the_cycle() {
    let walker = Character::walker();
    let skel = walker.animation().skeleton();
    for k in 0..40 {
        let state = walker.state(k as f64 * 0.0275);
        for (j, joint) in skel.joints().iter().enumerate() {
            let p = state.bones[j].transform.translation;
            let d = state.signed_distance(p);
            assert!(d < 0.0, "{} is outside the body by {d} m", joint.name);
        }
    }
}

#[test]
fn surface_velocities_match_finite_differences_of_surface_points() {
    let walker = Character::walker();
    let probe = DVec3::new(0.3, 1.0, 0.4);
    let delta = 1e-5;
    for t in [0.05, 0.41, 0.77] {
        let state = walker.state(t);
        let before = walker.animation().world(t - delta);
        let after = walker.animation().world(t + delta);
        for shape in &state.shapes {
            let surface = shape.contact(probe).point;
            let local = shape.motion.transform.inverse().transform_point(surface);
            let fd = (after[shape.bone].transform_point(local)
                - before[shape.bone].transform_point(local))
                / (2.0 * delta);
            let v = shape.point_velocity(surface);
            assert!(
                (v - fd).length() < 1e-6 * (1.0 + fd.length()),
                "shape {} at {t}: {v} vs {fd}",
                shape.shape
            );
        }
        // The swinging limbs move: hands and feet reach ≥ 0.3 m/s somewhere in the cycle.
        let fastest = state
            .shapes
            .iter()
            .map(|s| s.point_velocity(s.contact(probe).point).length())
            .fold(0.0, f64::max);
        assert!(fastest > 0.3, "fastest surface point {fastest} m/s at {t}");
    }
}

fn shape_error(text: &str) -> BodyError {
    let table = BodyTable::from_toml(text).expect("valid TOML");
    match Body::new(&walker_skeleton(), &table) {
        Ok(_) => panic!("bad table accepted:\n{text}"),
        Err(e) => e,
    }
}

fn key_and_line(e: &BodyError) -> (&'static str, Option<usize>) {
    match e {
        BodyError::Shape { key, line, .. } => (key, *line),
        BodyError::Toml { .. } => panic!("expected a shape error, got {e}"),
    }
}

#[test]
fn table_errors_name_the_shape_key_and_line() {
    let head = "[[shape]]\nbone = \"Head\"\nkind = \"sphere\"\nradius = 0.1\n\n";
    let e = shape_error(&format!(
        "{head}[[shape]]\nbone = \"LeftForArm\"\nkind = \"capsule\"\nradius = 0.04\n"
    ));
    assert_eq!(key_and_line(&e), ("bone", Some(7)));
    assert!(
        e.to_string().contains("shape 2") && e.to_string().contains("LeftForArm"),
        "{e}"
    );
    let e = shape_error(&format!(
        "{head}[[shape]]\nbone = \"LeftForeArm\"\nkind = \"round-cone\"\nr0 = -0.04\nr1 = 0.03\n"
    ));
    assert_eq!(key_and_line(&e), ("r0", Some(9)));
    assert!(e.to_string().starts_with("line 9: shape 2"), "{e}");
    let e = shape_error("[[shape]]\nbone = \"LeftForeArm\"\nkind = \"capsule\"\n");
    assert_eq!(key_and_line(&e), ("radius", Some(1)));
    let e = shape_error(
        "[[shape]]\nbone = \"LeftForeArm\"\nkind = \"capsule\"\nradius = 0.04\nr0 = 0.05\n",
    );
    assert_eq!(key_and_line(&e), ("r0", Some(5)));
    let e = shape_error("[[shape]]\nbone = \"Chest\"\nkind = \"capsule\"\nradius = 0.1\n");
    assert_eq!(key_and_line(&e), ("to", Some(1)));
    assert!(e.to_string().contains("3 children"), "{e}");
    let e = shape_error(
        "[[shape]]\nbone = \"Chest\"\nkind = \"capsule\"\nradius = 0.1\nto = \"Head\"\n",
    );
    assert_eq!(key_and_line(&e), ("to", Some(5)));
    let e = shape_error(
        "[[shape]]\nbone = \"Neck\"\nkind = \"capsule\"\nradius = 0.1\nto = \"Head\"\nend = [0, 1, 0]\n",
    );
    assert_eq!(key_and_line(&e), ("end", Some(6)));
    let e = shape_error(
        "[[shape]]\nbone = \"Head\"\nkind = \"sphere\"\nradius = 0.1\nstart = [0, nan, 0]\n",
    );
    assert_eq!(key_and_line(&e), ("start", Some(5)));
}

#[test]
fn malformed_toml_names_its_line() {
    for (text, line) in [
        (
            "[[shape]]\nbone = \"Head\"\nkind = \"blob\"\nradius = 0.1\n",
            3,
        ),
        (
            "[[shape]]\nbone = \"Head\"\nkind = \"sphere\"\nradius = 0.1\ncolour = 1\n",
            5,
        ),
        (
            "[[shape]]\nbone = \"Head\"\nkind = \"sphere\"\nradius = \"big\"\n",
            4,
        ),
        (
            "[[shape]]\nbone = \"Head\"\nkind = \"sphere\"\nradius = 0.1\n[[shape]\n",
            5,
        ),
    ] {
        match BodyTable::from_toml(text) {
            Err(BodyError::Toml { line: Some(l), .. }) => assert_eq!(l, line, "{text}"),
            other => panic!("{text}: {other:?}"),
        }
    }
}

#[test]
fn body_table_files_name_the_file() {
    let dir = std::env::temp_dir().join(format!("weft-character-body-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bad = dir.join("body.toml");
    std::fs::write(&bad, "[[shape]]\nbone = 3\n").expect("write");
    let e = read_body_table(&bad).expect_err("bad table accepted");
    assert!(matches!(e, LoadError::Body { .. }));
    assert!(
        e.to_string().contains("body.toml") && e.to_string().contains("line 2"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_culled_nearest_shape_is_the_exhaustive_one() {
    let walker = Character::walker();
    let state = walker.state(0.61);
    let mut k = 0u64;
    for i in 0..4000 {
        k = k
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let r = |s: u32| ((k >> s) & 0xffff) as f64 / 65535.0;
        let p = DVec3::new(r(0) - 0.5, 1.8 * r(16), r(32) - 0.5);
        let exhaustive = state
            .shapes
            .iter()
            .map(|s| s.contact(p).distance)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(state.signed_distance(p), exhaustive, "point {i} at {p}");
        // Each shape's bounding sphere holds it: its distance is never below the bound.
        for s in &state.shapes {
            let (c, r) = s.geometry.bounding_sphere();
            assert!(s.contact(p).distance >= (p - c).length() - r - 1e-12);
        }
    }
}
