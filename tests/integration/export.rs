//! `weft export`, read back: OBJ files parsed by hand, the GLB by the `gltf` crate (validated),
//! both compared with the log's positions and the colliders' analytic motion; frame choice,
//! refusals (truncated log, an output that is the log, a file as the directory) and stopping.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::Duration;

use common::*;

/// A 30-frame log of [`MOVING`] and its final positions (float32), in `dir`.
fn moving_log(dir: &Path, extra: &[&str]) -> (PathBuf, Vec<[f32; 3]>) {
    let scene = write(dir, "moving.toml", MOVING);
    let log = dir.join("m.mcap");
    let json = dir.join("final.json");
    let mut args = vec![
        "run".to_owned(),
        scene,
        "--frames".into(),
        "30".into(),
        "--out".into(),
        log.to_string_lossy().into_owned(),
        "--dump-final".into(),
        json.to_string_lossy().into_owned(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let out = weft().args(&args).output().expect("weft starts");
    assert!(out.status.success(), "{:?}", texts(&out));
    let dumped: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parses");
    let last = serde_json::from_value(dumped["cloths"]["sheet"].clone()).expect("positions");
    (log, last)
}

fn export(log: &Path, out: &Path, more: &[&str]) -> std::process::Output {
    let mut args = vec![
        "export".to_owned(),
        log.to_string_lossy().into_owned(),
        "--out".into(),
        out.to_string_lossy().into_owned(),
    ];
    args.extend(more.iter().map(|s| s.to_string()));
    weft().args(&args).output().expect("weft starts")
}

/// An OBJ object: name, vertices, faces as 0-based indices into the file's vertices.
type Object = (String, Vec<[f32; 3]>, Vec<[usize; 3]>);

/// An OBJ file's objects and its normal count.
struct Obj {
    objects: Vec<Object>,
    normals: usize,
}

fn parse_obj(path: &Path) -> Obj {
    let text = std::fs::read_to_string(path).expect("an OBJ file");
    let mut objects: Vec<Object> = Vec::new();
    let mut normals = 0;
    for line in text.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("o") => objects.push((w.next().expect("a name").into(), vec![], vec![])),
            Some("v") => {
                let v: Vec<f32> = w.map(|x| x.parse().expect("a float")).collect();
                let o = objects.last_mut().expect("v inside an object");
                o.1.push([v[0], v[1], v[2]]);
            }
            Some("vn") => normals += 1,
            Some("f") => {
                let f: Vec<usize> = w
                    .map(|c| {
                        let (v, n) = c.split_once("//").expect("v//vn");
                        assert_eq!(v, n, "each vertex has its normal");
                        v.parse::<usize>().expect("an index") - 1
                    })
                    .collect();
                let o = objects.last_mut().expect("f inside an object");
                o.2.push([f[0], f[1], f[2]]);
            }
            Some("g" | "#") | None => {}
            Some(other) => panic!("unexpected OBJ statement {other}"),
        }
    }
    Obj { objects, normals }
}

fn centroid(v: &[[f32; 3]]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for p in v {
        for k in 0..3 {
            c[k] += p[k] as f64 / v.len() as f64;
        }
    }
    c
}

/// Where [`MOVING`]'s ball is at time `t`.
fn ball_at(t: f64) -> [f64; 3] {
    [0.3 * t, 0.5, -0.1 * t]
}

fn near(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < tol)
}

