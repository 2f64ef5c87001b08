//! `weft run`: a scene headless, logged to MCAP, stopped cleanly by a signal or divergence.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use weft_scene::Scene;
use weft_solver::SolverError;

use crate::crossing_report::CrossingTally;
use crate::output::{Named, Output, refuse_clashes};
use weft_record::{RecordOptions, Recorder, Status};
use weft_sim::Simulation;

/// Exit code of a run that diverged.
pub const EXIT_DIVERGED: u8 = 2;
/// Exit code of a run stopped by SIGINT/SIGTERM.
pub const EXIT_INTERRUPTED: u8 = crate::stop::EXIT_INTERRUPTED as u8;

/// Options of one run.
pub struct RunPlan<'a> {
    /// Files the run reads (the scene file; its meshes are added from the scene), with what
    /// they are called in messages: no output may be one of them.
    pub inputs: Vec<(&'static str, PathBuf)>,
    /// Frames to simulate.
    pub frames: u64,
    /// MCAP output.
    pub out: Option<&'a Path>,
    /// Final positions JSON.
    pub dump_final: Option<&'a Path>,
    /// Logging options.
    pub record: RecordOptions,
    /// Show a progress bar (on a terminal only).
    pub progress: bool,
    /// Refuse to run a scene whose explicit springs are past their stability limit.
    pub strict: bool,
}

/// Every file `scene` read, as paths: the scene file and its meshes (relative to its directory).
pub fn scene_inputs(scene_file: &Path, scene: &Scene) -> Vec<(&'static str, PathBuf)> {
    let dir = Scene::dir_of(scene_file);
    let mut v = vec![("the scene", scene_file.to_path_buf())];
    v.extend(
        scene
            .files
            .keys()
            .map(|f| ("a mesh of the scene", dir.join(f))),
    );
    v
}

