//! `weft fabric`: a textile lab's measurements as a material table to paste into a scene, and
//! the virtual cantilever's reading of it (see `weft_solver::fabric`).

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::bail;
use weft_solver::{Direction, FabricMeasurements, Material, virtual_cantilever};

use crate::cli::FabricArgs;

/// Standard gravity, under which the lab measured (m/s²).
const G: f64 = 9.81;

/// How far the virtual strip's chord may fall from the elastica's before `weft fabric` warns
/// (degrees): the accuracy the README states.
const TOLERANCE: f64 = 2.0;

/// Runs `weft fabric`.
pub fn fabric(args: &FabricArgs, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    let lab = FabricMeasurements {
        weight: args.weight,
        bending_length: [
            args.bending_length_warp,
            args.bending_length_weft.unwrap_or(args.bending_length_warp),
        ],
        extension: [
            args.extension_warp,
            args.extension_weft.unwrap_or(args.extension_warp),
        ],
        load: args.load,
        shear: args.shear,
    };
    let material = match lab.material(G) {
        Ok(m) => m,
        Err(e) => bail!("--{}: {}", e.field.replace('_', "-"), e.message),
    };
    say!(
        "# weft fabric: {} g/m², bending length {} cm (warp) / {} cm (weft), extension {} % / {} % \
         at {} N/m, shear {} N/m",
        lab.weight,
        lab.bending_length[0],
        lab.bending_length[1],
        lab.extension[0],
        lab.extension[1],
        lab.load,
        lab.shear
    )?;
    say!("{}", table(&material))?;
    if args.no_check {
        return Ok(ExitCode::SUCCESS);
    }
    say!(
        "# the virtual cantilever (ASTM D1388): {} at its defaults, {} cells along a 2c \
         overhang, settled 10 s",
        args.method.name(),
        args.segments
    )?;
    let mut off = Vec::new();
    for direction in [Direction::Warp, Direction::Weft] {
        let name = if direction == Direction::Warp {
            "warp"
        } else {
            "weft"
        };
        let reading = virtual_cantilever(
            &material,
            direction,
            args.method,
            args.segments as usize,
            G,
            stop,
        );
        if stop.load(Ordering::Relaxed) {
            say!("# stopped")?;
            return Ok(ExitCode::from(130));
        }
        let Some(r) = reading else {
            say!("# {name}: the strip did not settle within the elastica's range")?;
            off.push(name);
            continue;
        };
        say!(
            "#   {name}: bending length {:.2} cm, measured {:.2} cm ({:+.1} %); chord {:.2}° \
             against the elastica's {:.2}°",
            r.bending_length * 1e2,
            r.measured * 1e2,
            (r.measured / r.bending_length - 1.0) * 1e2,
            r.chord_angle,
            r.elastica_angle
        )?;
        if (r.chord_angle - r.elastica_angle).abs() > TOLERANCE {
            off.push(name);
        }
    }
    if !off.is_empty() {
        eprintln!(
            "weft: warning: the virtual strip along the {} is more than {TOLERANCE}° from the \
             elastica at {} cells: try more `--segments`, or `--method implicit-mass-spring`",
            off.join(" and "),
            args.segments
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `material = { … }` for `material`, as `cloth.<name>.material` reads it (density in g/m²).
fn table(m: &Material) -> String {
    format!(
        "material = {{ density = {:?}, stretch_warp = {:?}, stretch_weft = {:?}, shear = {:?}, \
         bending_warp = {:?}, bending_weft = {:?}, bending_bias = {:?} }}",
        round(m.density * 1e3),
        round(m.stretch),
        round(m.stretch_weft),
        round(m.shear),
        round(m.bending),
        round(m.bending_weft),
        round(m.bending_bias)
    )
}

/// `x` to six significant digits (what a lab's figures carry), as an `f64` that prints short.
fn round(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}
