//! `weft replay`: re-runs a logged run from the MCAP alone and compares the result.

use std::collections::BTreeMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};
use weft_scene::{MapFiles, Override, Scene};

use crate::cli::ReplayArgs;
use crate::run::{self, RunPlan};
use weft_record::{Channels, Compression, Precision, RecordOptions};

/// What a log says about the run that wrote it.
pub struct LoggedRun {
    /// `weft.run` metadata.
    pub run: BTreeMap<String, String>,
    /// Attachments by name.
    pub attachments: BTreeMap<String, Vec<u8>>,
    /// `weft.status` metadata, when the log has it.
    pub status: Option<BTreeMap<String, String>>,
}

/// Reads the metadata and attachments of a Weft log.
pub fn read_log(bytes: &[u8]) -> anyhow::Result<LoggedRun> {
    let summary = mcap::Summary::read(bytes)?.context("the log has no summary section")?;
    let mut run = None;
    let mut status = None;
    for idx in &summary.metadata_indexes {
        let m = mcap::read::metadata(bytes, idx)?;
        match m.name.as_str() {
            "weft.run" => run = Some(m.metadata),
            "weft.status" => status = Some(m.metadata),
            _ => {}
        }
    }
    let mut attachments = BTreeMap::new();
    for idx in &summary.attachment_indexes {
        let a = mcap::read::attachment(bytes, idx)?;
        attachments.insert(a.name.clone(), a.data.into_owned());
    }
    let run = run.context("the log has no weft.run metadata: not written by weft run")?;
    Ok(LoggedRun {
        run,
        attachments,
        status,
    })
}

/// A malformed value names its key and shows (a short piece of) what it holds.
fn parsed<T: std::str::FromStr>(key: &str, v: &str, what: &str) -> anyhow::Result<T> {
    v.trim().parse().map_err(|_| {
        anyhow::anyhow!(
            "weft.run metadata: `{key}` must be {what}, got {:?}",
            weft_scene::elide(v)
        )
    })
}

/// The `weft.run` metadata value `key`, parsed.
fn run_value<T: std::str::FromStr>(log: &LoggedRun, key: &str, what: &str) -> anyhow::Result<T> {
    let v = log
        .run
        .get(key)
        .with_context(|| format!("weft.run metadata lacks `{key}`"))?;
    parsed(key, v, what)
}

/// A `weft.run` value that older logs do not have, or `default` when absent.
fn run_value_or<T: std::str::FromStr>(
    log: &LoggedRun,
    key: &str,
    what: &str,
    default: T,
) -> anyhow::Result<T> {
    match log.run.get(key) {
        Some(v) => parsed(key, v, what),
        None => Ok(default),
    }
}

/// The scene a log was run with, rebuilt from its `scene/source.toml` and `files/…`
/// attachments with the logged overrides (as `weft replay` and `weft export` need it).
pub fn logged_scene(log: &LoggedRun, limits: &weft_scene::Limits) -> anyhow::Result<Scene> {
    let name = log
        .run
        .get("scene")
        .context("weft.run metadata lacks `scene`")?;
    let overrides: String = run_value(log, "overrides", "a JSON list of KEY=VALUE")?;
    let overrides: Vec<String> = serde_json::from_str(&overrides).map_err(|e| {
        anyhow::anyhow!("weft.run metadata: `overrides` must be a JSON list of KEY=VALUE: {e}")
    })?;
    let overrides: Vec<Override> = overrides
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow::anyhow!("weft.run metadata: `overrides`: {e}"))?;
    let source = log
        .attachments
        .get("scene/source.toml")
        .context("the log has no scene/source.toml attachment")?;
    let source = String::from_utf8_lossy(source).into_owned();
    let files = MapFiles(
        log.attachments
            .iter()
            .filter_map(|(k, v)| Some((k.strip_prefix("files/")?.to_owned(), v.clone())))
            .collect(),
    );
    match weft_scene::from_text_with(name, &source, &overrides, &files, limits) {
        Ok(s) => Ok(s),
        Err(e) => bail!("the logged scene no longer validates:\n{e}"),
    }
}

