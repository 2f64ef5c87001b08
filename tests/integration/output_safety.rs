//! Outputs never destroy inputs or each other: an output that is an input (or another output)
//! is refused, a log appears under its name only when finished, a second writer of the same
//! target is refused, and a failed write names the path and leaves no file under it.

use crate::common;

use std::time::Duration;

use common::*;

#[test]
fn an_output_that_is_the_scene_is_refused_and_the_scene_kept() {
    let dir = temp_dir("out-is-scene");
    let scene = write(&dir, "s.toml", SMALL);
    // The same file by another spelling.
    let again = dir.join(".").join("s.toml");
    for args in [
        vec![
            "run",
            &scene,
            "--frames",
            "2",
            "--out",
            &again.to_string_lossy(),
        ],
        vec!["run", &scene, "--frames", "2", "--dump-final", &scene],
    ] {
        let args: Vec<&str> = args.iter().map(|s| s.as_ref()).collect();
        let out = run(&args);
        let (o, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {o}{e}");
        assert!(e.contains("refusing to overwrite an input"), "{e}");
        assert_eq!(std::fs::read_to_string(&scene).expect("scene"), SMALL);
    }
}

#[test]
fn two_outputs_of_one_run_may_not_be_one_file() {
    let dir = temp_dir("out-twice");
    let scene = write(&dir, "s.toml", SMALL);
    let a = dir.join("a.mcap").to_string_lossy().into_owned();
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "2",
        "--out",
        &a,
        "--dump-final",
        &a,
    ]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("are the same file"), "{e}");
    assert!(!dir.join("a.mcap").exists());
}

#[test]
fn replay_may_not_overwrite_its_log() {
    let dir = temp_dir("replay-over-log");
    let scene = write(&dir, "s.toml", SMALL);
    let log = dir.join("a.mcap").to_string_lossy().into_owned();
    let out = run(&["run", &scene, "--frames", "3", "--out", &log]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let before = std::fs::read(&log).expect("log");
    let out = run(&["replay", &log, "--out", &log]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("refusing to overwrite an input"), "{e}");
    assert_eq!(std::fs::read(&log).expect("log"), before);
}

#[test]
fn a_log_appears_only_when_finished_and_a_second_writer_is_refused() {
    let dir = temp_dir("second-writer");
    let scene = write(&dir, "s.toml", &big(64));
    let target = dir.join("a.mcap");
    let first = spawn_logging(&["run", &scene, "--frames", "100000000"], &target);
    assert!(
        partial_grows_past(&target, 0, Duration::from_secs(30)),
        "the first run never started writing {}",
        target.display()
    );
    let part = partial(&target);
    assert!(
        !target.exists(),
        "a log under its final name before it is finished"
    );
    let second = run(&[
        "run",
        &scene,
        "--frames",
        "2",
        "--out",
        &target.to_string_lossy(),
    ]);
    let (_, e) = texts(&second);
    assert_eq!(second.status.code(), Some(1), "{e}");
    assert!(e.contains("another weft is writing"), "{e}");
    signal(first.id(), "INT");
    let (out, _) = exits_within(first, Duration::from_secs(20));
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!part.exists(), "the partial is renamed, not left");
    let log = read_log(&target);
    assert_eq!(log.metadata["weft.status"]["status"], "interrupted");
}

#[test]
fn a_full_device_is_named_and_leaves_no_file_passed_off_as_whole() {
    let dir = temp_dir("full");
    let scene = write(&dir, "s.toml", &big(32));
    // /dev/full: every write fails with ENOSPC.
    let out = run(&["run", &scene, "--frames", "50", "--out", "/dev/full"]);
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{o}{e}");
    assert!(e.contains("/dev/full"), "the message names the path: {e}");
    assert!(!e.contains("panicked"), "{e}");
    // A regular file on a "disk" that fills up: a 64 KiB file-size limit (EFBIG, with
    // SIGXFSZ ignored) stands in for a small full filesystem.
    let target = dir.join("a.mcap");
    let out = run_on_full_disk(
        64,
        &[
            "run",
            &scene,
            "--frames",
            "200",
            "--out",
            &target.to_string_lossy(),
        ],
    );
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{o}{e}");
    assert!(
        e.contains(&target.display().to_string()),
        "names the path: {e}"
    );
    assert!(!target.exists(), "no file under the final name");
    assert!(!partial(&target).exists(), "no partial left");
}

#[test]
fn a_log_to_a_device_or_a_pipe_is_refused_before_anything_is_simulated() {
    let dir = temp_dir("out-device");
    let scene = write(&dir, "s.toml", &big(48));
    let fifo = dir.join("pipe.mcap");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    for target in [std::path::Path::new("/dev/null"), fifo.as_path()] {
        // Before, /dev/null took the whole run (here endless) and then failed to sync it, and
        // a pipe blocked until a reader came.
        let child = spawn_logging(&["run", &scene, "--frames", "100000000"], target);
        let (out, _) = exits_within(child, Duration::from_secs(20));
        let (_, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{}: {e}", target.display());
        assert!(
            e.contains("not a regular file") && e.contains(&*target.to_string_lossy()),
            "{e}"
        );
        assert!(!e.contains("particles"), "no simulation was built: {e}");
    }
    let log = logged_run(&dir, "small.toml", SMALL, 2, "a.mcap");
    for command in ["recover", "replay"] {
        let out = run(&[command, &log.to_string_lossy(), "--out", "/dev/null"]);
        let (_, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{command}: {e}");
        assert!(e.contains("not a regular file"), "{command}: {e}");
    }
}
