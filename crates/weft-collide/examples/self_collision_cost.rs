//! What self-collision costs per frame at 128² particles, against the constraint solve itself,
//! measured along a real trajectory.
//!
//! Each scene runs with two hooks in turn each substep: a collision world holding only the
//! self-collision and one holding only the colliders (the ground, and the sphere for `drape`).
//! The time spent inside the self-collision hook is timed directly, frame by frame, while the
//! cloth falls, folds and settles. Frames `--warmup`..`--warmup + --frames` (dt = 1/60 s,
//! 10 substeps × 1 iteration, XPBD) are reported: the median self-collision time per frame,
//! and, stepped from the window's first state without any hook (the fused frame), the median
//! constraint solve per frame; then their ratio. Last, the mean per frame of each part of the
//! self-collision hook (its own clocks, [`weft_collide::SelfCollisionTimes`]) and its ratio to
//! the median solve: the list's upkeep (check, rebuilds, re-anchoring) and the sweeps (finding
//! and applying contacts).
//!
//! `cargo run --release -p weft-collide --example self_collision_cost -- [--scene curtain|drape]
//! [--frames F] [--warmup W] [--n N] [--margin M]`. Set `RAYON_NUM_THREADS` to choose the
//! thread count.
#![allow(clippy::unwrap_used)]

use std::time::{Duration, Instant};

use weft_collide::SelfCollisionParams;
use weft_collide::scenarios;
use weft_solver::{Method, Solver};

#[path = "../tests/integration/common/split.rs"]
mod split;
use split::Split;

struct Args {
    scenes: Vec<String>,
    frames: usize,
    warmup: usize,
    n: usize,
    margin: Option<f64>,
}

fn args() -> Args {
    let mut a = Args {
        scenes: vec!["curtain".into(), "drape".into()],
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
            "--frames" => a.frames = value.parse().unwrap(),
            "--warmup" => a.warmup = value.parse().unwrap(),
            "--n" => a.n = value.parse().unwrap(),
            "--margin" => a.margin = Some(value.parse().unwrap()),
            _ => panic!("unknown flag {flag}"),
        }
    }
    a
}

/// The scene's solver and its split hook: `curtain` is [`scenarios::curtain_fold`] (a curtain
/// folding onto itself in layers on the ground), `drape` an n × n sheet dropped on the sphere
/// ([`scenarios::sphere_drop`]) with self-collision on.
fn scene(name: &str, n: usize, params: SelfCollisionParams) -> (Solver, Split) {
    let (solver, colliders) = match name {
        "curtain" => scenarios::curtain_fold(Method::Xpbd, n).unwrap(),
        "drape" => scenarios::sphere_drop(Method::Xpbd, n).unwrap(),
        _ => panic!("unknown scene {name}"),
    };
    let split = Split::new(&solver, colliders, params).unwrap();
    (solver, split)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn main() {
    let a = args();
    let threads = rayon::current_num_threads();
    let params = SelfCollisionParams {
        search_margin: a
            .margin
            .unwrap_or(SelfCollisionParams::default().search_margin),
        adaptive_margin: a.margin.is_none(),
        ..SelfCollisionParams::default()
    };
    for name in &a.scenes {
        let (mut solver, mut hook) = scene(name, a.n, params);
        for _ in 0..a.warmup {
            solver.step_with(&mut hook).unwrap();
        }
        let start = solver.clone();
        let lists = |h: &Split| h.own.self_collision_lists().unwrap();
        let (r0, u0, _) = lists(&hook);
        let times = |h: &Split| h.own.self_collision_times().unwrap();
        let t0 = times(&hook);
        let mut own = Vec::new();
        let mut contacts = 0;
        for _ in 0..a.frames {
            hook.spent = Duration::ZERO;
            solver.step_with(&mut hook).unwrap();
            own.push(hook.spent.as_secs_f64() * 1e3);
            contacts = contacts.max(hook.own.stats().self_contacts);
        }
        let (r1, u1, len) = lists(&hook);
        let t1 = times(&hook);
        let mut bare = start.clone();
        let solve: Vec<f64> = (0..a.frames)
            .map(|_| {
                let t = Instant::now();
                bare.step().unwrap();
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        let (own, solve) = (median(own), median(solve));
        println!(
            "{name} {n}x{n}, thickness {t:.4} m, {threads} thread(s), frames {w}..{e}: up to \
             {contacts} self contacts per substep; {} rebuilds and {} partial updates of the \
             list, {len} pairs at the end; KE {:.2e} J",
            r1 - r0,
            u1 - u0,
            solver.particles().kinetic_energy(),
            n = a.n,
            t = solver.cloths()[0].thickness,
            w = a.warmup,
            e = a.warmup + a.frames,
        );
        println!(
            "  median per frame: self-collision {own:.3} ms, constraint solve {solve:.3} ms; \
             ratio {:.2}",
            own / solve
        );
        // Mean per frame of each part over the window, and against the median solve.
        let frames = a.frames as f64;
        let per_frame = |now: Duration, then: Duration| (now - then).as_secs_f64() * 1e3 / frames;
        let parts = [
            ("check", per_frame(t1.check, t0.check)),
            ("rebuild", per_frame(t1.rebuild, t0.rebuild)),
            ("re-anchor", per_frame(t1.reanchor, t0.reanchor)),
            ("find", per_frame(t1.find, t0.find)),
            ("apply", per_frame(t1.apply, t0.apply)),
        ];
        let line: Vec<String> = parts
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.3} ({:.2})", ms / solve))
            .collect();
        let (upkeep, sweep) = (
            parts[..3].iter().map(|p| p.1).sum::<f64>(),
            parts[3..].iter().map(|p| p.1).sum::<f64>(),
        );
        println!(
            "  mean per frame, ms (÷ solve): {}; upkeep {upkeep:.3} ({:.2}), sweep {sweep:.3} ({:.2})",
            line.join(", "),
            upkeep / solve,
            sweep / solve
        );
    }
}
