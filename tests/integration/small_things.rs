//! What a careful tool gets right: a closed stdout pipe ends quietly, a full device is an error
//! message (never a panic), plots come before the summary, malformed log metadata names its
//! key, a huge bad value is never echoed in full, and the viewer hides its library's paths.

use crate::common;

use std::collections::BTreeMap;
use std::io::Write;
use std::process::Stdio;

use common::*;

#[test]
fn a_closed_pipe_ends_quietly() {
    let dir = temp_dir("pipe");
    let scene = write(&dir, "s.toml", SMALL);
    for args in [
        vec!["run", scene.as_str(), "--frames", "5", "-q"],
        vec!["check", scene.as_str()],
    ] {
        let mut child = weft()
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starts");
        // The reader goes away before weft writes a byte.
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("exits");
        let e = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{e}");
    }
}

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    let dir = temp_dir("stdout-full");
    let scene = write(&dir, "s.toml", SMALL);
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full")
    };
    let out = weft()
        .args(["check", &scene])
        .stdout(full())
        .output()
        .expect("runs");
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("cannot write to standard output"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    // Experiments: the plots are drawn before the summary is printed, so they survive.
    write(
        &dir,
        "exp.toml",
        "scene = \"s.toml\"\nframes = 3\nmetrics = [\"sag\"]\n\n[[series]]\nname = \"s\"\nvary = { \"sim.substeps\" = [1, 2] }\n\n[[plot]]\nfile = \"p.png\"\nx = \"sim.substeps\"\ny = \"sag\"\n",
    );
    let out_dir = dir.join("out");
    let out = weft()
        .args([
            "experiments",
            &dir.join("exp.toml").to_string_lossy(),
            "--no-mcap",
            "--out",
        ])
        .arg(&out_dir)
        .stdout(full())
        .output()
        .expect("runs");
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    assert!(out_dir.join("p.png").exists(), "the plot was drawn first");
}

/// Writes a minimal log whose `weft.run` metadata holds `run`, with the scene attached.
fn log_with(path: &std::path::Path, run: &[(&str, &str)]) {
    let file = std::fs::File::create(path).expect("create");
    let mut w = mcap::WriteOptions::new()
        .create(std::io::BufWriter::new(file))
        .expect("writer");
    w.write_metadata(&mcap::records::Metadata {
        name: "weft.run".into(),
        metadata: run
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect::<BTreeMap<_, _>>(),
    })
    .expect("metadata");
    w.attach(&mcap::Attachment {
        log_time: 0,
        create_time: 0,
        name: "scene/source.toml".into(),
        media_type: "application/toml".into(),
        data: std::borrow::Cow::Borrowed(SMALL.as_bytes()),
    })
    .expect("attach");
    w.finish().expect("finish");
    w.into_inner().flush().expect("flush");
}

#[test]
fn malformed_run_metadata_names_the_key() {
    let dir = temp_dir("bad-metadata");
    let log = dir.join("a.mcap");
    let good = [
        ("scene", "s.toml"),
        ("frames", "5"),
        ("mesh_every", "1"),
        ("timing", "false"),
        ("overrides", "[]"),
    ];
    for (key, bad) in [("frames", "lots"), ("timing", "maybe"), ("overrides", "{")] {
        let run_md: Vec<(&str, &str)> = good
            .iter()
            .map(|&(k, v)| (k, if k == key { bad } else { v }))
            .collect();
        log_with(&log, &run_md);
        let out = run(&[
            "replay",
            &log.to_string_lossy(),
            "--out",
            &dir.join("r.mcap").to_string_lossy(),
        ]);
        let (_, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{key}: {e}");
        assert!(e.contains(&format!("`{key}`")), "{key}: {e}");
    }
}

#[test]
fn a_huge_bad_value_is_cut_short_in_the_message() {
    let dir = temp_dir("huge-value");
    let huge = "x".repeat(1 << 20);
    for text in [
        SMALL.replace("method = \"xpbd\"", &format!("method = \"{huge}\"")),
        SMALL.replace(
            "pins = [\"top-left\", \"top-right\"]",
            &format!("pins = [\"{huge}\"]"),
        ),
        format!("{SMALL}{huge} = 1\n"),
    ] {
        let scene = write(&dir, "s.toml", &text);
        let out = run(&["check", &scene]);
        let (_, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{}", &e[..e.len().min(300)]);
        assert!(
            e.len() < 2000,
            "a {} byte message for a 1 MiB value",
            e.len()
        );
        assert!(e.contains('…'), "{e}");
    }
}

#[test]
fn the_no_display_message_names_no_source_file() {
    let out = weft()
        .arg("view")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", "/nonexistent")
        .output()
        .expect("runs");
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("DISPLAY"), "{e}");
    assert!(!e.contains(".rs:"), "an internal source path: {e}");
}