/// Runs `weft replay`.
pub fn replay(args: &ReplayArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let bytes = weft_scene::read_regular(&args.log, u64::MAX)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", args.log.display()))?;
    // Whole and every CRC intact, or say what is wrong and how to recover it.
    if let Err(fault) = weft_record::verify::verify(&bytes, stop) {
        bail!("{}", fault.message(&args.log));
    }
    let log = read_log(&bytes).with_context(|| format!("{}", args.log.display()))?;
    let logged_frames: u64 = run_value(&log, "frames", "a frame count")?;
    let mesh_every: u64 = run_value(&log, "mesh_every", "a frame count")?;
    let timing: bool = run_value(&log, "timing", "true or false")?;
    let record = RecordOptions {
        channels: run_value_or(&log, "log", "particles, surface or all", Channels::All)?,
        every: run_value_or(&log, "every", "a frame count", 1)?,
        mesh_every,
        precision: run_value_or(&log, "precision", "f32 or f16", Precision::F32)?,
        compression: run_value_or(&log, "compression", "none or zstd", Compression::Zstd)?,
        timing,
    };
    // A log cut short (interrupted, recovered) holds fewer frames than were asked for: replay
    // the frames it holds.
    let cut_short = log.status.as_ref().and_then(|st| {
        let status = st.get("status")?;
        matches!(status.as_str(), "interrupted" | "recovered").then_some((status, st.get("frames")))
    });
    let frames = match cut_short {
        Some((_, held)) => {
            let held = held.map(String::as_str).unwrap_or("");
            parsed::<u64>("weft.status frames", held, "a frame count")?.min(logged_frames)
        }
        None => logged_frames,
    };
    let scene = logged_scene(&log, &args.limits.limits())?;
    let out = args.out.clone().unwrap_or_else(|| {
        let mut p = args.log.clone().into_os_string();
        p.push(".replay.mcap");
        PathBuf::from(p)
    });
    eprintln!(
        "weft: replaying {} into {}{}",
        args.log.display(),
        out.display(),
        if args.out.is_none() {
            " (--out FILE to choose)"
        } else {
            ""
        }
    );
    let plan = RunPlan {
        inputs: vec![("the log", args.log.clone())],
        frames,
        out: Some(&out),
        dump_final: None,
        record,
        progress: !args.quiet,
        strict: false,
    };
    let code = run::run(scene, &plan, stop)?;
    if stop.load(Ordering::SeqCst) {
        return Ok(code);
    }
    let again = std::fs::read(&out).with_context(|| format!("cannot read {}", out.display()))?;
    let name = args.log.display();
    if again == bytes {
        say!("replay is byte-identical to {name}")?;
        return Ok(code);
    }
    if let Some(difference) = first_difference(&bytes, &again, cut_short.is_some(), timing)? {
        bail!(
            "replay differs from {name} {difference}; the replay is in {}",
            out.display()
        );
    }
    match cut_short {
        Some((status, _)) => {
            say!(
                "replay matches every message of {name} over the {frames} frame(s) it holds ({status} log)"
            )?;
        }
        None => say!(
            "replay matches every message of {name} (the wall-clock step_ms and log_wait_ms of --timing aside)"
        )?,
    }
    Ok(code)
}

/// Why a replay whose messages differ from its log's does so.
const NO_REPRODUCTION: &str = ": the logged run does not reproduce (its scene or the simulation \
                               changed since it was written)";

