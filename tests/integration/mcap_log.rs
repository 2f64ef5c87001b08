//! Runs logged to MCAP: readable by the `mcap` crate, byte-identical on rerun and replay,
//! valid after SIGINT/SIGTERM and after divergence.

use crate::common;

use std::path::Path;
use std::time::Duration;

use common::*;

#[test]
fn log_holds_every_frame_and_matches_the_dumped_positions() {
    let dir = temp_dir("log");
    let scene = write(&dir, "small.toml", SMALL);
    let mcap = dir.join("a.mcap");
    let json = dir.join("a.json");
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "20",
        "--out",
        &mcap.to_string_lossy(),
        "--dump-final",
        &json.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(o.contains("20 frames, 0.333 s simulated"), "{o}");
    let log = read_log(&mcap);
    assert_eq!(log.counts["/cloth/flag/particles"], 21, "{:?}", log.counts);
    assert_eq!(log.counts["/cloth/flag/mesh"], 21);
    assert_eq!(log.counts["/stats"], 21);
    assert_eq!(log.metadata["weft.status"]["status"], "complete");
    assert_eq!(log.metadata["weft.run"]["frames"], "20");
    assert!(log.attachments.contains(&"scene/source.toml".to_owned()));
    let dumped: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parses");
    let expected: Vec<[f32; 3]> =
        serde_json::from_value(dumped["cloths"]["flag"].clone()).expect("positions");
    assert_eq!(log.last["/cloth/flag/particles"], expected);
    assert_eq!(expected.len(), 64);
}

