//! Every stop is honoured within a second or two: inside a long frame (the solver polls the
//! flag per substep), while building a big cloth (`weft check`), and a FIFO is never opened as
//! a mesh. Exit code 130 for SIGINT and SIGTERM alike, and a finished log when one was open.

use crate::common;

use std::process::Stdio;
use std::time::Duration;

use common::*;

/// How long a stop may take (the tests run beside other builds on a small machine).
const PROMPT: Duration = Duration::from_secs(3);

fn stop_inside_a_long_frame(sig: &str) {
    let dir = temp_dir(&format!("long-frame-{sig}"));
    let scene = write(&dir, "s.toml", &big(64));
    let target = dir.join("a.mcap");
    // 20000 substeps x 50 iterations on 4096 particles: one frame takes minutes.
    let child = spawn_logging(
        &[
            "run",
            &scene,
            "--frames",
            "5",
            "--set",
            "sim.substeps=20000",
            "--set",
            "sim.iterations=50",
        ],
        &target,
    );
    // The log's frame 0 is written as soon as the run starts: from then on frames are long.
    assert!(
        wait_for(Duration::from_secs(60), || partial(&target).exists()),
        "the run never started"
    );
    std::thread::sleep(Duration::from_millis(300));
    signal(child.id(), sig);
    let (out, took) = exits_within(child, Duration::from_secs(60));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(took < PROMPT, "{sig}: took {took:?} to stop: {err}");
    assert_eq!(out.status.code(), Some(130), "{err}");
    let log = read_log(&target);
    assert_eq!(log.metadata["weft.status"]["status"], "interrupted");
    assert_eq!(log.metadata["weft.status"]["frames"], "0");
    assert_eq!(
        log.counts["/stats"], 1,
        "frame 0 only: the stop came inside frame 1"
    );
}

#[test]
fn sigint_inside_a_long_frame_stops_within_a_second() {
    stop_inside_a_long_frame("INT");
}

#[test]
fn sigterm_inside_a_long_frame_stops_within_a_second() {
    stop_inside_a_long_frame("TERM");
}

#[test]
fn check_of_a_big_cloth_stops_at_once() {
    let dir = temp_dir("check-stop");
    let scene = write(&dir, "s.toml", &big(2048));
    for sig in ["INT", "TERM"] {
        let child = weft()
            .args(["check", &scene, "--max-memory", "64G"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starts");
        // Loading and building 4 million particles takes several seconds here.
        std::thread::sleep(Duration::from_millis(700));
        signal(child.id(), sig);
        let (out, took) = exits_within(child, Duration::from_secs(60));
        let (o, e) = texts(&out);
        assert!(took < PROMPT, "{sig}: took {took:?}");
        assert_eq!(out.status.code(), Some(130), "{sig}: {o}{e}");
        assert!(
            !o.contains("ok"),
            "{sig}: a stopped check says nothing is ok: {o}"
        );
    }
}

#[test]
fn a_fifo_is_never_opened_as_a_mesh() {
    let dir = temp_dir("fifo");
    let fifo = dir.join("pipe.obj");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let scene = write(
        &dir,
        "s.toml",
        "[cloth.shirt]\nmesh = \"pipe.obj\"\nmass = 0.2\n",
    );
    let child = weft()
        .args(["check", &scene])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    let (out, _) = exits_within(child, Duration::from_secs(20));
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("cloth.shirt.mesh") && e.contains("not a regular file"),
        "{e}"
    );
}

#[test]
fn a_scene_file_that_is_a_device_is_refused() {
    let out = run(&["check", "/dev/zero"]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("/dev/zero") && e.contains("not a regular file"),
        "{e}"
    );
}

#[test]
fn sigint_while_self_collision_lists_a_thick_cloth_stops_within_a_second() {
    // A 512² sheet of 1 m, 1 m thick (as thick as a cloth may be: its own width), kept apart
    // particle by particle (the thick cloth's contact): every particle lies within reach (at
    // least twice the thickness) of every other, so the first list build tests 3·10¹⁰ pairs
    // (all exempt, so it takes no memory): minutes of work inside the first substep, where
    // the solver's own per-substep poll cannot see a stop.
    let dir = temp_dir("thick-self-collision");
    let scene = write(
        &dir,
        "s.toml",
        "[cloth.c]\nresolution = [512, 512]\nthickness = 1.0\n\n\
         [self_collision]\ncontact = \"particles\"\n",
    );
    let target = dir.join("a.mcap");
    let child = spawn_logging(
        &["run", &scene, "--frames", "5", "--max-memory", "4T"],
        &target,
    );
    // Frame 0 in the log: the run is stepping (a stop before would end it at once).
    assert!(
        partial_grows_past(&target, 100_000, Duration::from_secs(120)),
        "the run never started"
    );
    std::thread::sleep(Duration::from_millis(500));
    signal(child.id(), "INT");
    let (out, took) = exits_within(child, Duration::from_secs(120));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(took < PROMPT, "took {took:?} to stop: {err}");
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert_eq!(
        read_log(&target).metadata["weft.status"]["status"],
        "interrupted"
    );
}

/// Names of the files in `dir`.
fn names(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default()
}

/// Renders the default scene at 8192², signals once `ready` says so, and checks the stop.
fn stop_a_big_render(name: &str, ready: impl Fn(&[String]) -> bool) {
    let dir = temp_dir(name);
    let out = dir.join("out");
    let child = weft()
        .args(["render", "--frames", "3", "--size", "8192x8192", "--out"])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    assert!(
        wait_for(Duration::from_secs(120), || ready(&names(&out))),
        "{name}: never got there: {:?}",
        names(&out)
    );
    signal(child.id(), "INT");
    let (done, took) = exits_within(child, Duration::from_secs(120));
    let (o, e) = texts(&done);
    assert!(took < PROMPT, "{name}: took {took:?} to stop: {o}{e}");
    assert_eq!(done.status.code(), Some(130), "{name}: {o}{e}");
    let left = names(&out);
    assert!(
        !left.iter().any(|n| n.starts_with("frame_")),
        "{name}: an image was left: {left:?}"
    );
}

#[test]
fn sigint_while_drawing_an_8192_image_stops_within_a_second() {
    // The GIF's partial file is opened before the first image is drawn; drawing 8192² on a
    // software rasteriser takes seconds (a tile at a time, the stop looked at between tiles).
    let started = std::cell::Cell::new(None);
    stop_a_big_render("render-stop-drawing", |names| {
        if names.iter().any(|n| n.ends_with(".gif")) {
            let at = started.get().unwrap_or_else(std::time::Instant::now);
            started.set(Some(at));
            at.elapsed() > Duration::from_millis(1500)
        } else {
            false
        }
    });
}

#[test]
fn sigint_while_writing_an_8192_png_stops_within_a_second() {
    // Compressing 256 MB of pixels at the strongest level takes seconds: rows are streamed
    // through the compressor a few at a time, the stop looked at between them.
    stop_a_big_render("render-stop-png", |names| {
        names.iter().any(|n| n.starts_with("frame_00000.partial"))
    });
}