/// Where a replay first differs from its log, in words: the frame and topic of the first message
/// that differs, and how; or, when every message matches, the first metadata record or
/// attachment that differs. Messages are matched by sequence number. A log cut short
/// (`partial`: interrupted, recovered) is compared over the messages it holds (a recovered log
/// may lack some), and only by its messages; with `timing`, `/stats` messages are compared
/// without their wall-clock `step_ms`, and only messages are compared.
fn first_difference(
    logged: &[u8],
    again: &[u8],
    partial: bool,
    timing: bool,
) -> anyhow::Result<Option<String>> {
    let mut replayed = mcap::MessageStream::new(again)?;
    // Frame k's messages come before its `/stats` message.
    let mut frame = 0_u64;
    for m in mcap::MessageStream::new(logged)? {
        let m = m?;
        let topic = &m.channel.topic;
        let r = loop {
            match replayed.next().transpose()? {
                Some(r) if partial && r.sequence < m.sequence => {
                    frame += u64::from(r.channel.topic == "/stats");
                }
                r => break r,
            }
        };
        let at = format!("at frame {frame} on {topic}");
        let Some(r) = r else {
            let why = format!("{at} (the replay ends before it){NO_REPRODUCTION}");
            return Ok((!partial).then_some(why));
        };
        let why = if r.channel.topic != *topic {
            format!("the replay has {} there", r.channel.topic)
        } else if r.sequence != m.sequence {
            format!(
                "message {} of the log is message {} of the replay",
                m.sequence, r.sequence
            )
        } else if r.log_time != m.log_time {
            format!("log time {} ns, replayed at {} ns", m.log_time, r.log_time)
        } else if !same_data(topic, &m.data, &r.data, timing) {
            format!("message {}: its data differ", m.sequence)
        } else {
            frame += u64::from(topic == "/stats");
            continue;
        };
        return Ok(Some(format!("{at} ({why}){NO_REPRODUCTION}")));
    }
    if let Some(r) = replayed.next().transpose()?
        && !partial
    {
        let topic = &r.channel.topic;
        return Ok(Some(format!(
            "at frame {frame} on {topic} (the log ends before it){NO_REPRODUCTION}"
        )));
    }
    if partial || timing {
        return Ok(None);
    }
    outside_messages(logged, again).map(Some)
}

/// Whether two messages on `topic` hold the same data (for `/stats` with `timing`, the same
/// JSON but for `step_ms`).
fn same_data(topic: &str, a: &[u8], b: &[u8], timing: bool) -> bool {
    let without_step_ms = |d: &[u8]| {
        let mut v = serde_json::from_slice::<serde_json::Value>(d).ok()?;
        let o = v.as_object_mut()?;
        o.remove("step_ms");
        o.remove("log_wait_ms");
        Some(v)
    };
    a == b
        || (timing
            && topic == "/stats"
            && without_step_ms(a).is_some_and(|a| Some(a) == without_step_ms(b)))
}

/// The first metadata record (and key) or attachment in which two logs whose messages match
/// differ, in words.
fn outside_messages(logged: &[u8], again: &[u8]) -> anyhow::Result<String> {
    let (a, b) = (records_outside(logged)?, records_outside(again)?);
    for i in 0..a.len().max(b.len()) {
        let why = match (a.get(i), b.get(i)) {
            (Some(x), Some(y)) if x == y => continue,
            (Some((x, _)), Some((y, _))) if x != y => {
                format!("the log has {x} where the replay has {y}")
            }
            (Some((name, x)), Some((_, y))) => {
                let key = x.keys().chain(y.keys()).find(|k| x.get(*k) != y.get(*k));
                let value = |m: &BTreeMap<String, String>, k: &str| {
                    m.get(k).map_or("nothing".to_owned(), |v| {
                        format!("{:?}", weft_scene::elide(v))
                    })
                };
                match key {
                    Some(k) => format!(
                        "{name}, `{k}`: {} in the log, {} in the replay",
                        value(x, k),
                        value(y, k)
                    ),
                    None => format!("{name} differs"),
                }
            }
            (Some((name, _)), None) => format!("the replay lacks {name}"),
            (None, Some((name, _))) => format!("the log lacks {name}"),
            (None, None) => break,
        };
        return Ok(format!(
            "outside its messages, which all match: {why} (written by another version of weft?)"
        ));
    }
    Ok(
        "outside its messages, metadata and attachments, which all match (written by another \
        version of weft?)"
            .into(),
    )
}

/// A log's metadata records and attachments, in order: `metadata NAME` with its keys, and
/// `attachment NAME` with its size and a hash of its bytes.
fn records_outside(bytes: &[u8]) -> anyhow::Result<Vec<(String, BTreeMap<String, String>)>> {
    let summary = mcap::Summary::read(bytes)?.context("the log has no summary section")?;
    let mut v = Vec::new();
    for idx in &summary.metadata_indexes {
        let m = mcap::read::metadata(bytes, idx)?;
        v.push((format!("metadata {}", m.name), m.metadata));
    }
    for idx in &summary.attachment_indexes {
        let a = mcap::read::attachment(bytes, idx)?;
        let mut h = DefaultHasher::new();
        a.data.hash(&mut h);
        let contents = format!("{} bytes, hash {:016x}", a.data.len(), h.finish());
        v.push((
            format!("attachment {}", a.name),
            BTreeMap::from([("contents".to_owned(), contents)]),
        ));
    }
    Ok(v)
}
