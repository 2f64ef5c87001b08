//! `weft experiments`: the recorder. Runs a queue of scene variants in parallel (optionally one
//! shard of it), logs each run to MCAP, and writes a summary table and plots.
//!
//! Its modules:
//!
//! - `cantilever`: the cantilever bending test in an experiments file, a strip per run.
//! - `front`: cost–accuracy fronts: the runs no cheaper run of their series beats.
//! - `metrics`: metrics of one run, measured while it steps.
//! - `montage`: every rendered run of a series tiled into one labelled video.
//! - `plot`: PNG line plots of one metric against a swept key, one line per series.
//! - `progress`: progress while `weft experiments` runs: one bar for the queue, on a terminal.
//! - `reference`: a converged reference run that the accuracy metrics compare every run with.
//! - `report`: the queue's summary: CSV, Markdown and plots, from every run result present.
//! - `spec`: the experiments file, expanded into a numbered queue of runs.

mod cantilever;
mod front;
mod metrics;
mod montage;
mod plot;
mod progress;
mod reference;
mod report;
mod spec;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use weft_scene::Override;

use crate::cli::ExperimentArgs;
use crate::output::{Named, Output, refuse_clashes};
use metrics::Meter;
use spec::{PlannedRun, Spec, parse_shard};
use weft_record::{RecordOptions, Recorder, Status};
use weft_sim::Simulation;

/// A run and its result, when it has one (a row of the summary and of its plots).
pub struct Row<'a> {
    /// The planned run.
    pub run: &'a PlannedRun,
    /// Its result.
    pub result: RunResult,
}

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

