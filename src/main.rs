//! The `weft` binary: the interactive viewer; runs scenes headless, logs them to MCAP, checks
//! scene files, replays logs and runs experiment queues.

mod app;
mod cli;
mod default_scene;
mod experiments;
mod record;
mod replay;
mod run;
mod sim;
mod stability;
mod video;

use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::Parser;
use weft_scene::{Scene, SceneErrors};

use cli::{Cli, Command, RunArgs};
use record::RecordOptions;
use run::RunPlan;

fn main() -> ExitCode {
    let cli = Cli::parse();
    // SIGINT and SIGTERM only raise a flag: runs check it every frame and close their logs.
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)) {
        eprintln!("weft: warning: cannot catch SIGINT/SIGTERM: {e}");
    }
    let result = match cli.command {
        None => app::view(&cli.view, Arc::clone(&stop)),
        Some(Command::View(args)) => app::view(&args, Arc::clone(&stop)),
        Some(Command::Run(args)) => run_command(&args, &stop),
        Some(Command::Check(args)) => check(&args),
        Some(Command::Replay(args)) => replay::replay(&args, &stop),
        Some(Command::Experiments(args)) => experiments::run(&args, &stop),
        Some(Command::Render(args)) => render_command(&args, &stop),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("weft: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Loads the scene a run names (or the default one), printing every error.
fn load_scene(
    path: Option<&std::path::Path>,
    overrides: &[weft_scene::Override],
) -> Result<Scene, SceneErrors> {
    match path {
        Some(p) => weft_scene::load(p, overrides),
        None => default_scene::load(overrides),
    }
}

fn report(errors: &SceneErrors) -> ExitCode {
    for e in &errors.0 {
        eprintln!("error: {e}");
    }
    ExitCode::FAILURE
}

fn run_command(args: &RunArgs, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    let scene = match load_scene(args.scene.as_deref(), &args.overrides()) {
        Ok(s) => s,
        Err(e) => return Ok(report(&e)),
    };
    let plan = RunPlan {
        frames: args.frames,
        out: args.out.as_deref(),
        dump_final: args.dump_final.as_deref(),
        record: RecordOptions {
            mesh_every: args.mesh_every,
            timing: args.timing,
        },
        progress: !args.quiet,
    };
    run::run(scene, &plan, stop)
}

fn render_command(args: &cli::RenderArgs, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    let scene = match load_scene(args.scene.as_deref(), &args.set) {
        Ok(s) => s,
        Err(e) => return Ok(report(&e)),
    };
    let plan = video::VideoPlan {
        frames: args.frames,
        every: args.every,
        out: &args.out,
        size: args.size,
        options: weft_render::RenderOptions {
            wireframe: args.wireframe,
            particles: args.particles,
            grid: !args.no_grid,
            shadows: !args.no_shadows,
        },
        progress: !args.quiet,
    };
    video::render(scene, &plan, stop)
}

fn check(args: &cli::CheckArgs) -> anyhow::Result<ExitCode> {
    match weft_scene::load(&args.scene, &args.set) {
        Ok(scene) => {
            let groups = match scene.build() {
                Ok(g) => g,
                Err(e) => return Ok(report(&e.into())),
            };
            let methods: Vec<&str> = scene.methods().iter().map(|m| m.name()).collect();
            println!(
                "{}: ok ({} cloth(s), {} collider(s), methods: {})",
                scene.name,
                scene.cloths.len(),
                scene.colliders.len(),
                methods.join(", ")
            );
            for g in &groups {
                for i in 0..g.solver.cloths().len() {
                    if let Some(v) = stability::verdict(&g.solver, i) {
                        if v.ok {
                            println!("  {}", v.text);
                        } else {
                            println!("  warning: {}", v.text);
                        }
                    }
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(e) => Ok(report(&e)),
    }
}
