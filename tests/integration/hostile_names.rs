//! Names that look like a temporary file never cost a file: `recover` and `replay` leave their
//! input as it was whatever it is called, and outputs named like another output's temporary
//! file (or an input named so) are each written where they were asked to be.

use crate::common;

use common::*;

#[test]
fn recover_and_replay_leave_an_input_named_like_a_temporary_file() {
    let dir = temp_dir("hostile-recover");
    let whole = logged_run(&dir, "s.toml", SMALL, 20, "whole.mcap");
    let bytes = std::fs::read(&whole).expect("log");
    // A whole log and a cut one, each named as a killed run's log once was.
    let input = dir.join("run.partial.mcap");
    let cut = dir.join("cut.partial.mcap");
    std::fs::write(&input, &bytes).expect("copy");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).expect("cut");
    for (from, to) in [(&input, "run.mcap"), (&cut, "cut.mcap")] {
        let before = std::fs::read(from).expect("input");
        let out = run(&[
            "recover",
            &from.to_string_lossy(),
            "--out",
            &dir.join(to).to_string_lossy(),
        ]);
        let (o, e) = texts(&out);
        assert_eq!(
            std::fs::read(from).expect("the input is still there"),
            before,
            "recover changed its input {}: {o}{e}",
            from.display()
        );
        if out.status.success() {
            read_log(&dir.join(to));
        }
    }
    assert!(dir.join("run.mcap").exists(), "a whole log recovers");
    let replayed = dir.join("x.mcap");
    let out = run(&[
        "replay",
        &input.to_string_lossy(),
        "--out",
        &replayed.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert_eq!(
        std::fs::read(&input).expect("input"),
        bytes,
        "replay kept it"
    );
    read_log(&replayed);
}

#[test]
fn outputs_named_like_temporary_files_land_where_they_were_asked() {
    let dir = temp_dir("hostile-outputs");
    // The log named as the dump's temporary file once was.
    let scene = write(&dir, "s.toml", SMALL);
    let log = dir.join("b.partial.json");
    let dump = dir.join("b.json");
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "5",
        "--out",
        &log.to_string_lossy(),
        "--dump-final",
        &dump.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert_eq!(read_log(&log).metadata["weft.status"]["status"], "complete");
    let text = std::fs::read_to_string(&dump).expect("dump");
    assert!(
        serde_json::from_str::<serde_json::Value>(&text).is_ok(),
        "the dump is JSON: {text:.80}"
    );
    // The scene named as the log's temporary file once was.
    let target = logged_run(&dir, "t.partial.toml", SMALL, 5, "t.toml");
    assert_eq!(
        std::fs::read_to_string(dir.join("t.partial.toml")).expect("scene"),
        SMALL,
        "scene kept"
    );
    assert_eq!(
        read_log(&target).metadata["weft.status"]["status"],
        "complete"
    );
    let leftovers: Vec<String> = std::fs::read_dir(&dir)
        .expect("dir")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn outputs_named_without_a_directory_are_written_in_the_working_directory() {
    let dir = temp_dir("relative-out");
    write(&dir, "s.toml", SMALL);
    let out = weft()
        .current_dir(&dir)
        .args(["run", "s.toml", "--frames", "3", "--out", "run.mcap"])
        .args(["--dump-final", "final.json"])
        .output()
        .expect("weft runs");
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert_eq!(
        read_log(&dir.join("run.mcap")).metadata["weft.status"]["status"],
        "complete"
    );
    assert!(dir.join("final.json").exists(), "the dump is written");
    let out = weft()
        .current_dir(&dir)
        .args(["recover", "run.mcap", "--out", "again.mcap"])
        .output()
        .expect("weft runs");
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert_eq!(
        read_log(&dir.join("again.mcap")).metadata["weft.status"]["status"],
        "recovered"
    );
}
