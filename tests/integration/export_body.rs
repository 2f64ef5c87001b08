//! The character's body in `weft export`, read back: each body part is an OBJ object whose
//! vertices lie on that part's surface at the frame's time (worked out by weft-character, apart
//! from the log), and a GLB node moved by translation and rotation keys.

use crate::common;

use std::path::Path;

use common::*;
use weft_character::{Character, Geometry};
use weft_solver::glam::DVec3;

/// The walker and a small cloth away from it (the log test in `crates/weft-record/src/body.rs` runs it too).
const WALKER: &str = include_str!("../fixtures/walker.toml");

/// Objects of an OBJ file: name and vertices.
fn objects(path: &Path) -> Vec<(String, Vec<DVec3>)> {
    let text = std::fs::read_to_string(path).expect("an OBJ file");
    let mut out: Vec<(String, Vec<DVec3>)> = Vec::new();
    for line in text.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("o") => out.push((w.next().expect("a name").into(), vec![])),
            Some("v") => {
                let v: Vec<f64> = w.map(|x| x.parse().expect("a number")).collect();
                let o = out.last_mut().expect("v inside an object");
                o.1.push(DVec3::new(v[0], v[1], v[2]));
            }
            _ => {}
        }
    }
    out
}

#[test]
fn the_body_is_exported_where_the_character_is_at_each_frame() {
    let dir = temp_dir("export-body");
    let log = logged_run(&dir, "walker.toml", WALKER, 30, "w.mcap");
    let objs = dir.join("obj");
    let out = run(&[
        "export",
        &log.to_string_lossy(),
        "--format",
        "obj",
        "--every",
        "10",
        "--out",
        &objs.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let walker = Character::walker();
    let shapes = walker.body().shapes().len();
    for frame in [0u32, 10, 20, 30] {
        let t = f64::from(frame) / 60.0;
        let state = walker.state(t);
        let objects = objects(&objs.join(format!("frame_{frame:05}.obj")));
        assert_eq!(objects.len(), 1 + shapes, "the cloth and every body part");
        for (i, s) in state.shapes.iter().enumerate() {
            let (name, vertices) = &objects[1 + i];
            assert_eq!(name, &format!("collider/body/{i}"));
            assert!(!vertices.is_empty());
            for &v in vertices {
                // OBJ numbers are float32: a few µm.
                let d = match s.geometry {
                    Geometry::Sphere { center, radius } => (v - center).length() - radius,
                    Geometry::RoundCone(c) => c.signed_distance(v),
                };
                assert!(d.abs() < 1e-5, "frame {frame}: {name}'s {v} is {d} m off");
            }
        }
    }
    let glb = dir.join("glb");
    let out = run(&[
        "export",
        &log.to_string_lossy(),
        "--format",
        "glb",
        "--out",
        &glb.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let gltf = gltf::Gltf::open(glb.join("w.glb")).expect("a glTF file");
    let moved: Vec<String> = gltf
        .animations()
        .flat_map(|a| a.channels().collect::<Vec<_>>())
        .filter(|c| c.target().property() == gltf::animation::Property::Rotation)
        .filter_map(|c| c.target().node().name().map(str::to_owned))
        .collect();
    for i in 0..shapes {
        assert!(moved.contains(&format!("collider/body/{i}")), "{moved:?}");
    }
}
