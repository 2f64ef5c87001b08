//! Names that look like a temporary file never cost a file: `recover` and `replay` leave their
//! input as it was whatever it is called, and outputs named like another output's temporary
//! file (or an input named so) are each written where they were asked to be.

use crate::common;

use common::*;

/// The MCAP file magic.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

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
            let fixed = std::fs::read(dir.join(to)).expect("recovered log");
            assert!(fixed.starts_with(MAGIC), "{to} is not MCAP");
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
    assert!(
        std::fs::read(&replayed)
            .expect("replay's log")
            .starts_with(MAGIC)
    );
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
    assert!(
        std::fs::read(&log).expect("log").starts_with(MAGIC),
        "the log is MCAP"
    );
    let text = std::fs::read_to_string(&dump).expect("dump");
    assert!(
        serde_json::from_str::<serde_json::Value>(&text).is_ok(),
        "the dump is JSON: {text:.80}"
    );
    // The scene named as the log's temporary file once was.
    let named = write(&dir, "t.partial.toml", SMALL);
    let target = dir.join("t.toml");
    let out = run(&[
        "run",
        &named,
        "--frames",
        "5",
        "--out",
        &target.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert_eq!(
        std::fs::read_to_string(&named).expect("scene"),
        SMALL,
        "scene kept"
    );
    assert!(std::fs::read(&target).expect("log").starts_with(MAGIC));
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
    assert!(
        std::fs::read(dir.join("run.mcap"))
            .expect("log")
            .starts_with(MAGIC)
    );
    assert!(dir.join("final.json").exists(), "the dump is written");
    let out = weft()
        .current_dir(&dir)
        .args(["recover", "run.mcap", "--out", "again.mcap"])
        .output()
        .expect("weft runs");
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(
        dir.join("again.mcap").exists(),
        "the recovered log is written"
    );
}
