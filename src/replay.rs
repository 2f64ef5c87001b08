//! `weft replay`: re-runs a logged run from the MCAP alone and compares the result.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

use anyhow::{Context, bail};
use weft_scene::{MapFiles, Override};

use crate::cli::ReplayArgs;
use crate::record::RecordOptions;
use crate::run::{self, RunPlan};

/// What a log says about the run that wrote it.
pub struct LoggedRun {
    /// `weft.run` metadata.
    pub run: BTreeMap<String, String>,
    /// Attachments by name.
    pub attachments: BTreeMap<String, Vec<u8>>,
}

/// Reads the metadata and attachments of a Weft log.
pub fn read_log(bytes: &[u8]) -> anyhow::Result<LoggedRun> {
    let summary = mcap::Summary::read(bytes)?.context("the log has no summary section")?;
    let mut run = None;
    for idx in &summary.metadata_indexes {
        let m = mcap::read::metadata(bytes, idx)?;
        if m.name == "weft.run" {
            run = Some(m.metadata);
        }
    }
    let mut attachments = BTreeMap::new();
    for idx in &summary.attachment_indexes {
        let a = mcap::read::attachment(bytes, idx)?;
        attachments.insert(a.name.clone(), a.data.into_owned());
    }
    let run = run.context("the log has no weft.run metadata: not written by weft run")?;
    Ok(LoggedRun { run, attachments })
}

/// Runs `weft replay`.
pub fn replay(args: &ReplayArgs, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    let bytes =
        std::fs::read(&args.log).with_context(|| format!("cannot read {}", args.log.display()))?;
    let log = read_log(&bytes).with_context(|| format!("{}", args.log.display()))?;
    let get = |k: &str| {
        log.run
            .get(k)
            .with_context(|| format!("weft.run metadata lacks `{k}`"))
    };
    let name = get("scene")?.clone();
    let frames: u64 = get("frames")?.parse()?;
    let mesh_every: u64 = get("mesh_every")?.parse()?;
    let timing: bool = get("timing")?.parse()?;
    let overrides: Vec<String> = serde_json::from_str(get("overrides")?)?;
    let overrides: Vec<Override> = overrides
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
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
    let scene = match weft_scene::from_text(&name, &source, &overrides, &files) {
        Ok(s) => s,
        Err(e) => bail!("the logged scene no longer validates:\n{e}"),
    };
    let out = args.out.clone().unwrap_or_else(|| {
        let mut p = args.log.clone().into_os_string();
        p.push(".replay.mcap");
        PathBuf::from(p)
    });
    let plan = RunPlan {
        frames,
        out: Some(&out),
        dump_final: None,
        record: RecordOptions { mesh_every, timing },
        progress: !args.quiet,
    };
    let code = run::run(scene, &plan, stop)?;
    let again = std::fs::read(&out)?;
    if again == bytes {
        println!("replay is byte-identical to {}", args.log.display());
    } else {
        println!(
            "replay differs from {} (expected if the log was interrupted, diverged, or used --timing)",
            args.log.display()
        );
    }
    Ok(code)
}