/// Runs `scene` as planned; `stop` is set by the signal handler.
pub fn run(scene: Scene, plan: &RunPlan<'_>, stop: &Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let mut inputs = plan.inputs.clone();
    if let Some((_, scene_file)) = plan.inputs.iter().find(|(r, _)| *r == "the scene") {
        inputs = scene_inputs(scene_file, &scene);
        inputs.extend(
            plan.inputs
                .iter()
                .filter(|(r, _)| *r != "the scene")
                .cloned(),
        );
    }
    let named_inputs: Vec<Named<'_>> = inputs
        .iter()
        .map(|(role, path)| Named { role, path })
        .collect();
    let mut outputs = Vec::new();
    if let Some(p) = plan.out {
        outputs.push(Named {
            role: "--out",
            path: p,
        });
    }
    if let Some(p) = plan.dump_final {
        outputs.push(Named {
            role: "--dump-final",
            path: p,
        });
    }
    refuse_clashes(&named_inputs, &outputs)?;
    // Claim the outputs before anything is simulated: an unwritable path, or one another weft
    // is writing, fails now. Nothing appears under the final names until the run is over.
    let log = plan.out.map(Output::create_log).transpose()?;
    let dump = plan.dump_final.map(Output::create).transpose()?;
    let name = scene.name.clone();
    let mut sim = Simulation::new(scene)?;
    if crate::stability::warn(&sim.groups) > 0 && plan.strict {
        anyhow::bail!(
            "--strict: a cloth's springs are past their stability limit; nothing was run"
        );
    }
    crate::crossing_report::warn_start(&sim);
    sim.set_stop(Arc::clone(stop));
    // From here a signal raises the flag: the loop below stops and closes the log.
    let _polling = crate::stop::Polling::start();
    let particles: usize = sim.groups.iter().map(|g| g.solver.particles().len()).sum();
    let methods: Vec<String> = sim.groups.iter().map(|g| g.method.to_string()).collect();
    eprintln!(
        "weft: {name}: {} cloth(s), {particles} particles, {}, dt {:.5} s, {} substeps x {} iterations",
        sim.scene.cloths.len(),
        methods.join(" + "),
        sim.scene.settings.dt,
        sim.scene.settings.substeps,
        sim.scene.settings.iterations,
    );
    let mut rec = log
        .as_ref()
        .map(|o| {
            Recorder::new(o.handle()?, &sim, plan.frames, plan.record)
                .with_context(|| format!("writing {}", o.target().display()))
        })
        .transpose()?;
    let bar = progress_bar(plan.frames, plan.progress);
    let start = Instant::now();
    let mut status = Status::Complete;
    let mut torn = false;
    let mut last = sim.stats(0.0, 0);
    let mut tally = CrossingTally::default();
    let mut seams = weft_sim::SeamWatch::default();
    let result = (|| -> anyhow::Result<()> {
        if let Some(r) = rec.as_mut() {
            r.frame(&sim, &last)?;
        }
        for _ in 0..plan.frames {
            if stop.load(Ordering::SeqCst) {
                status = Status::Interrupted;
                break;
            }
            match sim.step() {
                Ok(stats) => {
                    last = stats;
                    tally.add(&stats);
                    bar.suspend(|| crate::seam_report::warn_open(&mut seams, &sim));
                    if let Some(r) = rec.as_mut() {
                        r.frame(&sim, &stats)?;
                        if stats.frame % 16 == 0 {
                            bar.set_message(log_progress(&r.progress(), plan));
                        }
                    }
                }
                Err(e) if sim.interrupted(&e) => {
                    status = Status::Interrupted;
                    torn = true;
                    break;
                }
                Err(e) => {
                    status = Status::Diverged(e.to_string());
                    if let Some(hint) = divergence_hint(&e, &sim) {
                        eprintln!("weft: {hint}");
                    }
                    break;
                }
            }
            bar.inc(1);
        }
        Ok(())
    })();
    bar.finish_and_clear();
    let frames = last.frame;
    let mut logged = None;
    // Close the log on every way out, so it is readable and says how the run ended; only a
    // finished log is renamed into place.
    if let (Some(mut r), Some(o)) = (rec, log) {
        let target = o.target().display().to_string();
        // A run logged every N frames still ends its log with its last state (unless the
        // stop tore the last frame apart or it diverged).
        let whole = !torn && !matches!(status, Status::Diverged(_));
        let result = match result {
            Ok(()) if whole => r.last_frame(&sim, &last).map_err(anyhow::Error::from),
            result => result,
        };
        let progress = r.progress();
        let finished = r.finish(&status, frames);
        result.with_context(|| format!("writing {target}"))?;
        finished.with_context(|| format!("finishing {target}"))?;
        o.commit()?;
        logged = Some(progress);
    } else {
        result?;
    }
    // The run's wall time includes writing out what the log's queue still held.
    let wall = start.elapsed().as_secs_f64();
    if let Some(mut o) = dump {
        if torn {
            eprintln!(
                "weft: {} not written: the stop came inside frame {}",
                o.target().display(),
                frames + 1
            );
        } else {
            o.write_all(dump_final(&sim)?.as_bytes())?;
            o.commit()?;
        }
    }
    // A diverged run's positions are the exploded ones: no lowest point worth printing.
    let lowest = match status {
        Status::Diverged(_) => "— (diverged)".to_owned(),
        _ => format!(
            "{:+.4} m",
            (0..sim.scene.cloths.len())
                .flat_map(|i| sim.cloth_positions(i).iter().map(|p| p.y))
                .fold(f64::INFINITY, f64::min)
        ),
    };
    say!(
        "{frames} frames, {:.3} s simulated, {wall:.3} s wall, {:.3} ms/frame; lowest point y = {lowest}, stretch error max {:.2e} m, kinetic energy {:.3e} J",
        frames as f64 * sim.scene.settings.dt,
        if frames > 0 {
            1e3 * wall / frames as f64
        } else {
            0.0
        },
        last.residual_max,
        last.kinetic_energy,
    )?;
    if let Some(b) = last.bending_residual {
        say!(
            "bending residual (XPBD, last substep): {b:.1e} (0 converged, 1 about twice too soft)"
        )?;
    }
    if let Some(line) = tally.line() {
        say!("crossings: {line}")?;
    }
    if let Some(peak) = crate::limits::peak_memory() {
        say!(
            "memory: peak {}, estimated {}",
            weft_scene::human(peak),
            weft_scene::human(sim.scene.estimated_bytes())
        )?;
    }
    if let Some(p) = plan.out {
        let size = std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
        say!("wrote {} ({size} bytes)", p.display())?;
        if let Some(l) = logged {
            say!(
                "log: {} frame(s), {:.1} KB a frame; the run waited {:.1} ms for the log's queue",
                l.frames,
                size as f64 / 1e3 / l.frames.max(1) as f64,
                l.waited.as_secs_f64() * 1e3
            )?;
        }
    }
    Ok(match status {
        Status::Complete => ExitCode::SUCCESS,
        Status::Interrupted => {
            eprintln!("weft: interrupted after {frames} frames; the log holds every one of them");
            ExitCode::from(EXIT_INTERRUPTED)
        }
        Status::Diverged(m) => {
            eprintln!("weft: error: {m}");
            eprintln!("weft: the log holds the {frames} frames before it");
            ExitCode::from(EXIT_DIVERGED)
        }
    })
}

