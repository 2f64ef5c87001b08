//! `weft replay` fails, naming the first frame and topic that differ, when a log does not
//! reproduce (its scene changed, say); an interrupted log replays over the frames it holds, and
//! a `--timing` log matches but for its wall-clock step times.

use crate::common;

use std::time::Duration;

use common::*;

/// `bytes` with the first `from` inside a record of type `opcode` whose body holds `marker`
/// replaced by `to` (as long), that record's CRC (its last 4 bytes, an attachment's) zeroed
/// when `crc` is set, and the data section's CRC zeroed: a log edited after it was written,
/// whose CRCs say "not computed".
fn edited(bytes: &[u8], opcode: u8, marker: &[u8], from: &[u8], to: &[u8], crc: bool) -> Vec<u8> {
    assert_eq!(from.len(), to.len());
    let find = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).position(|w| w == needle);
    let mut b = bytes.to_vec();
    let mut pos = mcap::MAGIC.len();
    let mut done = false;
    while pos + 9 <= b.len() {
        let len = u64::from_le_bytes(b[pos + 1..pos + 9].try_into().expect("8 bytes"));
        let end = pos + 9 + usize::try_from(len).expect("a length");
        let op = b[pos];
        let body = &mut b[pos + 9..end];
        if !done && op == opcode && find(body, marker).is_some() {
            let at = find(body, from).expect("the text to replace");
            body[at..at + to.len()].copy_from_slice(to);
            if crc {
                let n = body.len();
                body[n - 4..].fill(0);
            }
            done = true;
        }
        if op == mcap::records::op::DATA_END {
            b[pos + 9..pos + 13].fill(0);
            break;
        }
        pos = end;
    }
    assert!(done, "nothing edited");
    b
}

/// Replays `log` into `dir/r.mcap`.
fn replay(dir: &std::path::Path, log: &std::path::Path) -> (Option<i32>, String, String) {
    let out = run(&[
        "replay",
        &log.to_string_lossy(),
        "--out",
        &dir.join("r.mcap").to_string_lossy(),
        "-q",
    ]);
    let (o, e) = texts(&out);
    (out.status.code(), o, e)
}

#[test]
fn a_log_that_does_not_reproduce_fails_naming_the_frame_and_topic() {
    let dir = temp_dir("replay-differs");
    let log = logged_run(&dir, "s.toml", SMALL, 20, "a.mcap");
    let bytes = std::fs::read(&log).expect("log");
    // The scene changed: the cloth is twice as heavy. Frame 0 (the rest pose) still matches.
    let heavier = edited(
        &bytes,
        mcap::records::op::ATTACHMENT,
        b"scene/source.toml",
        b"mass = 0.1",
        b"mass = 0.2",
        true,
    );
    let changed = dir.join("changed.mcap");
    std::fs::write(&changed, heavier).expect("write");
    let (code, o, e) = replay(&dir, &changed);
    assert_eq!(code, Some(1), "{o}{e}");
    assert!(
        e.contains("replay differs from")
            && e.contains("at frame 1 on /cloth/flag/particles")
            && e.contains("does not reproduce"),
        "{e}"
    );
    // Every message matches, but the log says another weft wrote it.
    let version = env!("CARGO_PKG_VERSION");
    let other: String = version
        .chars()
        .map(|c| {
            c.to_digit(10)
                .map_or(c, |d| char::from(b'0' + ((d + 1) % 10) as u8))
        })
        .collect();
    let older = edited(
        &bytes,
        mcap::records::op::METADATA,
        b"weft_version",
        version.as_bytes(),
        other.as_bytes(),
        false,
    );
    let older_log = dir.join("older.mcap");
    std::fs::write(&older_log, older).expect("write");
    let (code, o, e) = replay(&dir, &older_log);
    assert_eq!(code, Some(1), "{o}{e}");
    assert!(
        e.contains("outside its messages, which all match")
            && e.contains("metadata weft.run, `weft_version`"),
        "{e}"
    );
    // The log as written replays byte for byte.
    let (code, o, e) = replay(&dir, &log);
    assert_eq!(code, Some(0), "{o}{e}");
    assert!(o.contains("byte-identical"), "{o}");
}

#[test]
fn an_interrupted_or_timed_log_matches_over_what_it_holds() {
    let dir = temp_dir("replay-interrupted");
    let scene = write(&dir, "s.toml", &big(32));
    let target = dir.join("a.mcap");
    let child = spawn_logging(&["run", &scene, "--frames", "100000000"], &target);
    let grew = partial_grows_past(&target, 1 << 20, Duration::from_secs(60));
    signal(child.id(), "INT");
    let (out, _) = exits_within(child, Duration::from_secs(20));
    assert!(grew, "the log never grew past 1 MiB");
    assert_eq!(out.status.code(), Some(130));
    let log = read_log(&target);
    assert_eq!(log.metadata["weft.status"]["status"], "interrupted");
    let frames = &log.metadata["weft.status"]["frames"];
    let (code, o, e) = replay(&dir, &target);
    assert_eq!(code, Some(0), "{o}{e}");
    assert!(
        o.contains(&format!(
            "over the {frames} frame(s) it holds (interrupted log)"
        )),
        "{o}"
    );

    let timed = dir.join("t.mcap");
    let out = run(&[
        "run",
        &scene,
        "--frames",
        "10",
        "--timing",
        "--out",
        &timed.to_string_lossy(),
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let (code, o, e) = replay(&dir, &timed);
    assert_eq!(code, Some(0), "{o}{e}");
    assert!(
        o.contains("step_ms and log_wait_ms of --timing aside"),
        "{o}"
    );
}

#[test]
fn replay_says_where_it_writes_before_it_starts() {
    let dir = temp_dir("replay-where");
    let log = logged_run(&dir, "s.toml", SMALL, 5, "a.mcap");
    let out = run(&["replay", &log.to_string_lossy(), "-q"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    let beside = dir.join("a.mcap.replay.mcap");
    assert!(beside.exists());
    let line = e
        .lines()
        .next()
        .unwrap_or_else(|| panic!("nothing on stderr: {o}"));
    assert_eq!(
        line,
        format!(
            "weft: replaying {} into {} (--out FILE to choose)",
            log.display(),
            beside.display()
        )
    );
}
