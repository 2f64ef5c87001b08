//! The `weft` binary: runs the built-in default scene and reports what the cloth does.

mod default_scene;

use std::time::Instant;

use anyhow::Context;
use clap::Parser;
use weft_solver::Method;

/// Real-time cloth simulation with XPBD, PBD and mass-spring.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Cli {
    /// Method: xpbd, pbd or mass-spring.
    #[arg(long, default_value = "xpbd")]
    method: Method,
    /// Frames to simulate (at the scene's time step, 1/60 s by default).
    #[arg(long, default_value_t = 300)]
    frames: u64,
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let mut solver = default_scene::hanging(cli.method).context("building the default scene")?;
    let n = solver.particles().len();
    println!(
        "weft: default scene (hanging cloth, {n} particles, {} constraints), {}, {} substeps",
        solver.constraints().len(),
        cli.method,
        solver.settings().substeps
    );
    let start = Instant::now();
    for frame in 1..=cli.frames {
        solver.step().context("stepping the default scene")?;
        if frame % 60 == 0 || frame == cli.frames {
            let lowest = solver
                .particles()
                .positions
                .iter()
                .map(|p| p.y)
                .fold(f64::INFINITY, f64::min);
            println!(
                "t = {:5.2} s  lowest point y = {lowest:+.4} m  stretch error rms = {:.2e} m  kinetic energy = {:.3e} J",
                solver.time(),
                solver.residual().rms,
                solver.particles().kinetic_energy()
            );
        }
    }
    let wall = start.elapsed().as_secs_f64();
    println!(
        "{} frames, {:.2} s simulated, {:.3} s wall, {:.3} ms/frame",
        cli.frames,
        solver.time(),
        wall,
        1e3 * wall / cli.frames as f64
    );
    Ok(())
}
