//! End to end: the real viewer in a virtual X server (Xvfb), driven by `xdotool`: a left-button
//! drag on the cloth must grab the particle under the cursor and move it with the cursor, and
//! the session log (`--record`) must show both.
//!
//! Needs `Xvfb` and `xdotool` (scripts/install-test-deps.sh installs them); the test fails
//! when they are missing.

use crate::common;

use std::path::Path;
use std::thread::sleep;
use std::time::Duration;

use common::x11::{Guard, open_window, start_xvfb, viewer_on, wait_exit, xdotool, xyz};
use common::{signal, temp_dir, write};
use foxglove::Decode;
use foxglove::messages::PointCloud;
use glam::{UVec2, Vec2, Vec3};
use weft_render::Camera;

/// Window size, and the width of the viewer's side panel on its right (window.rs).
const W: u32 = 960;
const H: u32 = 640;
const PANEL: f32 = 300.0;

/// The camera the viewer is opened with: in front of the cloth, a little to the right and
/// above.
const EYE: Vec3 = Vec3::new(0.8, 1.9, 2.6);
const TARGET: Vec3 = Vec3::new(0.0, 1.5, 0.0);

/// A 16 × 16 vertical cloth pinned along its top edge: it hangs straight, so the particle
/// under the cursor is where it started when the test clicks.
const SCENE: &str = r#"[sim]
method = "xpbd"
dt = "1/60"
substeps = 10
damping = 0.5

[cloth.sheet]
resolution = [16, 16]
size = [1.0, 1.0]
center = [0.0, 1.5, 0.0]
mass = 0.2
pins = ["top"]
"#;

/// Checks the tools the viewer tests drive, and writes the test scene into a fresh directory
/// named `name`: `(directory, scene path)`.
fn prepare(name: &str) -> (std::path::PathBuf, String) {
    common::x11::require_x11_tools();
    let dir = temp_dir(name);
    let scene_path = write(&dir, "sheet.toml", SCENE);
    (dir, scene_path)
}

/// One `/interaction` message.
#[derive(Debug)]
struct Interaction {
    log_time: u64,
    particle: Option<u64>,
    target: Option<Vec3>,
}

/// Reads `/interaction` and the positions of particle `i` of `/cloth/sheet/particles` by log
/// time.
fn read(path: &Path, i: usize) -> (Vec<Interaction>, Vec<(u64, Vec3)>) {
    let bytes = std::fs::read(path).expect("log exists");
    mcap::Summary::read(&bytes)
        .expect("summary readable")
        .expect("the log was finished (it has a summary)");
    let mut inter = Vec::new();
    let mut positions = Vec::new();
    for m in mcap::MessageStream::new(&bytes).expect("readable") {
        let m = m.expect("message decodes");
        match m.channel.topic.as_str() {
            "/interaction" => {
                let v: serde_json::Value = serde_json::from_slice(&m.data).expect("JSON");
                let target = v["target"].as_array().map(|a| {
                    let c = |k: usize| a[k].as_f64().expect("number") as f32;
                    Vec3::new(c(0), c(1), c(2))
                });
                inter.push(Interaction {
                    log_time: m.log_time,
                    particle: v["particle"].as_u64(),
                    target,
                });
            }
            "/cloth/sheet/particles" => {
                let pc = PointCloud::decode(&m.data[..]).expect("PointCloud");
                let c = &pc.data[12 * i..12 * i + 12];
                let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
                positions.push((m.log_time, Vec3::new(f(0), f(4), f(8))));
            }
            _ => {}
        }
    }
    (inter, positions)
}

