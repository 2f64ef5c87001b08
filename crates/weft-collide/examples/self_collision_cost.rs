//! What self-collision costs per frame at 128² particles, against the constraint solve itself.
//!
//! Two scenes, each stepped `--warmup` frames with self-collision (so that the cloth is folded
//! or draped onto itself), then, from that same state, `--frames` frames of dt = 1/60 s with
//! 10 substeps × 1 iteration (XPBD) three ways:
//! (a) the collision world with self-collision, (b) the same world with self-collision off,
//! (c) no hook at all (`solver.step()`). Prints the median wall time per frame of each and
//! (a) − (b) against (c), in wall time and in CPU time (all threads).
//!
//! `cargo run --release -p weft-collide --example self_collision_cost -- [--scene curtain|drape|fold]
//! [--only a|b|c] [--frames F] [--warmup W] [--n N] [--margin M]`; `--only` runs one variant (for
//! `perf stat -e task-clock`). Set `RAYON_NUM_THREADS` to choose the thread count.
#![allow(clippy::unwrap_used)]

use std::time::Instant;

use weft_collide::scenarios::{self, THICKNESS};
use weft_collide::{CollisionWorld, SelfCollisionParams};
use weft_solver::glam::DVec3;
use weft_solver::{GridDesc, Mass, Method, Orientation, Solver, SolverBuilder};

struct Args {
    scenes: Vec<String>,
    only: Option<char>,
    frames: usize,
    warmup: usize,
    n: usize,
    margin: Option<f64>,
}

fn args() -> Args {
    let mut a = Args {
        scenes: vec!["curtain".into(), "drape".into(), "fold".into()],
        only: None,
        frames: 30,
        warmup: 60,
        n: 128,
        margin: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let value = it.next().unwrap_or_else(|| panic!("{flag} needs a value"));
        match flag.as_str() {
            "--scene" => a.scenes = vec![value],
            "--only" => a.only = value.chars().next(),
            "--frames" => a.frames = value.parse().unwrap(),
            "--warmup" => a.warmup = value.parse().unwrap(),
            "--n" => a.n = value.parse().unwrap(),
            "--margin" => a.margin = Some(value.parse().unwrap()),
            _ => panic!("unknown flag {flag}"),
        }
    }
    a
}

/// A vertical square n × n sheet, 0.9 m wide, thickness = particle spacing, 5 cm above the
/// ground, with the self-fold scenario's wavy sideways velocity: it buckles and folds onto
/// itself like [`scenarios::self_fold`], but with square cells.
fn curtain(n: usize) -> (Solver, CollisionWorld) {
    let (size, bottom) = (0.9, 0.05);
    let thickness = size / (n - 1) as f64;
    let mesh = GridDesc {
        resolution: (n, n),
        size: (size, size),
        center: DVec3::new(0.0, bottom + 0.5 * size, 0.0),
        orientation: Orientation::Vertical,
        mass: Mass::Total(0.2),
        pins: vec![],
    }
    .build()
    .unwrap();
    let (settings, params) = scenarios::method_setup(Method::Xpbd);
    let mut builder = SolverBuilder::new(settings, scenarios::scenario_forces()).unwrap();
    builder
        .add_cloth("curtain", &mesh, params, thickness)
        .unwrap();
    let mut solver = builder.build();
    let p = solver.particles_mut();
    for i in 0..p.len() {
        let y = p.positions[i].y - bottom;
        p.velocities[i].z = 0.3 * (std::f64::consts::TAU * y / 0.3).sin();
    }
    let mut world = CollisionWorld::new(&solver);
    world.add_collider(&scenarios::ground(0.0)).unwrap();
    world
        .enable_self_collision(&solver, &[0], SelfCollisionParams::default())
        .unwrap();
    (solver, world)
}