#[test]
fn obj_sequence_holds_every_frame_with_the_logged_positions() {
    let dir = temp_dir("export-obj");
    let (log, last) = moving_log(&dir, &[]);
    let out = dir.join("objs");
    let o = export(&log, &out, &["--format", "obj"]);
    assert!(o.status.success(), "{:?}", texts(&o));
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .expect("the directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let want: Vec<String> = (0..=30).map(|f| format!("frame_{f:05}.obj")).collect();
    assert_eq!(names, want, "one file per frame, no partial left");
    let obj = parse_obj(&out.join("frame_00030.obj"));
    let objects: Vec<&str> = obj.objects.iter().map(|o| o.0.as_str()).collect();
    assert_eq!(
        objects,
        [
            "cloth/sheet",
            "collider/ball",
            "collider/rod",
            "collider/box",
            "collider/ground"
        ]
    );
    let vertices: usize = obj.objects.iter().map(|o| o.1.len()).sum();
    assert_eq!(obj.normals, vertices);
    // The cloth: exactly the logged float32 positions, 8 × 8 particles, 2 × 7 × 7 triangles.
    let cloth = &obj.objects[0];
    assert_eq!(cloth.1, last);
    assert_eq!(cloth.2.len(), 98);
    let mut base = 0;
    for o in &obj.objects {
        let n = o.1.len();
        assert!(
            o.2.iter().flatten().all(|&i| i >= base && i < base + n),
            "{}: faces use their own vertices",
            o.0
        );
        base += n;
    }
    // The ball where its motion puts it at t = 0.5 s; the box's 8 corners around its centre.
    let ball = centroid(&obj.objects[1].1);
    assert!(near(ball, ball_at(0.5), 1e-5), "{ball:?}");
    assert_eq!(obj.objects[3].1.len(), 8);
    assert!(near(centroid(&obj.objects[3].1), [-1.0, 0.3, 0.0], 1e-6));
}

#[test]
fn a_log_without_surfaces_takes_its_triangles_from_the_scene() {
    let dir = temp_dir("export-obj-nomesh");
    let (log, last) = moving_log(&dir, &["--mesh-every", "0"]);
    assert!(!read_log(&log).counts.contains_key("/cloth/sheet/mesh"));
    let out = dir.join("objs");
    let o = export(&log, &out, &["--format", "obj", "--frames", "30.."]);
    assert!(o.status.success(), "{:?}", texts(&o));
    let obj = parse_obj(&out.join("frame_00030.obj"));
    assert_eq!(obj.objects[0].1, last);
    assert_eq!(obj.objects[0].2.len(), 98);
    assert_eq!(std::fs::read_dir(&out).expect("dir").count(), 1);
}

/// The cloth's positions at each exported frame as the GLB gives them: base + Σ wᵢ targetᵢ
/// with the weights of the frame's key, and the ball's translation per key.
struct GlbRead {
    times: Vec<f32>,
    cloth: Vec<Vec<[f32; 3]>>,
    ball: Vec<[f32; 3]>,
    target_names: Vec<String>,
    triangles: usize,
    interpolations: Vec<gltf::animation::Interpolation>,
}

fn read_glb(path: &Path) -> GlbRead {
    let bytes = std::fs::read(path).expect("the GLB");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid glTF binary");
    let blob = gltf.blob.clone().expect("a BIN chunk");
    let get = |_: gltf::Buffer<'_>| Some(blob.as_slice());
    let nodes: Vec<_> = gltf.nodes().collect();
    let names: Vec<&str> = nodes.iter().map(|n| n.name().expect("named")).collect();
    assert_eq!(
        names,
        [
            "cloth/sheet",
            "collider/ball",
            "collider/rod",
            "collider/box",
            "collider/ground"
        ]
    );
    let mesh = nodes[0].mesh().expect("the cloth's mesh");
    let prim = mesh.primitives().next().expect("a primitive");
    let reader = prim.reader(get);
    let base: Vec<[f32; 3]> = reader.read_positions().expect("positions").collect();
    let triangles = reader.read_indices().expect("indices").into_u32().count() / 3;
    let targets: Vec<Vec<[f32; 3]>> = reader
        .read_morph_targets()
        .map(|(p, _, _)| p.expect("position displacements").collect())
        .collect();
    let anims: Vec<_> = gltf.animations().collect();
    assert_eq!(anims.len(), 1);
    let mut times = Vec::new();
    let mut weights = Vec::new();
    let mut ball = Vec::new();
    let mut animated = Vec::new();
    let mut interpolations = Vec::new();
    for ch in anims[0].channels() {
        interpolations.push(ch.sampler().interpolation());
        let r = ch.reader(get);
        let input: Vec<f32> = r.read_inputs().expect("inputs").collect();
        let node = ch.target().node().index();
        animated.push((node, format!("{:?}", ch.target().property())));
        match r.read_outputs().expect("outputs") {
            gltf::animation::util::ReadOutputs::MorphTargetWeights(
                gltf::animation::util::MorphTargetWeights::F32(w),
            ) => {
                assert_eq!(node, 0);
                weights = w.collect();
                times = input;
            }
            gltf::animation::util::ReadOutputs::Translations(t) if node == 1 => {
                ball = t.collect();
                assert_eq!(ball.len(), input.len());
            }
            _ => {}
        }
    }
    // The ball moves and the rod oscillates; the box and the ground stand still.
    animated.sort();
    assert_eq!(
        animated,
        [
            (0, "MorphTargetWeights".to_owned()),
            (1, "Translation".to_owned()),
            (2, "Translation".to_owned())
        ]
    );
    let t = targets.len();
    assert_eq!(
        weights.len(),
        times.len() * t,
        "a weight per target per key"
    );
    let cloth = (0..times.len())
        .map(|k| {
            base.iter()
                .enumerate()
                .map(|(i, b)| {
                    let mut p = *b;
                    for (j, target) in targets.iter().enumerate() {
                        for c in 0..3 {
                            p[c] += weights[k * t + j] * target[i][c];
                        }
                    }
                    p
                })
                .collect()
        })
        .collect();
    let (json, _) = {
        let glb = gltf::binary::Glb::from_slice(&bytes).expect("GLB chunks");
        (glb.json.into_owned(), ())
    };
    let json: serde_json::Value = serde_json::from_slice(&json).expect("JSON");
    let target_names = serde_json::from_value(json["meshes"][0]["extras"]["targetNames"].clone())
        .expect("target names");
    GlbRead {
        times,
        cloth,
        ball,
        target_names,
        triangles,
        interpolations,
    }
}

#[test]
fn glb_animates_the_logged_cloth_and_the_moving_colliders() {
    let dir = temp_dir("export-glb");
    let (log, last) = moving_log(&dir, &[]);
    let out = dir.join("glb");
    let o = export(&log, &out, &["--format", "glb"]);
    assert!(o.status.success(), "{:?}", texts(&o));
    let g = read_glb(&out.join("m.glb"));
    assert_eq!(g.times.len(), 31, "a key per frame");
    assert_eq!(
        g.target_names.len(),
        30,
        "a morph target per frame after the first"
    );
    assert_eq!(g.target_names[29], "frame_00030");
    assert_eq!(g.triangles, 98);
    assert_eq!(
        g.interpolations,
        [gltf::animation::Interpolation::Linear; 3]
    );
    for (k, t) in g.times.iter().enumerate() {
        assert!((*t as f64 - k as f64 / 60.0).abs() < 1e-6, "key {k} at {t}");
        let b = g.ball[k].map(f64::from);
        assert!(near(b, ball_at(k as f64 / 60.0), 1e-6), "key {k}: {b:?}");
    }
    // The last key's positions are the log's last frame (to float32 rounding of base + Δ).
    let worst = g.cloth[30]
        .iter()
        .zip(&last)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-6, "GLB differs from the log by {worst} m");
    assert!(g.cloth[0] != g.cloth[30], "the cloth moves");
    // The same log gives the same bytes.
    let again = dir.join("again");
    let o = export(&log, &again, &["--format", "glb", "-q"]);
    assert!(o.status.success(), "{:?}", texts(&o));
    assert!(o.stdout.is_empty(), "--quiet says nothing");
    let bytes = |d: &Path| std::fs::read(d.join("m.glb")).expect("the GLB");
    assert!(bytes(&out) == bytes(&again), "two exports differ");
}

