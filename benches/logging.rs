//! MCAP logging overhead of `weft run` on the 128² default scene (`assets/scenes/hanging.toml`
//! with `--set cloth.cloth.resolution=[128, 128]`), in process through the crates `weft run` uses:
//! weft-sim (`Simulation`) and weft-record (`Recorder`).
//!
//! Per frame, as `weft run` does it: `no_log` steps the simulation; `mcap` steps it and logs
//! the frame (`Recorder::frame` with the CLI defaults: particles, the cloth mesh every frame,
//! `/stats`) to a file under the system temp dir; `writer_only` logs a fixed frame without
//! stepping. Opening and finishing the log (once per run) are outside the timing.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};

use weft_record::{RecordOptions, Recorder, Status};
use weft_sim::Simulation;

const N: usize = 128;

fn simulation() -> Simulation {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/hanging.toml");
    let resolution: weft_scene::Override = format!("cloth.cloth.resolution=[{N}, {N}]")
        .parse()
        .expect("well-formed override");
    let scene = weft_scene::load(&path, &[resolution]).expect("hanging.toml loads");
    Simulation::new(scene).expect("scene builds")
}

/// The options `weft run` uses by default (`--mesh-every 1`, no `--timing`).
const OPTIONS: RecordOptions = RecordOptions {
    mesh_every: 1,
    timing: false,
};

fn sink() -> PathBuf {
    std::env::temp_dir().join(format!("weft-bench-logging-{}.mcap", std::process::id()))
}

/// Opens a fresh log at `path` for `sim`, as `weft run --out` does.
fn recorder(sim: &Simulation, path: &PathBuf, frames: u64) -> Recorder {
    let file = std::fs::File::create(path).expect("temp file");
    Recorder::new(file, sim, frames, OPTIONS).expect("recorder")
}

fn logging(c: &mut Criterion) {
    let path = sink();
    let mut group = c.benchmark_group(format!("weft_run/{}", N * N));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(1));

    let mut sim = simulation();
    group.bench_function(BenchmarkId::from_parameter("no_log"), |b| {
        b.iter(|| black_box(sim.step().expect("stable")));
    });

    let mut sim = simulation();
    group.bench_function(BenchmarkId::from_parameter("mcap"), |b| {
        b.iter_custom(|iters| {
            let mut rec = recorder(&sim, &path, iters);
            let t = Instant::now();
            for _ in 0..iters {
                let stats = sim.step().expect("stable");
                rec.frame(&sim, &stats).expect("log frame");
            }
            let elapsed = t.elapsed();
            rec.finish(&Status::Complete, iters).expect("finish log");
            elapsed
        });
    });

    let sim = simulation();
    let stats = sim.stats(0.0, 0);
    group.bench_function(BenchmarkId::from_parameter("writer_only"), |b| {
        b.iter_custom(|iters| {
            let mut rec = recorder(&sim, &path, iters);
            let t = Instant::now();
            for _ in 0..iters {
                rec.frame(&sim, &stats).expect("log frame");
            }
            let elapsed = t.elapsed();
            rec.finish(&Status::Complete, iters).expect("finish log");
            elapsed
        });
    });
    group.finish();
    let size = std::fs::metadata(&path).map_or(0, |m| m.len());
    eprintln!("last log: {size} bytes at {}", path.display());
    let _ = std::fs::remove_file(&path);
}

criterion_group!(benches, logging);
criterion_main!(benches);
