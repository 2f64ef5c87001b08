//! Probe (not committed): the layered outfit under mesh contact, per frame.
#![allow(clippy::unwrap_used, missing_docs)]
use std::path::Path;
use std::time::Instant;
use weft_scene::Override;

fn main() {
    let frames: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(20);
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/layered_outfit.toml");
    let ov: Vec<Override> = Vec::new();
    let scene = weft_scene::load(&path, &ov).unwrap();
    let mut groups = scene.build().unwrap();
    let g = &mut groups[0];
    let (mut lb, mut lr) = (0, 0);
    for f in 0..frames {
        let t = Instant::now();
        g.step().unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        if f < 9 {
            for (c, info) in g.solver.cloths().iter().enumerate() {
                let x = &g.solver.particles().positions;
                let m = weft_collide::crossings::measure(x, &info.triangles, 0.0045);
                let pinned = info
                    .particles
                    .clone()
                    .filter(|&i| g.solver.particles().inv_masses[i] == 0.0)
                    .count();
                println!(
                    "  cloth {c}: {} particles, {} pinned, crossings {}, closest {:?}",
                    info.particles.len(),
                    pinned,
                    m.crossings,
                    m.closest
                );
            }
        }
        if let Some(s) = g.world.as_ref().and_then(|w| w.cloth_contact_stats()) {
            println!(
                "frame {f}: {ms:.0} ms builds {} refreshes {} listed {} contacts {} impacts {} frozen {} rounds {}",
                s.builds - lb,
                s.refreshes - lr,
                s.listed,
                s.contacts,
                s.fail_safe.impacts,
                s.fail_safe.frozen,
                s.fail_safe.rounds
            );
            (lb, lr) = (s.builds, s.refreshes);
        } else {
            println!("frame {f}: {ms:.0} ms (no cloth contact yet)");
        }
    }
}