#[test]
fn reruns_and_replays_are_byte_identical() {
    let dir = temp_dir("identical");
    let scene = write(&dir, "small.toml", SMALL);
    let paths: Vec<String> = ["a", "b"]
        .iter()
        .map(|n| dir.join(format!("{n}.mcap")).to_string_lossy().into_owned())
        .collect();
    for p in &paths {
        let out = run(&[
            "run",
            &scene,
            "--frames",
            "15",
            "--out",
            p,
            "--set",
            "sim.method=pbd",
        ]);
        assert!(out.status.success(), "{:?}", texts(&out));
    }
    let a = std::fs::read(&paths[0]).expect("a");
    assert_eq!(a, std::fs::read(&paths[1]).expect("b"), "reruns differ");
    let replayed = dir.join("r.mcap");
    let out = run(&["replay", &paths[0], "--out", &replayed.to_string_lossy()]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(o.contains("byte-identical"), "{o}");
    assert_eq!(a, std::fs::read(&replayed).expect("replay"));
    // A different input gives a different file.
    let out = run(&["run", &scene, "--frames", "15", "--out", &paths[1]]);
    assert!(out.status.success());
    assert_ne!(a, std::fs::read(&paths[1]).expect("b"));
}

#[test]
fn the_default_scene_is_hanging_toml() {
    let dir = temp_dir("default");
    let a = dir.join("a.json");
    let b = dir.join("b.json");
    let out = run(&["run", "--frames", "3", "--dump-final", &a.to_string_lossy()]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let out = run(&[
        "run",
        "assets/scenes/hanging.toml",
        "--frames",
        "3",
        "--dump-final",
        &b.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    assert_eq!(std::fs::read(a).expect("a"), std::fs::read(b).expect("b"));
}

fn interrupted_run_leaves_a_valid_log(signal: &str) {
    let dir = temp_dir(&format!("signal-{signal}"));
    let scene = write(&dir, "small.toml", SMALL);
    let mcap = dir.join("run.mcap");
    let child = spawn_logging(&["run", &scene, "--frames", "100000000"], &mcap);
    std::thread::sleep(Duration::from_millis(800));
    let kill = std::process::Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(kill.success());
    let out = child.wait_with_output().expect("exits");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted after"), "{err}");
    let log = read_log(&mcap);
    let status = &log.metadata["weft.status"];
    assert_eq!(status["status"], "interrupted");
    let frames: usize = status["frames"].parse().expect("number");
    assert!(frames > 0, "no frame simulated before the signal");
    assert_eq!(log.counts["/cloth/flag/particles"], frames + 1);
    assert_eq!(log.counts["/stats"], frames + 1);
}

#[test]
fn sigint_leaves_a_valid_log() {
    interrupted_run_leaves_a_valid_log("INT");
}

#[test]
fn sigterm_leaves_a_valid_log() {
    interrupted_run_leaves_a_valid_log("TERM");
}

#[test]
fn divergence_stops_with_a_message_and_a_valid_log() {
    let dir = temp_dir("diverge");
    let scene = write(&dir, "small.toml", SMALL);
    let mcap = dir.join("run.mcap");
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "100",
        "--out",
        &mcap.to_string_lossy(),
        "--set",
        "sim.method=mass-spring",
        "--set",
        "sim.substeps=1",
        "--set",
        "cloth.flag.stretch_spring_stiffness=1e7",
    ]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("mass-spring simulation diverged"), "{err}");
    let log = read_log(Path::new(&mcap));
    let status = &log.metadata["weft.status"];
    assert_eq!(status["status"], "diverged");
    assert!(status["message"].contains("diverged"));
    let frames: usize = status["frames"].parse().expect("number");
    assert!(frames < 100);
    assert_eq!(log.counts["/cloth/flag/particles"], frames + 1);
    for p in &log.last["/cloth/flag/particles"] {
        assert!(
            p.iter().all(|c| c.is_finite()),
            "a logged frame is not finite"
        );
    }
}

#[test]
fn scenes_with_several_methods_log_every_cloth() {
    let dir = temp_dir("compare");
    let mcap = dir.join("c.mcap");
    let out = run(&[
        "run",
        "assets/scenes/compare.toml",
        "--frames",
        "3",
        "--mesh-every",
        "0",
        "--set",
        "cloth.xpbd.resolution=[6, 6]",
        "--set",
        "cloth.pbd.resolution=[6, 6]",
        "--set",
        "cloth.springs.resolution=[6, 6]",
        "--set",
        "cloth.implicit.resolution=[6, 6]",
        "--out",
        &mcap.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let log = read_log(&mcap);
    for name in ["xpbd", "pbd", "springs", "implicit"] {
        assert_eq!(log.counts[&format!("/cloth/{name}/particles")], 4);
        assert_eq!(log.last[&format!("/cloth/{name}/particles")].len(), 36);
    }
    assert!(!log.counts.contains_key("/cloth/xpbd/mesh"));
    assert_eq!(
        log.metadata["weft.run"]["methods"],
        "implicit-mass-spring,pbd,mass-spring,xpbd"
    );
}

#[test]
fn colliders_are_logged_and_collide() {
    let dir = temp_dir("colliders");
    let mcap = dir.join("s.mcap");
    let json = dir.join("s.json");
    let out = run(&[
        "run",
        "assets/scenes/sphere_drop.toml",
        "--frames",
        "60",
        "--set",
        "cloth.sheet.resolution=[12, 12]",
        "--mesh-every",
        "0",
        "--out",
        &mcap.to_string_lossy(),
        "--dump-final",
        &json.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let log = read_log(&mcap);
    // Static colliders are logged once.
    assert_eq!(log.counts["/colliders"], 1);
    // The cloth's centre rests on the ball (top at y = 0.9) instead of falling through it.
    let centre = log.last["/cloth/sheet/particles"]
        .iter()
        .filter(|p| p[0].abs() < 0.1 && p[2].abs() < 0.1)
        .map(|p| p[1])
        .fold(f32::INFINITY, f32::min);
    assert!(centre > 0.85 && centre < 1.0, "centre at y = {centre}");
}

/// A skinned glTF character's body is on `/colliders` as the triangle list
/// `collider/body/model`, at the skinning of each logged frame's time (the scene's own
/// `SkinCollider`, placed), whenever the cloth meshes are logged.
#[test]
fn a_skinned_characters_body_is_logged_as_it_moves() {
    use foxglove::Decode;
    use foxglove::messages::SceneUpdate;
    let dir = temp_dir("glb-body");
    let mcap = dir.join("g.mcap");
    let scene = Path::new("assets/scenes/glb_character.toml");
    let out = run(&[
        "run",
        &scene.to_string_lossy(),
        "--frames",
        "6",
        "--mesh-every",
        "3",
        "--out",
        &mcap.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let skin = weft_scene::load(scene, &[])
        .expect("the scene")
        .model
        .expect("a model")
        .skin;
    let bytes = std::fs::read(&mcap).expect("log");
    let mut seen = Vec::new();
    for m in mcap::MessageStream::new(&bytes).expect("readable") {
        let m = m.expect("message");
        if m.channel.topic != "/colliders" {
            continue;
        }
        let update = SceneUpdate::decode(&m.data[..]).expect("a SceneUpdate");
        let Some(e) = update
            .entities
            .iter()
            .find(|e| e.id == "collider/body/model")
        else {
            continue;
        };
        let t = m.log_time as f64 * 1e-9;
        let want = skin.vertices(t);
        let points = &e.triangles[0].points;
        assert_eq!(points.len(), want.len());
        for (p, w) in points.iter().zip(&want) {
            let d = (weft_solver::glam::DVec3::new(p.x, p.y, p.z) - *w).length();
            assert!(d < 1e-6, "t = {t}: logged vertex {d} m from the skinning");
        }
        assert_eq!(
            e.triangles[0].indices.len(),
            3 * skin.mesh().triangles.len()
        );
        seen.push((t * 60.0).round() as u32);
    }
    assert_eq!(seen, vec![0, 3, 6], "frames logging the body");
}
