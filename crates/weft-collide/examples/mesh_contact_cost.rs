//! What triangle-mesh contact costs per frame, in CPU time as well as wall-clock time (on a
//! shared machine the wall clock mostly measures the other processes), side by side in one
//! run: the scenes of the `mesh_contact` bench (XPBD, 10 substeps × 1 iteration), each
//! stepped after 30 frames from the same state, median over `REPS` frames.
//!
//! - static: a 128² cloth on `icosphere_drop`'s 20,480-triangle sphere mesh and the ground,
//!   against the bare solve of the same state (fused, no hook), the ground alone, the mesh
//!   alone, and the cloth on `sphere_drop`'s analytic sphere of the same size, with the
//!   ground and alone;
//! - deforming: a 90² cloth on `breathing_drop`'s 5,120-triangle deforming ball, against its
//!   bare solve.
//!
//! CPU time is the sum over the process's threads of the time on a CPU
//! (`/proc/self/task/*/schedstat`, Linux; "n/a" elsewhere).
//!
//! `cargo run --release -p weft-collide --example mesh_contact_cost -- [REPS] [SCENE]`; set
//! `RAYON_NUM_THREADS` to choose the thread count and `WEFT_SIMD` the solver's kernel path.
//! SCENE `mesh`, `sphere` or `deforming` steps only that scene's collider frame `REPS` times
//! from copies of the same state, `ground` the mesh scene's cloth on the ground alone, `REPS`
//! frames in a row (for a profiler); `steady` steps the static scenes continuously instead of
//! from copies (as a running app steps them), three rounds alternating between them.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use weft_collide::CollisionWorld;
use weft_collide::scenarios::{
    SPHERE_RADIUS, balls_alone, breathing_drop, ground, icosphere_drop, sphere_drop,
};
use weft_solver::{Method, Solver};