#[test]
fn frames_and_every_choose_the_keys() {
    let dir = temp_dir("export-glb-range");
    let (log, _) = moving_log(&dir, &[]);
    let out = dir.join("glb");
    let o = export(
        &log,
        &out,
        &[
            "--format",
            "glb",
            "--frames",
            "10..=20",
            "--every",
            "5",
            "--interpolation",
            "step",
        ],
    );
    assert!(o.status.success(), "{:?}", texts(&o));
    let g = read_glb(&out.join("m.glb"));
    assert_eq!(g.interpolations, [gltf::animation::Interpolation::Step; 3]);
    assert_eq!(g.target_names, ["frame_00015", "frame_00020"]);
    let want = [0.0, 5.0 / 60.0, 10.0 / 60.0];
    for (k, t) in g.times.iter().enumerate() {
        assert!((*t as f64 - want[k]).abs() < 1e-6, "{:?}", g.times);
        // Times start at 0 for the first frame exported: frame 10 + 5k.
        let b = g.ball[k].map(f64::from);
        assert!(
            near(b, ball_at((10.0 + 5.0 * k as f64) / 60.0), 1e-6),
            "{b:?}"
        );
    }
    let o = export(&log, &out, &["--format", "obj", "--frames", "40.."]);
    let (_, e) = texts(&o);
    assert!(!o.status.success());
    assert!(e.contains("holds frames 0..=30: none in --frames"), "{e}");
}