impl RunResult {
    /// The result of a run that never started.
    pub fn not_run(r: &PlannedRun) -> Self {
        Self {
            index: r.index,
            series: r.series.clone(),
            label: r.label.clone(),
            status: NOT_RUN.into(),
            metrics: Default::default(),
            mcap: None,
        }
    }
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

/// Refuses a queue whose runs, `jobs` at a time, could need more memory together than the
/// limit allows (each alone was checked when it was loaded): the `jobs` largest estimates
/// are what may be built at once, in one process (whose own base is counted once).
fn refuse_concurrent_memory(
    needs: &[u64],
    jobs: usize,
    limits: &weft_scene::Limits,
) -> anyhow::Result<()> {
    let Some((cap, origin)) = &limits.max_memory else {
        return Ok(());
    };
    let mut sorted = needs.to_vec();
    sorted.sort_unstable_by(|a, b| b.cmp(a));
    let at_once = jobs.min(sorted.len());
    let base = weft_scene::BASE_BYTES;
    let need: u64 = sorted
        .iter()
        .take(at_once)
        .fold(base, |a, b| a.saturating_add(b.saturating_sub(base)));
    if need > *cap {
        bail!(
            "{at_once} runs at a time may need about {} together, more than the {} allowed \
             ({origin}); lower --jobs, or raise the limit with --max-memory",
            weft_scene::human(need),
            weft_scene::human(*cap)
        );
    }
    Ok(())
}

/// Queues longer than this are run only with `--yes`.
pub const ASK_ABOVE_RUNS: u64 = 1000;
/// Queues longer than this are refused outright (their plan alone would fill memory).
pub const MAX_RUNS: u64 = 1_000_000;
/// `--jobs` above this many per core is cut to it.
pub const JOBS_PER_CORE: usize = 4;

/// The status of a planned run that never started (interrupted queue, other shard).
pub const NOT_RUN: &str = "not run";

/// The path of run `index`'s result under `out`.
pub fn result_path(out: &Path, index: usize) -> PathBuf {
    out.join("results").join(format!("run-{index}.json"))
}

/// The finished result of `r` under `out`, if there is one (complete or diverged: an
/// interrupted run is run again).
fn finished_result(out: &Path, r: &PlannedRun) -> Option<RunResult> {
    let text = std::fs::read_to_string(result_path(out, r.index)).ok()?;
    let res: RunResult = serde_json::from_str(&text).ok()?;
    (res.series == r.series
        && res.label == r.label
        && (res.status == "complete" || res.status.starts_with("diverged")))
    .then_some(res)
}

/// Runs `weft experiments`.
pub fn run(args: &ExperimentArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let spec = Spec::load(&args.file)?;
    // Everything that can be refused is refused before a directory is made or a run starts.
    let shard = args.shard.as_deref().map(parse_shard).transpose()?;
    let count = spec.count();
    if count > MAX_RUNS {
        bail!(
            "{}: the queue holds {count} runs, more than {MAX_RUNS}: split the sweep",
            args.file.display()
        );
    }
    if count > ASK_ABOVE_RUNS && !args.yes && !args.report_only {
        bail!(
            "{}: the queue holds {count} runs (more than {ASK_ABOVE_RUNS}); run it with --yes \
             if that is what you meant",
            args.file.display()
        );
    }
    let runs = spec.expand()?;
    spec.check_plots(&runs)
        .with_context(|| format!("{}", args.file.display()))?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs = match args.jobs {
        Some(j) if j as usize > JOBS_PER_CORE * cores => {
            eprintln!(
                "weft: --jobs {j} cut to {} ({JOBS_PER_CORE} per core on {cores} cores)",
                JOBS_PER_CORE * cores
            );
            JOBS_PER_CORE * cores
        }
        Some(j) => j as usize,
        None => cores,
    };
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "experiments".into());
        PathBuf::from("experiments-out").join(stem)
    });
    let scene_path = spec.scene_path(&args.file);
    // The report's files may not be an input (the experiments file, the scene).
    let report_files = report::files(&spec, &out);
    refuse_clashes(
        &[
            Named {
                role: "the experiments file",
                path: &args.file,
            },
            Named {
                role: "the scene",
                path: &scene_path,
            },
        ],
        &report_files
            .iter()
            .map(|(role, path)| Named { role, path })
            .collect::<Vec<_>>(),
    )?;
    std::fs::create_dir_all(out.join("results"))
        .and_then(|()| std::fs::create_dir_all(out.join("runs")))
        .with_context(|| format!("cannot create {}", out.display()))?;
    let mut failed = false;
    if !args.report_only {
        let mut mine: Vec<&PlannedRun> = runs
            .iter()
            .filter(|r| shard.is_none_or(|(k, n)| r.index % n == k))
            .collect();
        if args.resume {
            let before = mine.len();
            mine.retain(|r| finished_result(&out, r).is_none());
            eprintln!(
                "weft: --resume: {} of {before} runs already have results",
                before - mine.len()
            );
        }
        // Validate every run's scene before simulating any, keeping only its memory estimate:
        // a loaded scene holds its cloths' meshes, so each run loads its own when it starts.
        // `jobs` at a time, as the runs will go (a scene loaded is less than its run needs).
        let limits = args.limits.limits();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build()?;
        let prepared: Vec<_> = pool.install(|| {
            mine.par_iter()
                .map(|r| {
                    cantilever::prepare(
                        spec.cantilever.as_ref(),
                        &scene_path,
                        &r.overrides,
                        &limits,
                    )
                })
                .collect()
        });
        let mut strips = Vec::with_capacity(mine.len());
        for (r, p) in mine.iter().zip(prepared) {
            strips.push(p.with_context(|| format!("run {} ({} {})", r.index, r.series, r.label))?);
        }
        let loaded: Vec<_> = pool.install(|| {
            strips
                .par_iter()
                .map(|(overrides, _)| {
                    weft_scene::load_with(&scene_path, overrides, &limits)
                        .map(|s| s.estimated_bytes())
                })
                .collect()
        });
        let mut needs = Vec::with_capacity(mine.len());
        for (r, need) in mine.iter().zip(loaded) {
            match need {
                Ok(bytes) => needs.push(bytes),
                Err(e) => bail!("run {} ({} {}):\n{e}", r.index, r.series, r.label),
            }
        }
        refuse_concurrent_memory(&needs, jobs, &limits)?;
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
        // From here a signal raises the flag: running runs close their logs, runs not yet
        // started are left `not run`.
        let _polling = crate::stop::Polling::start();
        let reference =
            run_reference(&spec, &scene_path, &limits, stop).context("the [reference] run")?;
        let bar = progress::QueueProgress::new(mine.len());
        let results: Vec<anyhow::Result<RunResult>> = pool.install(|| {
            mine.par_iter()
                .zip(&strips)
                .map(|(r, (overrides, strip))| {
                    if stop.load(Ordering::SeqCst) {
                        bar.done(&format!(
                            "  run {:>3} {} {}: {NOT_RUN}",
                            r.index, r.series, r.label
                        ));
                        return Ok(RunResult::not_run(r));
                    }
                    let res = weft_scene::load_with(&scene_path, overrides, &limits)
                        .map_err(|e| anyhow::anyhow!("{e}"))
                        .and_then(|scene| {
                            let sim = Simulation::new(scene)?;
                            for line in crate::stability::warnings(&sim.groups) {
                                bar.note(&format!(
                                    "  run {:>3} {} {}: warning: {line}",
                                    r.index, r.series, r.label
                                ));
                            }
                            let run = Execute {
                                spec: &spec,
                                run: r,
                                strip: *strip,
                                reference: reference.as_ref(),
                            };
                            run.execute(sim, &out, !args.no_mcap, gpu.as_ref(), stop)
                        })
                        .and_then(|result| {
                            // Written as soon as the run ends, so a killed queue keeps what it did.
                            let path = result_path(&out, r.index);
                            crate::output::write_file(
                                &path,
                                serde_json::to_string_pretty(&result)?.as_bytes(),
                            )?;
                            Ok(result)
                        });
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

/// One run to execute: its plan, and its cantilever strip and the experiment's reference
/// where the file has them.
struct Execute<'a> {
    spec: &'a Spec,
    run: &'a PlannedRun,
    strip: Option<cantilever::Strip>,
    reference: Option<&'a Arc<reference::Reference>>,
}

impl Execute<'_> {
    fn execute(
        &self,
        mut sim: Simulation,
        out: &Path,
        mcap: bool,
        gpu: Option<&weft_render::Gpu>,
        stop: &Arc<AtomicBool>,
    ) -> anyhow::Result<RunResult> {
        let (spec, r) = (self.spec, self.run);
        let dt = sim.scene.settings.dt;
        let frames = spec.frames(dt);
        sim.set_stop(Arc::clone(stop));
        let rel = format!("{}.mcap", run_dir(r));
        let log = mcap.then(|| Output::create(&out.join(&rel))).transpose()?;
        let mut rec = match &log {
            Some(o) => {
                let options = RecordOptions {
                    mesh_every: 0,
                    ..RecordOptions::default()
                };
                let rec = Recorder::new(o.handle()?, &sim, frames, options)
                    .with_context(|| format!("writing {}", o.target().display()))?;
                Some(rec)
            }
            None => None,
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
        // The video starts with the initial state, so a run that diverges in its first frame still
        // has a frame to hold and mark.
        if let Some(v) = video.as_mut() {
            v.frame_span(&sim, frames as f64 * dt);
            v.frame(&sim)?;
        }
        let tracker = self.reference.map(|r| r.track(&sim)).transpose()?;
        let mut meter = Meter::new(&sim, self.strip, tracker);
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
                        meter.frame(&stats, &sim);
                        if let Some(rec) = rec.as_mut() {
                            rec.frame(&sim, &stats)?;
                        }
                        if let Some(v) = video.as_mut() {
                            v.frame(&sim)?;
                        }
                    }
                    Err(e) if sim.interrupted(&e) => {
                        status = Status::Interrupted;
                        break;
                    }
                    Err(e) => {
                        status = Status::Diverged(e.to_string());
                        break;
                    }
                }
            }
            Ok(())
        })();
        if let (Some(rec), Some(log)) = (rec, log) {
            rec.finish(&status, sim.frame())?;
            logged?;
            log.commit()?;
        } else {
            logged?;
        }
        // A run that diverged keeps its frames up to the divergence, marked.
        if let Some(v) = video {
            match &status {
                Status::Diverged(m) => v.finish_diverged(m)?,
                _ => v.finish()?,
            };
        }
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
}