/// Nanoseconds on a CPU, summed over the process's threads, if the system tells.
fn cpu_ns() -> Option<u64> {
    let mut sum = 0;
    for entry in std::fs::read_dir("/proc/self/task").ok()? {
        let text = std::fs::read_to_string(entry.ok()?.path().join("schedstat")).ok()?;
        sum += text.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(sum)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median CPU and wall-clock milliseconds of `f` on fresh copies made by `setup` (untimed).
fn time<T>(reps: usize, setup: impl Fn() -> T, f: impl Fn(&mut T)) -> (Option<f64>, f64) {
    let (mut cpu, mut wall) = (Vec::new(), Vec::new());
    for _ in 0..reps {
        let mut x = setup();
        let (c0, w0) = (cpu_ns(), Instant::now());
        f(&mut x);
        wall.push(w0.elapsed().as_secs_f64() * 1e3);
        if let (Some(a), Some(b)) = (c0, cpu_ns()) {
            cpu.push((b - a) as f64 * 1e-6);
        }
    }
    let cpu = (cpu.len() == reps).then(|| median(cpu));
    (cpu, median(wall))
}

fn in_contact(mut scene: (Solver, CollisionWorld)) -> (Solver, CollisionWorld) {
    for _ in 0..30 {
        scene.0.step_with(&mut scene.1).expect("stable");
    }
    scene
}

fn bare(reps: usize, s: &Solver) -> (Option<f64>, f64) {
    time(
        reps,
        || s.clone(),
        |s| {
            std::hint::black_box(s.step().expect("stable"));
        },
    )
}

fn with(reps: usize, s: &Solver, w: &CollisionWorld) -> (Option<f64>, f64) {
    time(
        reps,
        || (s.clone(), w.clone()),
        |(s, w)| {
            std::hint::black_box(s.step_with(w).expect("stable"));
        },
    )
}

/// Median wall-clock milliseconds of `reps` frames of `s` (with `w`, if given) stepped one
/// after another: no copies, so caches and the solver's buffers are as a running app has them.
fn steady(reps: usize, s: &mut Solver, w: Option<&mut CollisionWorld>) -> (Option<f64>, f64) {
    let mut wall = Vec::new();
    let mut w = w;
    for _ in 0..reps {
        let t0 = Instant::now();
        let stats = match w.as_deref_mut() {
            Some(w) => s.step_with(w),
            None => s.step(),
        };
        std::hint::black_box(stats.expect("stable"));
        wall.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    (None, median(wall))
}

/// A world holding only the mesh scene's ground, for `solver`.
fn ground_alone(solver: &Solver) -> CollisionWorld {
    let mut w = CollisionWorld::new(solver);
    w.add_collider(&ground(-SPHERE_RADIUS)).expect("ground");
    w
}

/// The static scenes stepped continuously, in three rounds alternating between them.
fn steady_frames(reps: usize) {
    let (solver, mesh) = in_contact(icosphere_drop(Method::Xpbd, 128).expect("scene"));
    let (sphere_solver, sphere) = in_contact(sphere_drop(Method::Xpbd, 128).expect("scene"));
    let ground_only = ground_alone(&solver);
    let mut cases = [
        ("bare solve (mesh scene)", solver.clone(), None),
        ("ground alone", solver.clone(), Some(ground_only)),
        ("20,480-triangle mesh + ground", solver, Some(mesh)),
        ("bare solve (sphere scene)", sphere_solver.clone(), None),
        ("analytic sphere + ground", sphere_solver, Some(sphere)),
    ];
    println!(
        "solver kernel path: {}; static scenes at 128², stepped continuously, median of {reps} frames:",
        cases[0].1.simd_path()
    );
    for round in 1..=3 {
        println!("round {round}");
        for (name, s, w) in &mut cases {
            show(name, steady(reps, s, w.as_mut()));
        }
    }
}

fn show(name: &str, (cpu, wall): (Option<f64>, f64)) {
    match cpu {
        Some(c) => println!("  {name:<34} CPU {c:7.2} ms   wall {wall:7.2} ms"),
        None => println!("  {name:<34} CPU     n/a      wall {wall:7.2} ms"),
    }
}

fn ratio(a: (Option<f64>, f64), b: (Option<f64>, f64)) -> String {
    match (a.0, b.0) {
        (Some(x), Some(y)) => format!("{:.2} (CPU), {:.2} (wall)", x / y, a.1 / b.1),
        _ => format!("{:.2} (wall)", a.1 / b.1),
    }
}

fn main() {
    let reps: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(15);
    match std::env::args().nth(2).as_deref() {
        Some("mesh") => {
            let (s, w) = in_contact(icosphere_drop(Method::Xpbd, 128).expect("scene"));
            show("20,480-triangle mesh + ground", with(reps, &s, &w));
            return;
        }
        Some("ground") => {
            let (mut s, _) = in_contact(icosphere_drop(Method::Xpbd, 128).expect("scene"));
            let mut w = ground_alone(&s);
            show("ground alone", steady(reps, &mut s, Some(&mut w)));
            return;
        }
        Some("sphere") => {
            let (s, w) = in_contact(sphere_drop(Method::Xpbd, 128).expect("scene"));
            show("analytic sphere + ground", with(reps, &s, &w));
            return;
        }
        Some("deforming") => {
            let (s, w) = in_contact(breathing_drop(Method::Xpbd, 90).expect("scene"));
            show("deforming mesh + ground", with(reps, &s, &w));
            return;
        }
        Some("steady") => {
            steady_frames(reps);
            return;
        }
        _ => {}
    }
    let (solver, mesh_world) = in_contact(icosphere_drop(Method::Xpbd, 128).expect("scene"));
    let (sphere_solver, sphere_world) = in_contact(sphere_drop(Method::Xpbd, 128).expect("scene"));
    let ground_world = ground_alone(&solver);
    let (mesh_alone, sphere_alone) = balls_alone(&solver, &sphere_solver).expect("each ball alone");
    println!(
        "solver kernel path: {} (WEFT_SIMD=avx512|avx2|scalar forces one)",
        solver.simd_path()
    );
    println!("static, 128² cloth, per frame (median of {reps}):");
    let solve = bare(reps, &solver);
    let ground_only = with(reps, &solver, &ground_world);
    let mesh = with(reps, &solver, &mesh_world);
    let mesh_only = with(reps, &solver, &mesh_alone);
    let sphere_solve = bare(reps, &sphere_solver);
    let sphere = with(reps, &sphere_solver, &sphere_world);
    let sphere_only = with(reps, &sphere_solver, &sphere_alone);
    show("bare solve (mesh scene's state)", solve);
    show("ground only", ground_only);
    show("20,480-triangle mesh + ground", mesh);
    show("20,480-triangle mesh alone", mesh_only);
    show("bare solve (sphere scene's state)", sphere_solve);
    show("analytic sphere + ground", sphere);
    show("analytic sphere alone", sphere_only);
    println!("  frame with mesh / bare solve: {}", ratio(mesh, solve));
    println!("  mesh frame / sphere frame:    {}", ratio(mesh, sphere));
    let (solver, world) = in_contact(breathing_drop(Method::Xpbd, 90).expect("scene"));
    println!("deforming, 90² cloth on a 5,120-triangle ball, per frame (median of {reps}):");
    let solve = bare(reps, &solver);
    let deforming = with(reps, &solver, &world);
    show("bare solve", solve);
    show("deforming mesh + ground", deforming);
    println!(
        "  frame with mesh / bare solve: {}",
        ratio(deforming, solve)
    );
}