#[test]
fn bad_logs_and_outputs_are_refused_naming_the_file() {
    let dir = temp_dir("export-refusals");
    let (log, _) = moving_log(&dir, &[]);
    // A log cut short.
    let bytes = std::fs::read(&log).expect("log");
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).expect("write");
    let out = dir.join("out");
    let o = export(&cut, &out, &["--format", "obj"]);
    let (_, e) = texts(&o);
    assert!(!o.status.success());
    assert!(
        e.contains("cut.mcap is truncated") && e.contains("weft recover"),
        "{e}"
    );
    assert!(!out.exists() || std::fs::read_dir(&out).expect("dir").count() == 0);
    // The GLB would be the log itself.
    let glb_named = dir.join("run.glb");
    std::fs::copy(&log, &glb_named).expect("copy");
    let o = export(&glb_named, &dir, &["--format", "glb"]);
    let (_, e) = texts(&o);
    assert!(!o.status.success());
    assert!(e.contains("refusing to overwrite an input"), "{e}");
    assert_eq!(std::fs::read(&glb_named).expect("kept"), bytes);
    // A file where the directory should be.
    let file = dir.join("a-file");
    std::fs::write(&file, "x").expect("write");
    let o = export(&log, &file, &["--format", "obj"]);
    let (_, e) = texts(&o);
    assert!(!o.status.success());
    assert!(e.contains("a-file is not a directory"), "{e}");
    // A directory that cannot be made.
    let o = export(&log, &file.join("sub"), &["--format", "obj"]);
    let (_, e) = texts(&o);
    assert!(!o.status.success());
    assert!(e.contains("a-file/sub"), "{e}");
    // Memory: a limit below the log's own size.
    let o = export(&log, &out, &["--format", "glb", "--max-memory", "1K"]);
    let (_, e) = texts(&o);
    assert!(!o.status.success());
    assert!(e.contains("--max-memory") && e.contains("--every"), "{e}");
}

#[test]
fn sigint_stops_an_export_within_a_second_leaving_whole_files() {
    let dir = temp_dir("export-stop");
    let scene = write(&dir, "big.toml", &big(64));
    let log = dir.join("big.mcap");
    let o = run(&[
        "run",
        &scene,
        "--frames",
        "200",
        "--mesh-every",
        "0",
        "--set",
        "sim.substeps=1",
        "--out",
        &log.to_string_lossy(),
    ]);
    assert!(o.status.success(), "{:?}", texts(&o));
    let out = dir.join("objs");
    let child = weft()
        .args(["export", &log.to_string_lossy(), "--format", "obj", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    assert!(
        wait_for(Duration::from_secs(60), || out
            .join("frame_00001.obj")
            .exists()),
        "the export never wrote a file"
    );
    signal(child.id(), "INT");
    let (o, took) = exits_within(child, Duration::from_secs(60));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(took < Duration::from_secs(3), "took {took:?} to stop: {e}");
    assert_eq!(o.status.code(), Some(130), "{e}");
    let files: Vec<PathBuf> = std::fs::read_dir(&out)
        .expect("dir")
        .map(|e| e.expect("entry").path())
        .collect();
    assert!(files.len() < 201, "stopped before the end");
    for f in &files {
        let name = f.file_name().expect("name").to_string_lossy();
        assert!(!name.contains("partial"), "a partial left: {name}");
        let obj = parse_obj(f);
        assert_eq!(obj.objects[0].1.len(), 64 * 64, "{name} is whole");
    }
}
