//! End to end: the viewer's keys in a virtual X server (Xvfb), sent by `xdotool` after Tab
//! has hidden and shown the panel (which once left a panel widget focused, so that Space
//! opened the scene list and S was swallowed). The session log (`--record`) shows what
//! the simulation keys did; screenshots show what the camera and label keys did.

use crate::common;

use std::path::Path;
use std::thread::sleep;
use std::time::Duration;

use common::screen::{Region, Shot, shot};
use common::x11::{open_window, require_x11_tools, start_xvfb, wait_exit, xdotool};
use common::{temp_dir, write};
use foxglove::Decode;
use foxglove::messages::PointCloud;

/// A small cloth pinned along its top edge, falling from flat: every frame moves it.
const SCENE: &str = r#"[sim]
method = "xpbd"
dt = "1/60"
substeps = 4

[cloth.sheet]
resolution = [8, 8]
size = [1.0, 1.0]
center = [0.0, 1.5, 0.0]
orientation = "horizontal"
pins = ["top-left", "top-right"]
"#;

/// Window size, and the 3-D view left of the 300-point side panel.
const W: u32 = 960;
const H: u32 = 640;
const VIEW: Region = Region {
    x0: 0,
    y0: 0,
    x1: W - 302,
    y1: H,
};

/// Saves `shots` beside the test's files (for a failure message) and says where.
fn keep(dir: &Path, shots: &[(&str, &Shot)]) -> String {
    for (name, s) in shots {
        s.save(&dir.join(format!("{name}.png")));
    }
    format!("screenshots in {}", dir.display())
}

/// The particle positions of every logged frame after frame 0, in order.
fn logged_frames(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).expect("log exists");
    mcap::Summary::read(&bytes)
        .expect("summary readable")
        .expect("the log was finished (it has a summary)");
    let mut frames: Vec<(u64, Vec<u8>)> = mcap::MessageStream::new(&bytes)
        .expect("readable")
        .map(|m| m.expect("message decodes"))
        .filter(|m| m.channel.topic == "/cloth/sheet/particles")
        .map(|m| {
            let pc = PointCloud::decode(&m.data[..]).expect("PointCloud");
            (m.log_time, pc.data.to_vec())
        })
        .collect();
    frames.sort_by_key(|(t, _)| *t);
    frames.into_iter().skip(1).map(|(_, d)| d).collect()
}

#[test]
fn tab_space_s_and_r_reach_the_viewer_after_the_panel_had_focus() {
    require_x11_tools();
    let dir = temp_dir("e2e-keys");
    let scene = write(&dir, "sheet.toml", SCENE);
    let log = dir.join("session.mcap");
    let (display, _xvfb) = start_xvfb(3);
    let (mut viewer, window) = open_window(
        &display,
        &[
            "view",
            &scene,
            "--record",
            &log.to_string_lossy(),
            "--size",
            &format!("{W}x{H}"),
            "--paused",
        ],
    );
    xdotool(&display, &["windowfocus", "--sync", &window]);
    let key = |k: &str, wait_ms: u64| {
        xdotool(&display, &["key", k]);
        sleep(Duration::from_millis(wait_ms));
    };
    // Tab hides the panel and shows it again: egui would have moved its focus to the first
    // widget (the scene list).
    key("Tab", 700);
    key("Tab", 700);
    // Two single steps, then run for a while, then pause.
    key("s", 500);
    key("s", 500);
    key("space", 1500);
    key("space", 700);
    // Reset, wait (a viewer that failed to pause would step here), one step.
    key("r", 1200);
    key("s", 700);
    // The camera keys: F frames the scene; an orbit (right drag) moves the camera; Home frames
    // it again, as it was. The pointer waits on the panel, away from the 3-D view.
    let mouse = |args: &[&str], wait_ms: u64| {
        xdotool(&display, args);
        sleep(Duration::from_millis(wait_ms));
    };
    let (px, py) = ((W - 20).to_string(), (H - 20).to_string());
    let park = ["mousemove", px.as_str(), py.as_str()];
    mouse(&park, 300);
    key("f", 1500);
    let framed = shot(&display, W, H);
    mouse(&["mousemove", "200", "300"], 300);
    mouse(&["mousedown", "3"], 200);
    mouse(&["mousemove", "320", "260"], 300);
    mouse(&["mouseup", "3"], 200);
    mouse(&park, 1500);
    let orbited = shot(&display, W, H);
    key("Home", 1500);
    let reframed = shot(&display, W, H);
    // L shows the cloth's label (off by default with one cloth), L again hides it.
    key("l", 1500);
    let labelled = shot(&display, W, H);
    key("l", 1500);
    let unlabelled = shot(&display, W, H);
    key("q", 0);
    let (status, out) = wait_exit(&mut viewer, Duration::from_secs(60), "q");
    assert!(status.success(), "viewer failed ({status}): {out}");

    let frames = logged_frames(&log);
    assert!(
        frames.len() >= 8,
        "Space did not run the simulation: {} frames logged: {out}",
        frames.len()
    );
    assert_ne!(frames[0], frames[1], "S steps the cloth");
    // After R and one S, the cloth is where the first S left it: R reset it, S stepped it
    // once, and nothing stepped between (the second Space paused it).
    assert_eq!(
        frames.last(),
        frames.first(),
        "the last frame is not one step from the start ({} frames logged): {out}",
        frames.len()
    );

    let shots = keep(
        &dir,
        &[
            ("framed", &framed),
            ("orbited", &orbited),
            ("reframed", &reframed),
            ("labelled", &labelled),
            ("unlabelled", &unlabelled),
        ],
    );
    let area = (VIEW.x1 * VIEW.y1) as usize;
    let moved = framed.differing(&orbited, VIEW, 8).len();
    assert!(
        moved > area / 20,
        "the orbit changed only {moved} pixels: {shots}"
    );
    let back = framed.differing(&reframed, VIEW, 2).len();
    assert!(
        back < 20,
        "Home did not frame the scene as F did ({back} pixels differ): {shots}"
    );
    let label = reframed.differing(&labelled, VIEW, 8);
    assert!(
        label.len() > 300,
        "L showed no label ({} pixels changed): {shots}",
        label.len()
    );
    let hidden = reframed.differing(&unlabelled, VIEW, 2).len();
    assert!(hidden < 20, "L again left {hidden} pixels changed: {shots}");
}