/// The reference run's overrides: the file's common `set`, then the reference's own; refuses
/// a reference that changes the frame time step.
fn reference_overrides(
    common: &BTreeMap<String, Value>,
    spec: &spec::ReferenceSpec,
) -> anyhow::Result<Vec<Override>> {
    if spec.set.contains_key("sim.dt") {
        bail!(
            "reference.set: `sim.dt` cannot change (the reference is compared frame by frame); \
             refine it with sim.substeps"
        );
    }
    common
        .iter()
        .chain(&spec.set)
        .map(|(k, v)| {
            format!("{k}={}", spec::toml_text(v))
                .parse::<Override>()
                .with_context(|| format!("reference.set.{k}"))
        })
        .collect()
}

/// Loads and runs the reference of an experiments file for as many frames as its runs;
/// `None` without a `[reference]` or when stopped.
fn run_reference(
    spec: &Spec,
    scene_path: &Path,
    limits: &weft_scene::Limits,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<Option<Arc<reference::Reference>>> {
    let Some(r) = &spec.reference else {
        return Ok(None);
    };
    eprintln!("weft: running the reference");
    let (ov, _) = cantilever::prepare(
        spec.cantilever.as_ref(),
        scene_path,
        &reference_overrides(&spec.set, r)?,
        limits,
    )?;
    let scene =
        weft_scene::load_with(scene_path, &ov, limits).map_err(|e| anyhow::anyhow!("{e}"))?;
    let frames = spec.frames(scene.settings.dt);
    let sim = Simulation::new(scene)?;
    Ok(reference::Reference::run(sim, r.every, frames, stop)?.map(Arc::new))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shipped experiments file loads, expands, names plots it can draw, and every run's
    /// scene (and the reference's) loads with its overrides: a shipped experiment never stops
    /// on its own input.
    #[test]
    fn every_shipped_experiment_and_its_runs_load() {
        let limits = weft_scene::Limits::default();
        let mut files: Vec<PathBuf> = std::fs::read_dir("assets/experiments")
            .expect("assets/experiments")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        assert!(files.len() >= 9, "{files:?}");
        for file in files {
            let spec = Spec::load(&file).unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
            let runs = spec.expand().expect("expands");
            spec.check_plots(&runs).expect("plots");
            let scene = spec.scene_path(&file);
            let mut overrides: Vec<Vec<Override>> =
                runs.iter().map(|r| r.overrides.clone()).collect();
            if let Some(r) = &spec.reference {
                overrides.push(reference_overrides(&spec.set, r).expect("reference"));
            }
            for ov in overrides {
                let (ov, _) = cantilever::prepare(spec.cantilever.as_ref(), &scene, &ov, &limits)
                    .unwrap_or_else(|e| panic!("{}: {e:#}", file.display()));
                if let Err(e) = weft_scene::load_with(&scene, &ov, &limits) {
                    panic!("{}: {e}", file.display());
                }
            }
        }
    }
}
