//! The shared reference workload (see `../shared/peers/README.md`): an N×N 1 m grid of 1 kg,
//! top edge pinned, stretch + shear at α = 0, dt = 1/60, 10 substeps × 1 iteration.
//! Prints ms per frame. Usage: `cargo run --release -p weft-solver --example reference_workload -- N FRAMES`.

use std::time::Instant;

use weft_solver::{ClothParams, Edge, Family, Forces, GridDesc, Pin, Settings, SolverBuilder};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(Ok(128), |a| a.parse())?;
    let frames: usize = args.next().map_or(Ok(60), |a| a.parse())?;
    let mesh = GridDesc {
        resolution: (n, n),
        pins: vec![Pin::Edge(Edge::Top)],
        ..GridDesc::default()
    }
    .build()?;
    let mut params = ClothParams::default();
    for f in Family::ALL {
        params.get_mut(f).enabled = matches!(f, Family::Stretch | Family::Shear);
        params.get_mut(f).compliance = 0.0;
    }
    let mut b = SolverBuilder::new(Settings::default(), Forces::default())?;
    b.add_cloth("cloth", &mesh, params, 0.0)?;
    let mut s = b.build();
    println!(
        "N = {n}: {} particles, {} constraints, colours {:?}",
        s.particles().len(),
        s.constraints().len(),
        s.constraints().color_counts()
    );
    println!("{:?}", s.domain_stats());
    s.step()?; // warm-up
    let mut times = Vec::with_capacity(frames);
    for _ in 0..frames {
        let t = Instant::now();
        s.step()?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "median {:.3} ms/frame, min {:.3} ms/frame",
        times[frames / 2],
        times[0]
    );
    Ok(())
}
