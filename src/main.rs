//! The `weft` binary: the interactive viewer; runs scenes headless, logs them to MCAP, checks
//! scene files, replays logs and runs experiment queues.
//!
//! Its modules, by command: `run` (`weft run`), `app` (`weft view`), `video` (`weft render`),
//! `experiments`, `replay`, `recover`, `export`, `fabric`, `explain` (`weft check --explain`)
//! and `cli` (the command line). Shared by several: `view` and `framing` (what is drawn and
//! from where), `output` (files that never overwrite an input), `limits` (memory and file
//! size), `stop` (SIGINT and SIGTERM), `say` (standard output), `runtime_dir` (a private
//! `XDG_RUNTIME_DIR` for the GPU), `stability`, `crossing_report` and `seam_report` (warnings
//! in words) and `default_scene` (the built-in hanging cloth).

// First, so that `say!` is in scope in every module below.
#[macro_use]
mod say;
mod app;
mod cli;
mod crossing_report;
mod default_scene;
mod experiments;
mod explain;
mod export;
mod fabric;
mod framing;
mod limits;
mod output;
mod recover;
mod replay;
mod run;
mod runtime_dir;
mod seam_report;
mod stability;
mod stop;
mod video;
mod view;

use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use clap::Parser;
use weft_scene::{Limits, Scene, SceneErrors};

use cli::{Cli, Command, RunArgs};
use run::RunPlan;

fn main() -> ExitCode {
    let cli = Cli::parse();
    // First, while weft has one thread: the GPU commands may re-execute themselves.
    runtime_dir::ensure(match &cli.command {
        None | Some(Command::View(_) | Command::Render(_)) => true,
        Some(Command::Experiments(a)) => a.render,
        Some(_) => false,
    });
    // SIGINT and SIGTERM end the process at once unless a loop polls the flag (see stop.rs):
    // runs then close their logs, the solver stops within a substep.
    let stop = stop::install();
    let result = match cli.command {
        None => {
            let _polling = stop::Polling::start();
            app::view(&cli.view, Arc::clone(&stop))
        }
        Some(Command::View(args)) => {
            let _polling = stop::Polling::start();
            app::view(&args, Arc::clone(&stop))
        }
        Some(Command::Run(args)) => run_command(&args, &stop),
        Some(Command::Check(args)) => check(&args),
        Some(Command::Replay(args)) => replay::replay(&args, &stop),
        Some(Command::Experiments(args)) => experiments::run(&args, &stop),
        Some(Command::Render(args)) => render_command(&args, &stop),
        Some(Command::Recover(args)) => recover::recover(&args),
        Some(Command::Export(args)) => export::export(&args, &stop),
        Some(Command::Fabric(args)) => {
            let _polling = stop::Polling::start();
            fabric::fabric(&args, &stop)
        }
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("weft: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Loads the scene a run names (or the default one) within `limits`.
fn load_scene(
    path: Option<&std::path::Path>,
    overrides: &[weft_scene::Override],
    limits: &Limits,
) -> Result<Scene, SceneErrors> {
    match path {
        Some(p) => weft_scene::load_with(p, overrides, limits),
        None => default_scene::load(overrides),
    }
}

fn report(errors: &SceneErrors) -> ExitCode {
    for e in &errors.0 {
        eprintln!("error: {e}");
    }
    ExitCode::FAILURE
}

fn run_command(args: &RunArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let scene = match load_scene(
        args.scene.as_deref(),
        &args.overrides(),
        &args.limits.limits(),
    ) {
        Ok(s) => s,
        Err(e) => return Ok(report(&e)),
    };
    let plan = RunPlan {
        inputs: args
            .scene
            .iter()
            .map(|p| ("the scene", p.clone()))
            .collect(),
        frames: args.frames,
        out: args.out.as_deref(),
        dump_final: args.dump_final.as_deref(),
        record: args.log.options(args.timing),
        progress: !args.quiet,
        strict: args.strict,
    };
    run::run(scene, &plan, stop)
}

fn render_command(args: &cli::RenderArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let scene = match load_scene(
        args.scene.as_deref(),
        &args.overrides(),
        &args.limits.limits(),
    ) {
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
        camera: args.camera.pair(),
    };
    if let Some(scene_file) = &args.scene {
        // Neither --out itself nor any file the render writes into it may be an input.
        let inputs = run::scene_inputs(scene_file, &scene);
        output::refuse_clashes(
            &inputs
                .iter()
                .map(|(role, path)| output::Named { role, path })
                .collect::<Vec<_>>(),
            &[output::Named {
                role: "--out",
                path: &args.out,
            }],
        )?;
        video::refuse_overwriting_inputs(&inputs, &args.out, &scene.name)?;
    }
    video::render(scene, &plan, stop)
}

/// `weft check`: loads and builds the scene. Nothing is written, so a signal ends it at once.
fn check(args: &cli::CheckArgs) -> anyhow::Result<ExitCode> {
    match weft_scene::load_with(&args.scene, &args.overrides(), &args.limits.limits()) {
        Ok(scene) => {
            let groups = match scene.build() {
                Ok(g) => g,
                Err(e) => return Ok(report(&e.into())),
            };
            if args.explain {
                say!("{}", explain::resolved(&scene))?;
                return Ok(ExitCode::SUCCESS);
            }
            let methods: Vec<&str> = scene.methods().iter().map(|m| m.name()).collect();
            say!(
                "{}: ok ({} cloth(s), {} collider(s), methods: {})",
                scene.name,
                scene.cloths.len(),
                scene.colliders.len(),
                methods.join(", ")
            )?;
            say!(
                "  memory: about {} once running",
                weft_scene::human(scene.estimated_bytes())
            )?;
            for g in &groups {
                for i in 0..g.solver.cloths().len() {
                    if let Some(v) = stability::verdict(&g.solver, i) {
                        if v.ok {
                            say!("  {}", v.text)?;
                        } else {
                            say!("  warning: {}", v.text)?;
                        }
                    }
                }
            }
            for c in weft_sim::crossings::start_crossings(&scene, &groups) {
                say!("  warning: {c}")?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(e) => Ok(report(&e)),
    }
}
