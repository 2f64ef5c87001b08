//! The viewer's command line without a display: `weft` with no command is the viewer, a
//! missing display is a clear error pointing to the headless commands, and an unwritable
//! `--record` fails before any window is tried. `--record` never overwrites an input, an
//! earlier log or another weft's log: it is claimed (partial file, lock) before the window.

use crate::common;

use std::time::Duration;

use common::{
    big, exits_within, partial, partial_grows_past, signal, spawn_logging, temp_dir, texts, weft,
    write,
};

fn without_display(args: &[&str]) -> std::process::Output {
    weft()
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .expect("weft starts")
}

#[test]
fn no_display_is_a_clear_error_for_weft_and_weft_view() {
    for args in [
        &[][..],
        &["view"][..],
        &["view", "assets/scenes/sphere_drop.toml"][..],
    ] {
        let out = without_display(args);
        let (o, err) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {o}{err}");
        assert!(err.contains("cannot open a window"), "{args:?}: {err}");
        assert!(err.contains("DISPLAY"), "{args:?}: {err}");
        assert!(
            err.contains("weft run") && err.contains("weft render"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        // The viewer, not a headless run: nothing was simulated.
        assert!(!o.contains("frames"), "{args:?}: {o}");
    }
}

#[test]
fn no_display_leaves_no_log_behind() {
    let dir = temp_dir("viewer-no-display");
    let log = dir.join("session.mcap");
    let out = without_display(&["view", "--record", &log.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(1), "{:?}", texts(&out));
    assert!(!log.exists(), "an empty log was left at {}", log.display());
}

#[test]
fn an_unwritable_record_path_fails_before_the_window() {
    let out = without_display(&["view", "--record", "/no/such/dir/session.mcap"]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot write /no/such/dir/session.mcap"),
        "{err}"
    );
    assert!(!err.contains("cannot open a window"), "{err}");
}

#[test]
fn bad_scene_and_bad_size_are_reported_before_the_window() {
    let out = without_display(&["view", "no/such/scene.toml"]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("no/such/scene.toml"), "{err}");
    let out = without_display(&["view", "--size", "12x34"]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("WIDTHxHEIGHT"), "{err}");
}

#[test]
fn record_may_not_overwrite_the_scene() {
    let dir = temp_dir("viewer-record-scene");
    let scene = write(&dir, "s.toml", common::SMALL);
    // The same file by another spelling.
    let same = dir.join(".").join("s.toml");
    let out = without_display(&["view", &scene, "--record", &same.to_string_lossy()]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("refusing to overwrite an input"), "{err}");
    assert!(!err.contains("cannot open a window"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&scene).expect("the scene is still there"),
        common::SMALL
    );
}

#[test]
fn a_failed_session_keeps_the_earlier_log() {
    let dir = temp_dir("viewer-record-keep");
    let log = dir.join("session.mcap");
    std::fs::write(&log, b"an earlier session").expect("write");
    let out = without_display(&["view", "--record", &log.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(1), "{:?}", texts(&out));
    assert_eq!(
        std::fs::read(&log).expect("the earlier log is kept"),
        b"an earlier session"
    );
    assert!(!partial(&log).exists(), "the unfinished partial goes");
}

#[test]
fn record_refuses_a_log_another_weft_is_writing() {
    let dir = temp_dir("viewer-record-locked");
    let scene = write(&dir, "s.toml", &big(64));
    let target = dir.join("a.mcap");
    let first = spawn_logging(&["run", &scene, "--frames", "100000000"], &target);
    let started = partial_grows_past(&target, 0, Duration::from_secs(30));
    let part = partial(&target);
    let out = without_display(&["view", "--record", &target.to_string_lossy()]);
    signal(first.id(), "INT");
    let (run, _) = exits_within(first, Duration::from_secs(20));
    assert!(started, "the run never started writing {}", part.display());
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("another weft is writing"), "{err}");
    assert_eq!(
        run.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(target.exists(), "the run's log is whole and in place");
}
