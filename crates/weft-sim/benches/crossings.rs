//! What measuring cloth crossings costs a frame: `Simulation::step` with the measure off and on
//! (`set_measure_crossings`), and the measure alone (`crossings_now`), side by side on the
//! scenes where it is on by default: the two thin sheets landing on the ball
//! (`assets/scenes/layers.toml`, 4,608 particles, from frame 20) and the twisted sheet
//! (`assets/scenes/twist.toml`, 2,500 particles, from frame 60).
//!
//! Every sample starts from the same state: the scene is built and stepped to its first frame
//! outside the timing, then `iters` frames are timed, so the rows cover the same motion.

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main};
use weft_sim::Simulation;

fn warmed(scene: &str, warm: u64, measure: bool) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/scenes")
        .join(scene);
    let scene = weft_scene::load(&path, &[]).expect("the scene loads");
    let mut sim = Simulation::new(scene).expect("the scene builds");
    sim.set_measure_crossings(measure);
    for _ in 0..warm {
        sim.step().expect("stable");
    }
    sim
}

fn scene_group(c: &mut Criterion, scene: &str, warm: u64) {
    let mut group = c.benchmark_group(format!("crossings/{}", scene.trim_end_matches(".toml")));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(8));
    for (row, measure) in [("frame_off", false), ("frame_on", true)] {
        group.bench_function(BenchmarkId::from_parameter(row), |b| {
            b.iter_custom(|iters| {
                let mut sim = warmed(scene, warm, measure);
                let start = Instant::now();
                for _ in 0..iters {
                    black_box(sim.step().expect("stable"));
                }
                start.elapsed()
            })
        });
    }
    group.bench_function(BenchmarkId::from_parameter("measure_alone"), |b| {
        let sim = warmed(scene, warm, false);
        b.iter(|| black_box(sim.crossings_now()))
    });
    group.finish();
}

fn crossings(c: &mut Criterion) {
    scene_group(c, "layers.toml", 20);
    scene_group(c, "twist.toml", 60);
    scene_group(c, "character.toml", 12);
}

criterion_group!(benches, crossings);
criterion_main!(benches);