/// The scene: `fold` is the self-fold strip at n × n (0.3 m × 0.9 m, so its cells are three
/// times wider than tall); `curtain` the same fall with square cells ([`curtain`]); `drape`
/// an n × n sheet dropped on the sphere (thickness below the spacing: few self contacts).
fn scene(name: &str, n: usize) -> (Solver, CollisionWorld) {
    match name {
        "curtain" => curtain(n),
        "fold" => scenarios::self_fold(Method::Xpbd, n, n).unwrap(),
        "drape" => {
            let (solver, mut world) = scenarios::sphere_drop(Method::Xpbd, n).unwrap();
            world
                .enable_self_collision(&solver, &[0], SelfCollisionParams::default())
                .unwrap();
            (solver, world)
        }
        _ => panic!("unknown scene {name}"),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

/// CPU time of this process so far (ns), summed over its threads from Linux's
/// `/proc/self/task/*/schedstat` (first field: time on CPU); 0 where that is not available.
/// On a machine shared with other work, CPU time is steadier than wall time.
fn cpu_ns() -> u64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

/// Median wall and CPU ms per frame over `frames` frames from a copy of `solver`, with
/// `world` or no hook.
fn time_frames(solver: &Solver, world: Option<&CollisionWorld>, frames: usize) -> (f64, f64) {
    let mut solver = solver.clone();
    let mut world = world.cloned();
    let lists = |w: &Option<CollisionWorld>| w.as_ref().and_then(|w| w.self_collision_lists());
    let mut wall = Vec::with_capacity(frames);
    let mut cpu = Vec::with_capacity(frames);
    let before = lists(&world);
    for _ in 0..frames {
        let (t, c) = (Instant::now(), cpu_ns());
        match &mut world {
            Some(w) => solver.step_with(w).unwrap(),
            None => solver.step().unwrap(),
        };
        wall.push(t.elapsed().as_secs_f64() * 1e3);
        cpu.push((cpu_ns() - c) as f64 * 1e-6);
    }
    if let (Some((r0, u0, _)), Some((r1, u1, len))) = (before, lists(&world)) {
        println!(
            "  self-collision lists: {} rebuilds and {} partial updates in {frames} frames of \
             {} substeps; {len} pairs",
            r1 - r0,
            u1 - u0,
            solver.settings().substeps
        );
    }
    (median(wall), median(cpu))
}

fn main() {
    let a = args();
    let threads = rayon::current_num_threads();
    for name in &a.scenes {
        let (mut solver, mut world) = scene(name, a.n);
        if let Some(search_margin) = a.margin {
            let params = SelfCollisionParams {
                search_margin,
                ..SelfCollisionParams::default()
            };
            world.enable_self_collision(&solver, &[0], params).unwrap();
        }
        for _ in 0..a.warmup {
            solver.step_with(&mut world).unwrap();
        }
        let stats = world.stats();
        let thickness = solver.cloths()[0].thickness;
        println!(
            "{name} {n}x{n} (thickness {thickness:.4} m, sphere-drop thickness {THICKNESS}), \
             {threads} thread(s), after {w} warm-up frames: {} self contacts, deepest {:.2e} m, \
             KE {:.2e} J",
            stats.self_contacts,
            stats.max_self_depth,
            solver.particles().kinetic_energy(),
            n = a.n,
            w = a.warmup,
        );
        let mut without = world.clone();
        without.disable_self_collision();
        let run = |v: char| a.only.is_none_or(|o| o == v);
        let ta = run('a').then(|| time_frames(&solver, Some(&world), a.frames));
        let tb = run('b').then(|| time_frames(&solver, Some(&without), a.frames));
        let tc = run('c').then(|| time_frames(&solver, None, a.frames));
        for (what, pick) in [("wall", 0), ("cpu", 1)] {
            let get = |t: Option<(f64, f64)>| t.map(|t| if pick == 0 { t.0 } else { t.1 });
            let show = |t: Option<f64>| t.map_or("-".to_string(), |t| format!("{t:.3} ms"));
            let (ta, tb, tc) = (get(ta), get(tb), get(tc));
            println!(
                "  median {what} per frame: (a) self-collision {}, (b) without {}, (c) no hook {}",
                show(ta),
                show(tb),
                show(tc)
            );
            if let (Some(ta), Some(tb), Some(tc)) = (ta, tb, tc) {
                println!(
                    "    self-collision adds (a)-(b) = {:.3} ms per frame; constraint solve (c) \
                     = {tc:.3} ms; ratio {:.2}",
                    ta - tb,
                    (ta - tb) / tc
                );
            }
        }
    }
}
