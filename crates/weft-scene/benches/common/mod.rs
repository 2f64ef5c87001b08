//! What weft-scene's method benches share: scenes loaded from `assets/scenes/` with `--set`-style
//! overrides (the same path `weft run` takes), the reference workload's sizes, and where
//! criterion writes its reports.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use weft_scene::{Override, Scene, SolverGroup};
use weft_solver::{Method, SimdPath};

/// Grid sizes N of the N×N cloths: 1,024 … 65,536 particles.
pub const SIZES: [usize; 4] = [32, 64, 128, 256];

/// `assets/scenes/<name>` in this checkout.
pub fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/scenes")
        .join(name)
}

/// Loads `assets/scenes/<name>` with `overrides` (`KEY=VALUE`, as after `--set`).
pub fn load(name: &str, overrides: &[String]) -> Scene {
    let ov: Vec<Override> = overrides
        .iter()
        .map(|s| s.parse().expect("well-formed override"))
        .collect();
    match weft_scene::load(&scene_path(name), &ov) {
        Ok(s) => s,
        Err(e) => panic!("{name} {overrides:?}: {e}"),
    }
}

/// The scene's only solver group.
pub fn single_group(scene: &Scene) -> SolverGroup {
    let mut groups = scene.build().expect("scene builds");
    assert_eq!(groups.len(), 1, "{}: one method expected", scene.name);
    groups.remove(0)
}

/// Overrides that make `assets/scenes/reference.toml` an `n`×`n` cloth solved by `method`.
///
/// Mass-spring springs get k = m / (16 h²) for the lightest particle of mass m, so that
/// ω h ≤ 1 with ω² ≤ 8 springs · k · 2/m (stable at every size, explicit Euler needs ω h < 2).
pub fn reference_overrides(n: usize, method: Method) -> Vec<String> {
    let mut ov = vec![
        format!("cloth.reference.resolution=[{n}, {n}]"),
        format!("sim.method={}", method.name()),
    ];
    if matches!(method, Method::MassSpring | Method::ImplicitMassSpring) {
        let probe = load("reference.toml", &ov);
        let m = probe.cloths[0]
            .mesh
            .masses
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let h = probe.settings.h();
        let k = m / (16.0 * h * h);
        ov.push(format!("cloth.reference.stretch_spring_stiffness={k:e}"));
        ov.push(format!("cloth.reference.shear_spring_stiffness={k:e}"));
    }
    ov
}

/// The reference workload (`assets/scenes/reference.toml`) at `n`×`n` for `method`.
pub fn reference(n: usize, method: Method) -> SolverGroup {
    single_group(&load("reference.toml", &reference_overrides(n, method)))
}

/// Constraint evaluations per frame: constraints × substeps × iterations (mass-spring
/// evaluates each spring once per substep).
pub fn evaluations_per_frame(g: &SolverGroup) -> u64 {
    let s = g.solver.settings();
    let per_substep = match s.method {
        Method::MassSpring | Method::ImplicitMassSpring => 1,
        _ => u64::from(s.iterations),
    };
    g.solver.constraints().len() as u64 * u64::from(s.substeps) * per_substep
}

/// Criterion's output folder: `$CRITERION_HOME`, else `<target>/criterion` next to this
/// bench executable (`<target>/release/deps/<bench>`), as criterion itself resolves it.
pub fn criterion_dir() -> PathBuf {
    if let Some(home) = std::env::var_os("CRITERION_HOME") {
        return PathBuf::from(home);
    }
    if let Some(t) = std::env::var_os("CARGO_TARGET_DIR") {
        return PathBuf::from(t).join("criterion");
    }
    std::env::current_exe()
        .ok()
        .and_then(|exe| exe.ancestors().nth(3).map(Path::to_path_buf))
        .unwrap_or_else(|| PathBuf::from("target"))
        .join("criterion")
}

/// The kernel path the benches run on (`WEFT_SIMD`, else the widest this CPU has), printed once
/// so that every figure names its path. A `WEFT_SIMD` that names no path stops the bench.
pub fn simd_path() -> SimdPath {
    let path = match SimdPath::from_env() {
        Ok(asked) => SimdPath::resolve(asked),
        Err(e) => panic!("WEFT_SIMD: {e}"),
    };
    println!("kernel path: {path} (WEFT_SIMD=avx512|avx2|neon|scalar forces one)");
    path
}
