//! `weft run`: a scene headless, logged to MCAP, stopped cleanly by a signal or divergence.

use std::fs::File;
use std::io::IsTerminal;
use std::path::Path;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use weft_scene::Scene;

use crate::record::{RecordOptions, Recorder, Status};
use crate::sim::Simulation;

/// Exit code of a run that diverged.
pub const EXIT_DIVERGED: u8 = 2;
/// Exit code of a run stopped by SIGINT/SIGTERM.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Options of one run.
pub struct RunPlan<'a> {
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
}

/// Creates `path` for writing, with a message naming it.
pub fn create_output(path: &Path) -> anyhow::Result<File> {
    File::create(path).with_context(|| format!("cannot write {}", path.display()))
}

/// Runs `scene` as planned; `stop` is set by the signal handler.
pub fn run(scene: Scene, plan: &RunPlan<'_>, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    // Fail on an unwritable path before anything is simulated.
    let file = plan.out.map(create_output).transpose()?;
    if let Some(p) = plan.dump_final {
        create_output(p)?;
    }
    let name = scene.name.clone();
    let mut sim = Simulation::new(scene)?;
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
    let mut rec = file
        .map(|f| Recorder::new(f, &sim, plan.frames, plan.record))
        .transpose()?;
    let bar = progress_bar(plan.frames, plan.progress);
    let start = Instant::now();
    let mut status = Status::Complete;
    let mut last = sim.stats(0.0, 0);
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
                    if let Some(r) = rec.as_mut() {
                        r.frame(&sim, &stats)?;
                    }
                }
                Err(e) => {
                    status = Status::Diverged(e.to_string());
                    break;
                }
            }
            bar.inc(1);
        }
        Ok(())
    })();
    bar.finish_and_clear();
    let wall = start.elapsed().as_secs_f64();
    let frames = last.frame;
    // Close the log on every way out, so it is readable and says how the run ended.
    if let Some(r) = rec {
        let finished = r.finish(&status, frames);
        result?;
        finished.context("finishing the MCAP file")?;
    } else {
        result?;
    }
    if let Some(p) = plan.dump_final {
        dump_final(p, &sim)?;
    }
    let lowest = (0..sim.scene.cloths.len())
        .flat_map(|i| sim.cloth_positions(i).iter().map(|p| p.y))
        .fold(f64::INFINITY, f64::min);
    println!(
        "{frames} frames, {:.3} s simulated, {wall:.3} s wall, {:.3} ms/frame; lowest point y = {lowest:+.4} m, stretch error max {:.2e} m, kinetic energy {:.3e} J",
        sim.time(),
        if frames > 0 {
            1e3 * wall / frames as f64
        } else {
            0.0
        },
        last.residual_max,
        last.kinetic_energy,
    );
    if let Some(p) = plan.out {
        let size = std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
        println!("wrote {} ({size} bytes)", p.display());
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

fn progress_bar(frames: u64, wanted: bool) -> ProgressBar {
    if !wanted || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(frames), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames  {per_sec}  eta {eta}")
    {
        bar.set_style(style);
    }
    bar
}

/// Writes `{ "<cloth>": [[x, y, z], …] }` with positions rounded to float32, as logged.
fn dump_final(path: &Path, sim: &Simulation) -> anyhow::Result<()> {
    let mut map = serde_json::Map::new();
    for (i, c) in sim.scene.cloths.iter().enumerate() {
        let pts: Vec<[f32; 3]> = sim
            .cloth_positions(i)
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        map.insert(c.name.clone(), serde_json::to_value(pts)?);
    }
    let text = serde_json::to_string(&serde_json::json!({
        "frame": sim.frame(),
        "time": sim.time(),
        "cloths": map,
    }))?;
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}