#[test]
fn dragging_the_cloth_in_the_viewer_moves_the_grabbed_particle_and_is_logged() {
    let (dir, scene_path) = prepare("e2e-drag");
    let log = dir.join("session.mcap");

    // The viewer is opened with this camera (--eye, --target), so the test knows which
    // pixel shows which particle: the one nearest the cloth's centre.
    let scene = weft_scene::load(Path::new(&scene_path), &[]).expect("scene loads");
    let groups = scene.build().expect("solvers");
    let x: Vec<Vec3> = groups[0]
        .solver
        .particles()
        .positions
        .iter()
        .map(|p| p.as_vec3())
        .collect();
    let (min, max) = x.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(a, b), p| (a.min(*p), b.max(*p)),
    );
    let camera = Camera::looking_at(EYE, TARGET);
    let size = UVec2::new(W, H);
    let centre = 0.5 * (min + max);
    let i = (0..x.len())
        .min_by(|&a, &b| x[a].distance(centre).total_cmp(&x[b].distance(centre)))
        .expect("particles");
    let from = camera.project(x[i], size).expect("in view").round();
    let to = from + Vec2::new(160.0, -90.0);
    for p in [from, to] {
        assert!(
            p.x > 20.0 && p.x < W as f32 - PANEL - 20.0 && p.y > 40.0 && p.y < H as f32 - 20.0,
            "pixel {p} is not in the 3D view"
        );
    }

    let (display, _xvfb) = start_xvfb(0);
    let (mut viewer, window) = open_viewer(&display, &scene_path, &log);
    // No window manager gives it the keyboard: focus it for the final `q`.
    xdotool(&display, &["windowfocus", "--sync", &window]);

    // The drag: press on the particle, move in 12 steps, hold, release.
    let px = |p: Vec2| [format!("{}", p.x as i32), format!("{}", p.y as i32)];
    let [fx, fy] = px(from);
    xdotool(&display, &["mousemove", "--sync", &fx, &fy]);
    sleep(Duration::from_millis(500));
    xdotool(&display, &["mousedown", "1"]);
    sleep(Duration::from_millis(500));
    for k in 1..=12 {
        let p = from + (to - from) * (k as f32 / 12.0);
        let [x, y] = px(p.round());
        xdotool(&display, &["mousemove", &x, &y]);
        sleep(Duration::from_millis(120));
    }
    sleep(Duration::from_millis(1500));
    xdotool(&display, &["mouseup", "1"]);
    sleep(Duration::from_millis(1000));
    xdotool(&display, &["key", "q"]);

    // It quits on q and leaves a finished log.
    let (status, out) = wait_exit(&mut viewer, Duration::from_secs(60), "q");
    assert!(status.success(), "viewer failed ({status}): {out}");

    let (inter, positions) = read(&log, i);
    let grabbed: Vec<&Interaction> = inter.iter().filter(|m| m.particle.is_some()).collect();
    assert!(
        grabbed.len() >= 10,
        "only {} of {} logged frames show a grab (drag {from} -> {to}): {out}",
        grabbed.len(),
        inter.len()
    );
    assert!(
        grabbed.iter().all(|m| m.particle == Some(i as u64)),
        "grabbed {:?}, expected particle {i}",
        grabbed.iter().map(|m| m.particle).collect::<Vec<_>>()
    );
    // The grab ends before the log does (the button was released).
    let last = grabbed.last().expect("grabbed");
    assert!(inter.last().expect("messages").particle.is_none());

    // At the last grabbed frame the particle sits at the drag target, and the target is
    // under the cursor where the drag ended.
    let at = positions
        .iter()
        .find(|(t, _)| *t == last.log_time)
        .map(|(_, p)| *p)
        .expect("particles logged with the interaction");
    let target = last.target.expect("target logged");
    assert!(
        (at - target).length() < 1e-3,
        "particle {at} vs target {target}"
    );
    let seen = camera.project(at, size).expect("in view");
    assert!(
        (seen - to).length() < 6.0,
        "the particle is at pixel {seen}, the cursor ended at {to}"
    );
    // It moved with the drag: far from where it started, in the drag's direction.
    let moved = seen - from;
    let dir = (to - from).normalize();
    assert!(
        moved.dot(dir) > 0.9 * (to - from).length(),
        "moved {moved} px along a drag of {}",
        to - from
    );
    assert!(
        (at - x[i]).length() > 0.1,
        "moved only {} m",
        (at - x[i]).length()
    );
}

/// Starts `weft view SCENE --record LOG` on `display` with the test's camera and waits for
/// its window and a few frames; returns the process and the window id.
fn open_viewer(display: &str, scene: &str, log: &Path) -> (Guard, String) {
    open_window(
        display,
        &[
            "view",
            scene,
            "--record",
            &log.to_string_lossy(),
            "--size",
            &format!("{W}x{H}"),
            "--exit-after-frames",
            "100000",
            "--eye",
            &xyz(EYE),
            "--target",
            &xyz(TARGET),
        ],
    )
}

#[test]
fn ctrl_c_in_the_viewer_leaves_a_finished_log() {
    let (dir, scene_path) = prepare("e2e-interrupt");
    let log = dir.join("session.mcap");
    let (display, _xvfb) = start_xvfb(1);
    let (mut viewer, _) = open_viewer(&display, &scene_path, &log);
    signal(viewer.0.id(), "INT");
    let (status, out) = wait_exit(&mut viewer, Duration::from_secs(60), "SIGINT");
    assert_eq!(status.code(), Some(130), "{out}");
    assert!(
        !common::partial(&log).exists(),
        "the finished log is renamed into place"
    );
    let bytes = std::fs::read(&log).expect("log exists");
    let summary = mcap::Summary::read(&bytes)
        .expect("summary readable")
        .expect("the log was finished (it has a summary)");
    let status = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).expect("metadata"))
        .find(|m| m.name == "weft.status")
        .expect("weft.status written");
    assert_eq!(status.metadata["status"], "interrupted", "{out}");
    let frames: u64 = status.metadata["frames"].parse().expect("a number");
    let logged = mcap::MessageStream::new(&bytes)
        .expect("readable")
        .map(|m| m.expect("message"))
        .filter(|m| m.channel.topic == "/interaction")
        .count() as u64;
    assert!(frames > 0, "{out}");
    assert_eq!(logged, frames + 1, "frame 0 and every simulated frame");
}

#[test]
fn a_record_write_that_fails_names_the_path() {
    let (_, scene_path) = prepare("e2e-full");
    let (display, _xvfb) = start_xvfb(2);
    let mut viewer = viewer_on(
        &display,
        &[
            "view",
            &scene_path,
            "--record",
            "/dev/full",
            "--exit-after-frames",
            "20",
        ],
    );
    let (status, out) = wait_exit(&mut viewer, Duration::from_secs(120), "its 20th frame");
    assert_eq!(status.code(), Some(1), "{out}");
    assert!(
        out.contains("/dev/full"),
        "the message names the path: {out}"
    );
    assert!(!out.contains("panicked"), "{out}");
}