/// Advice for a divergence whose cause is not a too-large time step: a cloth that starts
/// beyond the bound, or a value that overflowed within the first frame.
pub fn divergence_hint(e: &SolverError, sim: &Simulation) -> Option<String> {
    let SolverError::Diverged {
        frame, position, ..
    } = e
    else {
        return None;
    };
    let bound = sim.scene.settings.divergence_bound;
    let starts_outside = sim.scene.cloths.iter().any(|c| {
        c.mesh
            .positions
            .iter()
            .any(|p| p.abs().max_element() > bound)
    });
    if starts_outside {
        return Some(format!(
            "hint: a cloth starts beyond sim.divergence_bound = {bound} m: move it (center) or \
             raise the bound; no time step fixes that"
        ));
    }
    if *frame == 0 && !position.is_finite() {
        return Some(
            "hint: a value overflowed within the first frame: check the masses, compliances and \
             sizes against the ranges `weft check` states"
                .into(),
        );
    }
    None
}

/// The progress bar's log part: frames written, megabytes, and the size the log is heading
/// for.
fn log_progress(p: &weft_record::LogProgress, plan: &RunPlan<'_>) -> String {
    let every = plan.record.every.max(1);
    let total = plan.frames / every + 2;
    let mb = p.bytes as f64 / 1e6;
    let projected = mb / p.written_frames.max(1) as f64 * total as f64;
    format!(
        "log {} frames, {mb:.0} MB, about {projected:.0} MB at the end",
        p.written_frames
    )
}

fn progress_bar(frames: u64, wanted: bool) -> ProgressBar {
    if !wanted || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(frames), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames  {per_sec}  eta {eta}  {msg}")
    {
        bar.set_style(style);
    }
    bar
}

/// `{ "<cloth>": [[x, y, z], …] }` with positions rounded to float32, as logged.
fn dump_final(sim: &Simulation) -> anyhow::Result<String> {
    let mut map = serde_json::Map::new();
    for (i, c) in sim.scene.cloths.iter().enumerate() {
        let pts: Vec<[f32; 3]> = sim
            .cloth_positions(i)
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        map.insert(c.name.clone(), serde_json::to_value(pts)?);
    }
    Ok(serde_json::to_string(&serde_json::json!({
        "frame": sim.frame(),
        "time": sim.time(),
        "cloths": map,
    }))?)
}
