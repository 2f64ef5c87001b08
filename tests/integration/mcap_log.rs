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
    // By default the particles only: the surface is `--log all`'s.
    assert!(
        !log.counts.contains_key("/cloth/flag/mesh"),
        "{:?}",
        log.counts
    );
    assert_eq!(log.metadata["weft.run"]["log"], "particles");
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

/// Runs `SMALL` for 20 frames logged with `options`; returns the log and the dumped positions.
fn logged_with(dir: &Path, name: &str, options: &[&str]) -> (Log, Vec<[f32; 3]>) {
    let scene = write(dir, "small.toml", SMALL);
    let mcap = dir.join(format!("{name}.mcap"));
    let json = dir.join(format!("{name}.json"));
    let (mcap_arg, json_arg) = (mcap.to_string_lossy(), json.to_string_lossy());
    let mut args = vec![
        "run",
        &scene,
        "--frames",
        "20",
        "--out",
        &mcap_arg,
        "--dump-final",
        &json_arg,
    ];
    args.extend_from_slice(options);
    let out = run(&args);
    assert!(out.status.success(), "{options:?}: {:?}", texts(&out));
    let dumped: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parses");
    let expected = serde_json::from_value(dumped["cloths"]["flag"].clone()).expect("positions");
    (read_log(&mcap), expected)
}

/// Each logging choice gives the channels and frames it names, ending at the dumped state.
#[test]
fn logging_choices_give_the_channels_frames_and_precision_they_name() {
    let dir = temp_dir("log-choices");
    let (all, expected) = logged_with(&dir, "all", &["--log", "all", "--mesh-every", "2"]);
    assert_eq!(all.counts["/cloth/flag/particles"], 21);
    assert_eq!(all.counts["/cloth/flag/mesh"], 11);
    assert_eq!(all.last["/cloth/flag/particles"], expected);

    let (surface, _) = logged_with(&dir, "surface", &["--log", "surface"]);
    assert!(!surface.counts.contains_key("/cloth/flag/particles"));
    assert_eq!(surface.counts["/cloth/flag/mesh"], 21);

    // Every 6th frame (0, 6, 12, 18) and the last (20).
    let (every, _) = logged_with(&dir, "every", &["--every", "6"]);
    assert_eq!(every.counts["/cloth/flag/particles"], 5);
    assert_eq!(every.counts["/stats"], 5);
    assert_eq!(every.last["/cloth/flag/particles"], expected);
    assert_eq!(every.metadata["weft.run"]["every"], "6");

    let (zstd, _) = logged_with(&dir, "zstd", &["--compression", "zstd"]);
    assert_eq!(zstd.last["/cloth/flag/particles"], expected);
    assert_eq!(zstd.metadata["weft.run"]["compression"], "zstd");

    // Half floats: within 2^-11 of each coordinate (the flag hangs within 2 m of the origin).
    let (half, _) = logged_with(&dir, "half", &["--precision", "f16"]);
    let got = &half.last["/cloth/flag/particles"];
    assert_eq!(got.len(), expected.len());
    let worst = got
        .iter()
        .flatten()
        .zip(expected.iter().flatten())
        .map(|(a, b)| (a - b).abs() / b.abs().max(1e-3))
        .fold(0.0_f32, f32::max);
    assert!(worst <= 2f32.powi(-11), "relative error {worst}");
    assert!(
        worst > 0.0,
        "f16 positions equal the f32 ones: not half floats"
    );
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
    // Every logging choice is in the log, and its replay is byte-identical too.
    let chosen = dir.join("chosen.mcap");
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "15",
        "--out",
        &chosen.to_string_lossy(),
        "--log",
        "all",
        "--every",
        "4",
        "--mesh-every",
        "2",
        "--precision",
        "f16",
        "--compression",
        "zstd",
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let again = dir.join("chosen-again.mcap");
    let out = run(&[
        "replay",
        &chosen.to_string_lossy(),
        "--out",
        &again.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(o.contains("byte-identical"), "{o}");
}

/// The same bytes on 1 and 2 solver threads, and with 1 or 2 zstd workers (one per core the
/// process may use: `taskset` gives it one).
#[test]
fn logs_are_the_same_bytes_on_any_number_of_threads() {
    let dir = temp_dir("threads");
    let scene = write(&dir, "s.toml", &big(24));
    let log = |name: &str, threads: &str, one_core: bool| {
        let path = dir.join(name);
        let args = [
            "run",
            scene.as_str(),
            "--frames",
            "20",
            "--log",
            "all",
            "--compression",
            "zstd",
            "--out",
            &path.to_string_lossy(),
        ];
        let mut cmd = if one_core {
            let mut c = std::process::Command::new("taskset");
            c.args(["-c", "0", env!("CARGO_BIN_EXE_weft")]);
            c.current_dir(env!("CARGO_MANIFEST_DIR"));
            c
        } else {
            weft()
        };
        let out = cmd
            .args(args)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .expect("weft starts");
        assert!(out.status.success(), "{name}: {:?}", texts(&out));
        std::fs::read(&path).expect("the log")
    };
    let one = log("one.mcap", "1", true);
    assert_eq!(one, log("two.mcap", "2", false), "1 and 2 threads differ");
    assert_eq!(
        one,
        log("mixed.mcap", "2", true),
        "1 and 2 zstd workers differ"
    );
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
    interrupted_log(signal, SMALL, &[]);
}

/// Runs `scene` logged with `options` until `signal`; checks the log is valid, interrupted,
/// and holds every frame simulated; returns the log's path.
fn interrupted_log(signal: &str, scene: &str, options: &[&str]) -> std::path::PathBuf {
    let dir = temp_dir(&format!("signal-{signal}-{}", options.len()));
    let scene = write(&dir, "small.toml", scene);
    let mcap = dir.join("run.mcap");
    let mut args = vec!["run", scene.as_str(), "--frames", "100000000"];
    args.extend_from_slice(options);
    let child = spawn_logging(&args, &mcap);
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
    mcap
}

/// SIGINT while the log's queue is full (the surface compressed on a 64² cloth is slower to
/// log than to simulate): every frame handed to the queue is in the file, and it is valid.
#[test]
fn sigint_with_a_queued_backlog_keeps_every_frame_handed_over() {
    let options = ["--log", "all", "--compression", "zstd", "--timing"];
    let mcap = interrupted_log("INT", &big(64), &options);
    // The run waited for the queue: frames were queued when the signal came.
    let bytes = std::fs::read(&mcap).expect("the log");
    let waited = mcap::MessageStream::new(&bytes)
        .expect("readable")
        .filter_map(|m| m.ok())
        .filter(|m| m.channel.topic == "/stats")
        .filter_map(|m| serde_json::from_slice::<serde_json::Value>(&m.data).ok())
        .filter_map(|v| v["log_wait_ms"].as_f64())
        .fold(0.0, f64::max);
    assert!(waited > 0.0, "the queue never filled");
    let log = read_log(&mcap);
    let frames: usize = log.metadata["weft.status"]["frames"]
        .parse()
        .expect("number");
    assert_eq!(log.counts["/cloth/flag/mesh"], frames + 1);
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
