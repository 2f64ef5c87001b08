//! A run killed with SIGKILL leaves its log cut short; `weft recover` rebuilds a valid log
//! (summary, indexes, CRCs) holding every message of the complete chunks, with the scene
//! attachments and status `recovered`; replay says a cut or damaged log is truncated or corrupt
//! and points to `weft recover`.

use crate::common;

use std::time::Duration;

use common::*;

/// Messages the mcap crate itself finds in the complete chunks of `bytes` (a chunk record
/// read whole, its CRC checked by the chunk reader).
fn messages_before_the_cut(bytes: &[u8]) -> usize {
    let records = mcap::read::LinearReader::new_with_options(
        bytes,
        mcap::read::Options::IgnoreEndMagic.into(),
    )
    .expect("starts with the magic");
    let mut n = 0;
    for r in records {
        let Ok(r) = r else { break };
        if let mcap::records::Record::Chunk { header, data } = r {
            let inner: Vec<_> = mcap::read::ChunkReader::new(header, &data)
                .expect("chunk opens")
                .collect::<Result<_, _>>()
                .expect("a complete chunk reads whole");
            n += inner
                .iter()
                .filter(|r| matches!(r, mcap::records::Record::Message { .. }))
                .count();
        }
    }
    n
}

/// Runs a big scene and kills it with SIGKILL once its partial log holds a few chunks.
fn killed_log(dir: &std::path::Path) -> std::path::PathBuf {
    let scene = write(dir, "s.toml", &big(48));
    let target = dir.join("run.mcap");
    let child = spawn_logging(&["run", &scene, "--frames", "100000000"], &target);
    let grew = partial_grows_past(&target, 3 << 20, Duration::from_secs(60));
    let part = partial(&target);
    signal(child.id(), "KILL");
    let (_, _) = exits_within(child, Duration::from_secs(10));
    assert!(grew, "the log never grew past 3 MiB");
    assert!(
        !target.exists(),
        "a killed run leaves nothing under the final name"
    );
    part
}

