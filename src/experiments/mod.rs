//! `weft experiments`: the recorder. Runs a queue of scene variants in parallel (optionally one
//! shard of it), logs each run to MCAP, and writes a summary table and plots.

mod metrics;
mod montage;
mod plot;
mod progress;
mod report;
mod spec;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::cli::ExperimentArgs;
use crate::record::{RecordOptions, Recorder, Status};
use crate::sim::Simulation;
use metrics::Meter;
use spec::{PlannedRun, Spec, parse_shard};

/// What one run produced (written as `results/run-<index>.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunResult {
    /// Position in the queue.
    pub index: usize,
    /// Series name.
    pub series: String,
    /// Swept values.
    pub label: String,
    /// `complete`, `interrupted` or `diverged: …`.
    pub status: String,
    /// Metric values by name (null when not finite).
    pub metrics: std::collections::BTreeMap<String, Option<f64>>,
    /// The run's MCAP, relative to the output directory.
    pub mcap: Option<String>,
}

fn slug(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    while out.contains("--") {
        out = out.replace("--", "-");
    }
    out.trim_matches('-').chars().take(60).collect()
}

/// Runs `weft experiments`.
pub fn run(args: &ExperimentArgs, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    let spec = Spec::load(&args.file)?;
    let runs = spec.expand()?;
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "experiments".into());
        PathBuf::from("experiments-out").join(stem)
    });
    std::fs::create_dir_all(out.join("results"))
        .and_then(|()| std::fs::create_dir_all(out.join("runs")))
        .with_context(|| format!("cannot create {}", out.display()))?;
    let mut failed = false;
    if !args.report_only {
        let shard = args.shard.as_deref().map(parse_shard).transpose()?;
        let mine: Vec<&PlannedRun> = runs
            .iter()
            .filter(|r| shard.is_none_or(|(k, n)| r.index % n == k))
            .collect();
        let scene_path = spec.scene_path(&args.file);
        // Validate every run's scene before simulating any.
        let mut scenes = Vec::new();
        for r in &mine {
            match weft_scene::load(&scene_path, &r.overrides) {
                Ok(s) => scenes.push(s),
                Err(e) => bail!("run {} ({} {}):\n{e}", r.index, r.series, r.label),
            }
        }
        let jobs = args
            .jobs
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
        eprintln!(
            "weft: {}: {} of {} runs{}, {} at a time, into {}",
            args.file.display(),
            mine.len(),
            runs.len(),
            shard
                .map(|(k, n)| format!(" (shard {k}/{n})"))
                .unwrap_or_default(),
            jobs,
            out.display()
        );
        let gpu = args
            .render
            .then(weft_render::Gpu::headless)
            .transpose()
            .context("cannot render (--render)")?;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build()?;
        let bar = progress::QueueProgress::new(mine.len());
        let results: Vec<anyhow::Result<RunResult>> = pool.install(|| {
            mine.par_iter()
                .zip(scenes)
                .map(|(r, scene)| {
                    let res = execute(&spec, r, scene, &out, !args.no_mcap, gpu.as_ref(), stop);
                    bar.done(&match &res {
                        Ok(x) => format!(
                            "  run {:>3} {} {}: {}",
                            r.index, r.series, r.label, x.status
                        ),
                        Err(e) => format!(
                            "  run {:>3} {} {}: error: {e:#}",
                            r.index, r.series, r.label
                        ),
                    });
                    res
                })
                .collect()
        });
        bar.finish();
        let mut tiles: Vec<(String, montage::Tile)> = Vec::new();
        for (r, res) in mine.iter().zip(results) {
            match res {
                Ok(result) => {
                    tiles.push((
                        r.series.clone(),
                        montage::Tile {
                            label: r.label.clone(),
                            dir: out.join(run_dir(r)),
                            diverged: result.status.starts_with("diverged"),
                        },
                    ));
                    failed |= result.status != "complete";
                    let path = out.join("results").join(format!("run-{}.json", r.index));
                    std::fs::write(&path, serde_json::to_string_pretty(&result)?)
                        .with_context(|| format!("cannot write {}", path.display()))?;
                }
                Err(_) => failed = true,
            }
        }
        if gpu.is_some() {
            write_montages(&spec.title, tiles, &out)?;
        }
    }
    report::write(&spec, &runs, &out)?;
    if stop.load(Ordering::SeqCst) {
        return Ok(ExitCode::from(crate::run::EXIT_INTERRUPTED));
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// A run's folder (and, with `.mcap`, its log) relative to the output directory.
fn run_dir(r: &PlannedRun) -> String {
    format!(
        "runs/{:03}-{}",
        r.index,
        slug(&format!("{} {}", r.series, r.label))
    )
}

/// One side-by-side video per series, of its runs in queue order (`series/<series>/`).
fn write_montages(
    title: &str,
    tiles: Vec<(String, montage::Tile)>,
    out: &Path,
) -> anyhow::Result<()> {
    let mut names: Vec<String> = Vec::new();
    for (s, _) in &tiles {
        if !names.contains(s) {
            names.push(s.clone());
        }
    }
    for name in names {
        let of: Vec<montage::Tile> = tiles
            .iter()
            .filter(|(s, _)| *s == name)
            .map(|(_, t)| montage::Tile {
                label: t.label.clone(),
                dir: t.dir.clone(),
                diverged: t.diverged,
            })
            .collect();
        let dir = out.join("series").join(slug(&name));
        let files = montage::write(&format!("{title}: {name}"), &of, &dir)?;
        for f in files {
            eprintln!("  series {name}: {}", f.display());
        }
    }
    Ok(())
}

fn execute(
    spec: &Spec,
    r: &PlannedRun,
    scene: weft_scene::Scene,
    out: &Path,
    mcap: bool,
    gpu: Option<&weft_render::Gpu>,
    stop: &AtomicBool,
) -> anyhow::Result<RunResult> {
    let dt = scene.settings.dt;
    let frames = match (spec.frames, spec.duration) {
        (Some(f), _) => f,
        (None, Some(d)) => (d / dt).round().max(1.0) as u64,
        (None, None) => 1,
    };
    let mut sim = Simulation::new(scene)?;
    let rel = format!("{}.mcap", run_dir(r));
    let mut rec = if mcap {
        let file = crate::run::create_output(&out.join(&rel))?;
        let options = RecordOptions {
            mesh_every: 0,
            timing: false,
        };
        Some(Recorder::new(file, &sim, frames, options)?)
    } else {
        None
    };
    // With --render: about 30 images per simulated second, into the run's own directory.
    let mut video = gpu
        .map(|gpu| {
            let dir = out.join(rel.trim_end_matches(".mcap"));
            let every = (1.0 / (30.0 * dt)).round().max(1.0) as u64;
            let size = glam::UVec2::new(640, 480);
            let options = weft_render::RenderOptions::default();
            crate::video::VideoRecorder::new(gpu, &sim, &dir, size, every, options)
        })
        .transpose()?;
    let mut meter = Meter::new(&sim);
    let start = Instant::now();
    let mut status = Status::Complete;
    let mut first = sim.stats(0.0, 0);
    first.frame = 0;
    let logged = (|| -> anyhow::Result<()> {
        if let Some(rec) = rec.as_mut() {
            rec.frame(&sim, &first)?;
        }
        for _ in 0..frames {
            if stop.load(Ordering::SeqCst) {
                status = Status::Interrupted;
                break;
            }
            match sim.step() {
                Ok(stats) => {
                    meter.frame(&stats);
                    if let Some(rec) = rec.as_mut() {
                        rec.frame(&sim, &stats)?;
                    }
                    if let Some(v) = video.as_mut() {
                        v.frame(&sim)?;
                    }
                }
                Err(e) => {
                    status = Status::Diverged(e.to_string());
                    break;
                }
            }
        }
        Ok(())
    })();
    if let Some(rec) = rec {
        rec.finish(&status, sim.frame())?;
    }
    logged?;
    // A run that diverged keeps its frames up to the divergence, marked.
    if let Some(v) = video {
        match &status {
            Status::Diverged(m) => v.finish_diverged(m)?,
            _ => v.finish()?,
        };
    }
    let _ = start;
    let metrics = meter
        .values(&sim)
        .into_iter()
        .map(|(m, v)| (m.name().to_owned(), v.is_finite().then_some(v)))
        .collect();
    Ok(RunResult {
        index: r.index,
        series: r.series.clone(),
        label: r.label.clone(),
        status: match status {
            Status::Complete => "complete".into(),
            Status::Interrupted => "interrupted".into(),
            Status::Diverged(m) => format!("diverged: {m}"),
        },
        metrics,
        mcap: mcap.then_some(rel),
    })
}
