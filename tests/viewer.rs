//! The viewer's command line without a display: `weft` with no command is the viewer, a
//! missing display is a clear error pointing to the headless commands, and an unwritable
//! `--record` fails before any window is tried.

mod common;

use common::{temp_dir, texts, weft};

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