#[test]
fn a_killed_run_is_recovered_with_every_complete_chunk() {
    let dir = temp_dir("recover");
    let part = killed_log(&dir);
    let bytes = std::fs::read(&part).expect("partial log");
    assert!(
        mcap::Summary::read(&bytes).is_err(),
        "a cut log has no footer"
    );
    let held = messages_before_the_cut(&bytes);
    assert!(held > 0, "no complete chunk before the kill");

    let fixed = dir.join("fixed.mcap");
    let out = run(&[
        "recover",
        &part.to_string_lossy(),
        "--out",
        &fixed.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(o.contains("recovered"), "{o}");
    // read_log checks the summary and reads every message (chunk CRCs checked).
    let log = read_log(&fixed);
    let total: usize = log.counts.values().sum();
    assert_eq!(
        total, held,
        "every message of the complete chunks, and only those"
    );
    let status = &log.metadata["weft.status"];
    assert_eq!(status["status"], "recovered");
    let stats = log.counts["/stats"];
    assert!(stats > 1);
    assert_eq!(
        status["frames"],
        (stats - 1).to_string(),
        "frames after frame 0"
    );
    assert_eq!(log.metadata["weft.run"]["frames"], "100000000");
    assert!(log.attachments.contains(&"scene/source.toml".to_owned()));
    let verified = mcap::read::LinearReader::new(&std::fs::read(&fixed).expect("fixed"))
        .expect("magic")
        .all(|r| r.is_ok());
    assert!(verified, "every record of the recovered log reads");

    // Replay of the cut log: truncated, and how to recover it.
    let out = run(&[
        "replay",
        &part.to_string_lossy(),
        "--out",
        &dir.join("r.mcap").to_string_lossy(),
    ]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("is truncated") && e.contains("weft recover"),
        "{e}"
    );
    assert!(!e.contains("Bad magic"), "{e}");

    // The recovered log replays exactly the frames it holds.
    let out = run(&[
        "replay",
        &fixed.to_string_lossy(),
        "--out",
        &dir.join("r.mcap").to_string_lossy(),
        "-q",
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(o.contains(&format!("{} frames,", stats - 1)), "{o}");
}

#[test]
fn a_log_with_flipped_bytes_is_called_corrupt() {
    let dir = temp_dir("corrupt");
    let log = logged_run(&dir, "s.toml", SMALL, 30, "a.mcap");
    let mut bytes = std::fs::read(&log).expect("log");
    // Flip 16 bytes in the middle of the data section (inside a chunk's compressed data).
    let mid = bytes.len() / 2;
    for b in &mut bytes[mid..mid + 16] {
        *b ^= 0xA5;
    }
    std::fs::write(&log, &bytes).expect("write");
    let out = run(&[
        "replay",
        &log.to_string_lossy(),
        "--out",
        &dir.join("r.mcap").to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{o}{e}");
    assert!(e.contains("is corrupt"), "{e}");
    assert!(!o.contains("replay differs"), "{o}");
}

#[test]
fn a_file_that_is_not_mcap_is_refused_and_nothing_is_written() {
    let dir = temp_dir("recover-not-mcap");
    // Bytes that look like nothing: a small linear congruential generator.
    let mut x: u32 = 61;
    let noise: Vec<u8> = (0..4096)
        .map(|_| {
            x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (x >> 24) as u8
        })
        .collect();
    let mut magic_then_noise = mcap::MAGIC.to_vec();
    magic_then_noise.extend(&noise);
    for (name, bytes, says) in [
        ("s.toml", b"a = 1\n".to_vec(), "is not an MCAP log"),
        ("noise.bin", noise, "is not an MCAP log"),
        ("empty.mcap", Vec::new(), "is empty"),
        ("magic.mcap", magic_then_noise, "nothing to recover"),
    ] {
        let input = dir.join(name);
        std::fs::write(&input, bytes).expect("write");
        let fixed = dir.join("o.mcap");
        let out = run(&[
            "recover",
            &input.to_string_lossy(),
            "--out",
            &fixed.to_string_lossy(),
        ]);
        let (o, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{name}: {o}{e}");
        assert!(e.contains(says), "{name}: {e}");
        assert!(!fixed.exists(), "{name}: no recovered log");
        assert!(!partial(&fixed).exists(), "{name}: no temporary file left");
    }
}

/// The records of `bytes` after the opening magic, as (offset, opcode, body length), up to the
/// first that does not fit.
fn records(bytes: &[u8]) -> Vec<(usize, u8, usize)> {
    let mut v = Vec::new();
    let mut pos = mcap::MAGIC.len();
    while pos + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().expect("8 bytes"));
        let len = usize::try_from(len).expect("a length");
        if pos + 9 + len > bytes.len() {
            break;
        }
        v.push((pos, bytes[pos], len));
        pos += 9 + len;
    }
    v
}

/// Messages in the chunk record at `pos`.
fn messages_in_chunk(bytes: &[u8], pos: usize, len: usize) -> usize {
    let record = mcap::parse_record(mcap::records::op::CHUNK, &bytes[pos + 9..pos + 9 + len])
        .expect("a chunk");
    let mcap::records::Record::Chunk { header, data } = record else {
        panic!("not a chunk");
    };
    mcap::read::ChunkReader::new(header, &data)
        .expect("chunk opens")
        .filter(|r| matches!(r, Ok(mcap::records::Record::Message { .. })))
        .count()
}

/// Recovers `bytes` (written to `dir/name`), checks it succeeded and that the recovered log
/// reads whole, and returns its message count and what recover said.
fn recovered(dir: &std::path::Path, name: &str, bytes: &[u8]) -> (usize, String) {
    let damaged = dir.join(name);
    std::fs::write(&damaged, bytes).expect("write");
    let fixed = dir.join(format!("fixed-{name}"));
    let out = run(&[
        "recover",
        &damaged.to_string_lossy(),
        "--out",
        &fixed.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{name}: {o}{e}");
    let log = read_log(&fixed);
    assert_eq!(log.metadata["weft.status"]["status"], "recovered");
    assert!(log.attachments.contains(&"scene/source.toml".to_owned()));
    (log.counts.values().sum(), o)
}

#[test]
fn a_damaged_record_is_skipped_and_every_intact_chunk_is_kept() {
    let dir = temp_dir("recover-damaged");
    let log = logged_run(&dir, "s.toml", &big(48), 100, "a.mcap");
    let whole = std::fs::read(&log).expect("log");
    // Cut two thirds of the way: no summary (which repeats the schemas and channels), as a
    // killed run leaves its log.
    let cut = &whole[..whole.len() * 2 / 3];
    let chunks: Vec<_> = records(cut)
        .into_iter()
        .filter(|r| r.1 == mcap::records::op::CHUNK)
        .collect();
    assert!(chunks.len() >= 6, "{} chunks", chunks.len());
    let (all, _) = recovered(&dir, "cut.mcap", cut);
    assert_eq!(all, messages_before_the_cut(cut));
    // The first chunk holds only the schemas and channels; the second holds messages.
    let (first, second) = (chunks[0], chunks[1]);
    assert_eq!(messages_in_chunk(cut, first.0, first.2), 0);

    // A flipped byte in a chunk's length field: the chunk reads whole over the records after
    // it (second byte), or runs past the end of the file (third byte). Before, recovery
    // stopped there and kept nothing after it; now nothing is lost.
    for (k, at) in [(1, second.0), (2, second.0), (2, first.0)] {
        let mut bytes = cut.to_vec();
        bytes[at + 1 + k] ^= 0xFF;
        let (n, o) = recovered(&dir, &format!("length-{k}-{at}.mcap"), &bytes);
        assert!(o.contains("1 damaged stretch"), "{o}");
        assert_eq!(n, all, "length byte {k} of the chunk at {at}: {o}");
    }

    // The first chunk damaged inside: its schemas and channels are rebuilt from the
    // `weft.channels` metadata and every message is kept (before: "Message 1 referenced
    // unknown channel 1", and no recovered log).
    let mut bytes = cut.to_vec();
    bytes[first.0 + 9 + first.2 / 2] ^= 0xFF;
    let (n, o) = recovered(&dir, "first.mcap", &bytes);
    assert_eq!(n, all, "{o}");
    assert!(
        o.contains("rebuilt") && o.contains("1 damaged chunk"),
        "{o}"
    );

    // A chunk of messages damaged inside: only its messages are lost, and said to be.
    let (at, len) = (chunks[3].0, chunks[3].2);
    let mut bytes = cut.to_vec();
    bytes[at + 9 + len / 2] ^= 0xFF;
    let (n, o) = recovered(&dir, "middle.mcap", &bytes);
    let lost = messages_in_chunk(cut, at, len);
    assert!(lost > 0);
    assert_eq!(n, all - lost, "{o}");
    assert!(o.contains(&format!("at least {lost} message(s)")), "{o}");
}
