//! Substeps × iterations at equal cost: 1×20, 2×10, 5×4, 10×2, 20×1 projections of every
//! constraint per frame on the reference cloth (`assets/scenes/reference.toml`, 64×64, XPBD,
//! α = 0) with `--set sim.substeps=S --set sim.iterations=I`.
//!
//! Criterion times one frame of each. Outside the timing, each configuration also hangs the
//! cloth for 1 s (60 frames) from rest and records the constraint error it reached (RMS and
//! max |C| over every stretch and shear constraint, m, and the mean RMS over the last 0.5 s); the bench prints that table and
//! writes it to `<target>/criterion/substeps_error.md` (and `.json`, for
//! `scripts/bench_summary.py`). Equal cost, so lower error is better: small steps should win.

mod common;

use std::fmt::Write as _;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};

use common::{criterion_dir, evaluations_per_frame, load, single_group};

/// Grid size N of the N×N cloth.
const N: usize = 64;
/// (substeps, iterations), all 20 projections of each constraint per frame.
const CONFIGS: [(u32, u32); 5] = [(1, 20), (2, 10), (5, 4), (10, 2), (20, 1)];
/// Frames simulated before the error is read: 1 s at dt = 1/60.
const FRAMES: usize = 60;

fn overrides(substeps: u32, iterations: u32) -> Vec<String> {
    vec![
        format!("cloth.reference.resolution=[{N}, {N}]"),
        format!("sim.substeps={substeps}"),
        format!("sim.iterations={iterations}"),
    ]
}

/// One row of the table: the error after 1 s and the wall time that run took.
struct Row {
    substeps: u32,
    iterations: u32,
    rms: f64,
    max: f64,
    /// Mean of the per-frame RMS over the second half second (less sensitive to the phase of
    /// the cloth's swing at the 1 s snapshot).
    mean_rms: f64,
    ms_per_frame: f64,
}

fn error_after_one_second(substeps: u32, iterations: u32) -> Row {
    let mut g = single_group(&load("reference.toml", &overrides(substeps, iterations)));
    let mut elapsed = Duration::ZERO;
    let mut late_rms = Vec::new();
    for frame in 1..=FRAMES {
        let t = Instant::now();
        g.step().expect("stable");
        elapsed += t.elapsed();
        if frame > FRAMES / 2 {
            late_rms.push(g.solver.residual().rms);
        }
    }
    let ms_per_frame = elapsed.as_secs_f64() * 1e3 / FRAMES as f64;
    let mean_rms = late_rms.iter().sum::<f64>() / late_rms.len() as f64;
    let r = g.solver.residual();
    Row {
        substeps,
        iterations,
        rms: r.rms,
        max: r.max,
        mean_rms,
        ms_per_frame,
    }
}

fn write_table(rows: &[Row]) {
    let mut md = format!(
        "Constraint error after 1 s ({FRAMES} frames, dt = 1/60) of the reference cloth, \
         {N}×{N}, XPBD, α = 0; every configuration projects each constraint 20 times per frame.\n\n\
         | substeps × iterations | RMS C at 1 s (m) | max abs C at 1 s (m) | mean RMS C, 0.5–1 s (m) | ms/frame (this run) |\n\
         |---|---|---|---|---|\n"
    );
    let mut json = String::from("[");
    for (i, r) in rows.iter().enumerate() {
        let _ = writeln!(
            md,
            "| {} × {} | {:.3e} | {:.3e} | {:.3e} | {:.2} |",
            r.substeps, r.iterations, r.rms, r.max, r.mean_rms, r.ms_per_frame
        );
        let _ = write!(
            json,
            "{}{{\"substeps\": {}, \"iterations\": {}, \"rms\": {:e}, \"max\": {:e}, \"mean_rms\": {:e}, \"ms_per_frame\": {}}}",
            if i > 0 { ", " } else { "" },
            r.substeps,
            r.iterations,
            r.rms,
            r.max,
            r.mean_rms,
            r.ms_per_frame
        );
    }
    json.push_str("]\n");
    println!("\n{md}");
    let dir = criterion_dir();
    let written = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::write(dir.join("substeps_error.md"), &md))
        .and_then(|()| std::fs::write(dir.join("substeps_error.json"), &json));
    match written {
        Ok(()) => println!("wrote {}", dir.join("substeps_error.md").display()),
        Err(e) => eprintln!("cannot write the table to {}: {e}", dir.display()),
    }
}

fn substeps(c: &mut Criterion) {
    let rows: Vec<Row> = CONFIGS
        .iter()
        .map(|&(s, i)| error_after_one_second(s, i))
        .collect();
    // Same cost per frame, so the configurations differ only in the error they reach; the
    // claim this table checks is that substeps beat iterations.
    assert!(
        rows[rows.len() - 1].rms < rows[0].rms,
        "20×1 should reach a smaller RMS error than 1×20"
    );
    write_table(&rows);

    let mut group = c.benchmark_group(format!("substeps_x_iterations/{}", N * N));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for (s, i) in CONFIGS {
        let mut g = single_group(&load("reference.toml", &overrides(s, i)));
        group.throughput(Throughput::Elements(evaluations_per_frame(&g)));
        group.bench_function(BenchmarkId::from_parameter(format!("{s}x{i}")), |b| {
            b.iter(|| black_box(g.step().expect("stable")));
        });
    }
    group.finish();
}

criterion_group!(benches, substeps);
criterion_main!(benches);
