//! `weft replay`: re-runs a logged run from the MCAP alone and compares the result.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use anyhow::{Context, bail};
use weft_scene::{MapFiles, Override, Scene};

use crate::cli::ReplayArgs;
use crate::record::RecordOptions;
use crate::run::{self, RunPlan};

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
    if let Err(fault) = crate::record::verify::verify(&bytes) {
        bail!("{}", fault.message(&args.log));
    }
    let log = read_log(&bytes).with_context(|| format!("{}", args.log.display()))?;
    let logged_frames: u64 = run_value(&log, "frames", "a frame count")?;
    let mesh_every: u64 = run_value(&log, "mesh_every", "a frame count")?;
    let timing: bool = run_value(&log, "timing", "true or false")?;
    // A log cut short (interrupted, recovered) holds fewer frames than were asked for: replay
    // the frames it holds.
    let frames = match &log.status {
        Some(st)
            if matches!(
                st.get("status").map(String::as_str),
                Some("interrupted" | "recovered")
            ) =>
        {
            let held = st.get("frames").map(String::as_str).unwrap_or("");
            parsed::<u64>("weft.status frames", held, "a frame count")?.min(logged_frames)
        }
        _ => logged_frames,
    };
    let scene = logged_scene(&log, &args.limits.limits())?;
    let out = args.out.clone().unwrap_or_else(|| {
        let mut p = args.log.clone().into_os_string();
        p.push(".replay.mcap");
        PathBuf::from(p)
    });
    let plan = RunPlan {
        inputs: vec![("the log", args.log.clone())],
        frames,
        out: Some(&out),
        dump_final: None,
        record: RecordOptions { mesh_every, timing },
        progress: !args.quiet,
    };
    let code = run::run(scene, &plan, stop)?;
    let again = std::fs::read(&out)?;
    if again == bytes {
        say!("replay is byte-identical to {}", args.log.display())?;
    } else {
        say!(
            "replay differs from {} (expected if the log was interrupted, diverged, or used --timing)",
            args.log.display()
        )?;
    }
    Ok(code)
}
