//! End to end, from screenshots of the viewer in a virtual X server (Xvfb): the cloths of
//! `compare.toml` carry their labels in the 3-D view, and on the character scene at
//! 1280×800 the side panel lies inside its window: one edge line where the panel starts,
//! and no other vertical line through its text (the panel's unit test checks that its
//! contents fit its width).

use crate::common;

use std::path::Path;
use std::thread::sleep;
use std::time::Duration;

use common::screen::{Region, Shot, shot};
use common::temp_dir;
use common::x11::{open_window, require_x11_tools, start_xvfb, wait_exit, xdotool};

/// Opens `scene` paused at `w`×`h` on `display`, with the pointer parked on the panel.
fn open(display: &str, scene: &str, w: u32, h: u32) -> common::x11::Guard {
    let (viewer, window) = open_window(
        display,
        &["view", scene, "--size", &format!("{w}x{h}"), "--paused"],
    );
    xdotool(display, &["windowfocus", "--sync", &window]);
    let (px, py) = ((w - 20).to_string(), (h - 20).to_string());
    xdotool(display, &["mousemove", &px, &py]);
    sleep(Duration::from_millis(1500));
    viewer
}

/// Quits the viewer with Q and checks it exited cleanly.
fn quit(display: &str, mut viewer: common::x11::Guard) {
    xdotool(display, &["key", "q"]);
    let (status, out) = wait_exit(&mut viewer, Duration::from_secs(60), "q");
    assert!(status.success(), "viewer failed ({status}): {out}");
}

fn keep(dir: &Path, shots: &[(&str, &Shot)]) -> String {
    for (name, s) in shots {
        s.save(&dir.join(format!("{name}.png")));
    }
    format!("screenshots in {}", dir.display())
}

#[test]
fn compare_shows_a_label_over_each_of_its_four_cloths() {
    require_x11_tools();
    let dir = temp_dir("e2e-labels");
    let (w, h) = (960, 640);
    let view = Region {
        x0: 0,
        y0: 40, // below the help hint
        x1: w - 302,
        y1: h,
    };
    let (display, _xvfb) = start_xvfb(4);
    let viewer = open(&display, "assets/scenes/compare.toml", w, h);
    let on = shot(&display, w, h);
    xdotool(&display, &["key", "l"]);
    sleep(Duration::from_millis(1500));
    let off = shot(&display, w, h);
    quit(&display, viewer);
    let shots = keep(&dir, &[("labels-on", &on), ("labels-off", &off)]);
    // The label pixels: those the labels change (the scene is paused: nothing else does).
    let changed = on.differing(&off, view, 24);
    assert!(
        changed.len() > 2000,
        "only {} label pixels: {shots}",
        changed.len()
    );
    // Each label has a swatch of its cloth's colour (the renderer's palette, cloths in
    // scene order).
    for i in 0..4 {
        let [r, g, b] = weft_render::cloth_colour(i);
        let c: egui::Color32 = egui::Rgba::from_rgb(r, g, b).into();
        let swatch = changed
            .iter()
            .filter(|&&(x, y)| {
                let p = on.at(x, y);
                p[0].abs_diff(c.r()) < 4 && p[1].abs_diff(c.g()) < 4 && p[2].abs_diff(c.b()) < 4
            })
            .count();
        assert!(
            swatch >= 60,
            "cloth {i}: {swatch} pixels of its colour {c:?}: {shots}"
        );
    }
}

#[test]
fn the_panel_fits_its_window_on_the_character_scene() {
    require_x11_tools();
    let dir = temp_dir("e2e-panel");
    let (w, h) = (1280, 800);
    let (display, _xvfb) = start_xvfb(5);
    let viewer = open(&display, "assets/scenes/character.toml", w, h);
    let s = shot(&display, w, h);
    quit(&display, viewer);
    let shots = keep(&dir, &[("character", &s)]);
    // A vertical line one or two pixels wide: a run of pixels each unlike the pixel on its
    // left and unlike the one or two on its right.
    let edge = |x: u32, y: u32| {
        let far =
            |a: [u8; 3], b: [u8; 3]| (0..3).map(|c| a[c].abs_diff(b[c]) as u32).sum::<u32>() > 30;
        let p = s.at(x, y);
        far(p, s.at(x - 1, y)) && (far(p, s.at(x + 1, y)) || far(p, s.at(x + 2, y)))
    };
    let longest = |x: u32| {
        let (mut run, mut best) = (0, 0);
        for y in 0..h {
            run = if edge(x, y) { run + 1 } else { 0 };
            best = best.max(run);
        }
        best
    };
    let panel = w - 300;
    // The panel's own edge, where it starts.
    let edge_at = (panel - 2..=panel + 1).find(|&x| longest(x) > h - 10);
    assert!(edge_at.is_some(), "no panel edge near x = {panel}: {shots}");
    // No other line inside it.
    for x in panel + 3..w - 2 {
        let run = longest(x);
        assert!(run < 40, "a {run}-pixel vertical line at x = {x}: {shots}");
    }
}
