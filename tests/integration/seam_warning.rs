//! `weft run` warns, once and without stopping, about a garment whose seams are still open
//! after they were due to close: the shipped skirt sewn in 0.4 s folds a hem corner into its
//! seam, and mesh contact, which lets nothing through, holds 9 of its 68 seam pairs open.

use crate::common;

use common::{run, texts};

/// `weft run` of the shipped skirt for `frames` frames, sewn over `seam_time` seconds.
fn skirt(seam_time: f64, frames: u32) -> (String, String) {
    let set = format!("cloth.skirt.seam_time={seam_time}");
    let frames = frames.to_string();
    let args = [
        "run",
        "assets/scenes/skirt.toml",
        "--frames",
        &frames,
        "--set",
        &set,
    ];
    let out = run(&args);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "the run goes on: {o}{e}");
    (o, e)
}

#[test]
fn a_skirt_sewn_too_fast_is_warned_about_once_and_the_run_goes_on() {
    // Due at 0.65 s, frame 39.
    let (o, e) = skirt(0.4, 45);
    let warning = "weft: warning: cloth `skirt`: ";
    assert_eq!(e.matches(warning).count(), 1, "{e}");
    assert!(
        e.contains("of its 68 seam pairs are still open 0.25 s after seam_time (0.4 s)"),
        "{e}"
    );
    assert!(e.contains("a longer seam_time"), "{e}");
    assert!(o.contains("45 frames"), "{o}");
}

#[test]
fn the_shipped_skirt_closes_its_seams_and_says_nothing_of_them() {
    // Sewn over 0.6 s: due at 0.85 s, frame 51.
    let (_, e) = skirt(0.6, 54);
    assert!(!e.contains("seam pairs are still open"), "{e}");
}
