//! MCAP logging against no log, in process through the crates `weft run` uses: weft-sim
//! (`Simulation`) and weft-record (`Recorder`, its log written on its own thread).
//!
//! Two scenes: the 128² reference (`assets/scenes/reference.toml`) and the walker in its
//! T-shirt (`assets/scenes/character.toml`). Per frame, as `weft run --out` does it: `no_log`
//! steps the simulation; each other row steps it and hands the frame to the recorder with the
//! options it names (`particles` is `weft run`'s default: particles, no compression; `all`
//! adds the surface every frame; `zstd` compresses the chunks; `f16` halves the positions).
//! The time of a sample includes finishing its log (the queue written out, the summary, the
//! sync); building the scene, stepping the walker to frame 60 and opening the log are outside
//! it, so every row's samples start from the same state.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};

use weft_record::{Channels, Compression, Precision, RecordOptions, Recorder, Status};
use weft_sim::Simulation;

fn simulation(scene: &str) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(scene);
    let scene = weft_scene::load(&path, &[]).expect("the scene loads");
    Simulation::new(scene).expect("the scene builds")
}

fn sink() -> PathBuf {
    std::env::temp_dir().join(format!("weft-bench-logging-{}.mcap", std::process::id()))
}

/// The rows: a name and the recorder's options.
fn variants() -> Vec<(&'static str, RecordOptions)> {
    let default = RecordOptions::default();
    let all = RecordOptions {
        channels: Channels::All,
        ..default
    };
    let zstd = |o: RecordOptions| RecordOptions {
        compression: Compression::Zstd,
        ..o
    };
    vec![
        ("particles", default),
        ("all", all),
        ("particles_zstd", zstd(default)),
        ("all_zstd", zstd(all)),
        (
            "particles_f16",
            RecordOptions {
                precision: Precision::F16,
                ..default
            },
        ),
    ]
}

/// The scene `scene` built and stepped `warm` frames (outside any timing), so that every
/// row's samples cover the same stretch of its motion.
fn warmed(scene: &str, warm: u64) -> Simulation {
    let mut sim = simulation(scene);
    for _ in 0..warm {
        sim.step().expect("stable");
    }
    sim
}

fn scene_group(c: &mut Criterion, name: &str, scene: &str, warm: u64, seconds: u64) {
    let path = sink();
    let mut group = c.benchmark_group(format!("logging/{name}"));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(seconds))
        .throughput(Throughput::Elements(1));

    group.bench_function(BenchmarkId::from_parameter("no_log"), |b| {
        b.iter_custom(|iters| {
            let mut sim = warmed(scene, warm);
            let t = Instant::now();
            for _ in 0..iters {
                black_box(sim.step().expect("stable"));
            }
            t.elapsed()
        });
    });
    for (label, options) in variants() {
        group.bench_function(BenchmarkId::from_parameter(label), |b| {
            b.iter_custom(|iters| {
                let mut sim = warmed(scene, warm);
                let file = std::fs::File::create(&path).expect("a temporary file");
                let mut rec = Recorder::new(file, &sim, iters, options).expect("a recorder");
                let t = Instant::now();
                for _ in 0..iters {
                    let stats = sim.step().expect("stable");
                    rec.frame(&sim, &stats).expect("a frame logged");
                }
                rec.finish(&Status::Complete, iters)
                    .expect("the log finished");
                t.elapsed()
            });
        });
    }
    group.finish();
    let _ = std::fs::remove_file(&path);
}

/// Bytes a frame costs in each row's log: a 120-frame run's file over its 121 logged frames
/// (its header, scene and summary included), as `{"<scene>/<row>": bytes}` in
/// `<criterion>/logging_bytes.json` for the summary script.
fn bytes_per_frame(scenes: &[(&str, &str)]) {
    const FRAMES: u64 = 120;
    let path = sink();
    let mut entries = Vec::new();
    for (name, scene) in scenes {
        for (label, options) in variants() {
            let mut sim = simulation(scene);
            let file = std::fs::File::create(&path).expect("a temporary file");
            let mut rec = Recorder::new(file, &sim, FRAMES, options).expect("a recorder");
            rec.frame(&sim, &sim.stats(0.0, 0)).expect("frame 0");
            for _ in 0..FRAMES {
                let stats = sim.step().expect("stable");
                rec.frame(&sim, &stats).expect("a frame logged");
            }
            rec.finish(&Status::Complete, FRAMES)
                .expect("the log finished");
            let size = std::fs::metadata(&path).map_or(0, |m| m.len());
            let per_frame = size / (FRAMES + 1);
            eprintln!("logging/{name}/{label}: {per_frame} bytes a frame");
            entries.push(format!("\"{name}/{label}\": {per_frame}"));
        }
    }
    let _ = std::fs::remove_file(&path);
    let dir = std::env::var_os("CRITERION_HOME")
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("CARGO_TARGET_DIR").map(|t| PathBuf::from(t).join("criterion"))
        })
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target/criterion"));
    let json = format!("{{{}}}\n", entries.join(", "));
    if let Err(e) = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::write(dir.join("logging_bytes.json"), json))
    {
        eprintln!("logging_bytes.json not written in {}: {e}", dir.display());
    }
}

const SCENES: [(&str, &str); 2] = [
    ("reference", "assets/scenes/reference.toml"),
    ("walker", "assets/scenes/character.toml"),
];

fn logging(c: &mut Criterion) {
    // The walker from frame 60, dressed and walking (its seams close in the first 0.1 s).
    for ((name, scene), (warm, seconds)) in SCENES.iter().zip([(0, 3), (60, 6)]) {
        scene_group(c, name, scene, warm, seconds);
    }
    bytes_per_frame(&SCENES);
}

criterion_group!(benches, logging);
criterion_main!(benches);
