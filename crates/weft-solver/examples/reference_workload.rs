//! The shared reference workload (see `../shared/peers/README.md` and
//! `assets/scenes/reference.toml`): an N×N 1 m grid of 1 kg, top edge pinned, stretch + shear
//! at α = 0, dt = 1/60, 10 substeps × 1 iteration, no bending.
//!
//! Prints one line in the peers' style (`ms/frame=MEAN (median MEDIAN)`, over the frames after
//! the warm-up), so `scripts/compare_peers.sh` and `../shared/peers/summarize.py` read it:
//!
//! ```sh
//! cargo run --release -p weft-solver --example reference_workload -- --n 128 --frames 60 --threads 1
//! ```
//!
//! The old positional form `-- N FRAMES` still works. `--threads 0` uses rayon's default pool.
//! `--simd avx512|avx2|neon|scalar` (or `WEFT_SIMD=…`) forces the kernel path; the output names
//! the path that ran. `--method` picks the method (default xpbd); springs get k = m / (16 h²)
//! for a particle's mass m, as in the method benches.

use std::process::ExitCode;
use std::time::Instant;

use weft_solver::{
    ClothParams, Edge, Family, Forces, GridDesc, Method, Pin, Settings, SimdPath, SolverBuilder,
};

/// Command-line options.
struct Options {
    n: usize,
    frames: usize,
    warmup: usize,
    threads: usize,
    domain_size: usize,
    simd: Option<SimdPath>,
    method: Method,
}

const USAGE: &str = "usage: reference_workload [--n N] [--frames F] [--warmup W] [--threads T] [--domain-size D] [--simd avx512|avx2|neon|scalar] [--method NAME] | [N [FRAMES]]";

fn parse_args() -> Result<Options, String> {
    let mut o = Options {
        n: 128,
        frames: 60,
        warmup: 3,
        threads: 1,
        domain_size: Settings::default().domain_size,
        simd: SimdPath::from_env().map_err(|e| format!("WEFT_SIMD: {e}"))?,
        method: Method::Xpbd,
    };
    let mut positional = 0;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| -> Result<usize, String> {
            let v = args
                .next()
                .ok_or(format!("{name} needs a value\n{USAGE}"))?;
            v.parse()
                .map_err(|e| format!("{name} {v}: {e}, expected a whole number\n{USAGE}"))
        };
        match a.as_str() {
            "--n" => o.n = value("--n")?,
            "--frames" => o.frames = value("--frames")?,
            "--warmup" => o.warmup = value("--warmup")?,
            "--threads" => o.threads = value("--threads")?,
            "--domain-size" => o.domain_size = value("--domain-size")?,
            "--simd" => {
                let v = args
                    .next()
                    .ok_or(format!("--simd needs a value\n{USAGE}"))?;
                o.simd = Some(v.parse().map_err(|e| format!("--simd: {e}\n{USAGE}"))?);
            }
            "--method" => {
                let v = args
                    .next()
                    .ok_or(format!("--method needs a value\n{USAGE}"))?;
                o.method = v.parse().map_err(|e| format!("--method: {e}\n{USAGE}"))?;
            }
            "-h" | "--help" => return Err(USAGE.to_owned()),
            _ if !a.starts_with('-') && positional < 2 => {
                let v: usize = a
                    .parse()
                    .map_err(|e| format!("{a}: {e}, expected a whole number\n{USAGE}"))?;
                if positional == 0 {
                    o.n = v;
                } else {
                    o.frames = v;
                }
                positional += 1;
            }
            _ => return Err(format!("unexpected argument `{a}`\n{USAGE}")),
        }
    }
    if o.n < 2 || o.frames == 0 {
        return Err(format!("need N >= 2 and FRAMES >= 1\n{USAGE}"));
    }
    Ok(o)
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("reference_workload: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let o = parse_args()?;
    let n = o.n;
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
        // As the method benches: k = m / (16 h²) for the lightest particle, so ω h ≤ 1.
        let h = Settings::default().h();
        params.get_mut(f).spring_stiffness = 1.0 / (n * n) as f64 / (16.0 * h * h);
    }
    let settings = Settings {
        domain_size: o.domain_size,
        simd: o.simd,
        method: o.method,
        ..Settings::default()
    };
    let mut b = SolverBuilder::new(settings, Forces::default())?;
    b.add_cloth("cloth", &mesh, params, 0.0)?;
    let mut s = b.build();
    // Stretch 2N(N−1) + shear 2(N−1)²: 64,770 at N = 128.
    let expected = 2 * n * (n - 1) + 2 * (n - 1) * (n - 1);
    let constraints = s.constraints().len();
    if constraints != expected {
        return Err(format!("N = {n}: {constraints} constraints, expected {expected}").into());
    }
    println!(
        "N = {n}: {} particles, {constraints} constraints, colours {:?}",
        s.particles().len(),
        s.constraints().color_counts()
    );
    println!("{:?}", s.domain_stats());
    if let Some(asked) = o.simd
        && asked != s.simd_path()
    {
        println!(
            "kernel path {asked} is not available on this CPU: running {}",
            s.simd_path()
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(o.threads)
        .build()?;
    let threads = pool.current_num_threads();
    let mut times = Vec::with_capacity(o.frames);
    let mut cg = 0u64;
    pool.install(|| -> Result<(), weft_solver::SolverError> {
        for _ in 0..o.warmup {
            s.step()?;
        }
        for _ in 0..o.frames {
            let t = Instant::now();
            cg += u64::from(s.step()?.cg_iterations);
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        Ok(())
    })?;
    let total_ms: f64 = times.iter().sum();
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let mean = total_ms / times.len() as f64;
    let substeps = u64::from(settings.substeps);
    let iterations = u64::from(settings.iterations);
    let projections = (constraints as u64 * substeps * iterations) as f64;
    let r = s.residual();
    println!(
        "{:<14} simd={:<6} threads={threads} N={n:<4} particles={:<6} constraints={constraints:<6} substeps={substeps:<3} iters={iterations} frames={} seconds={:.3} ms/frame={mean:.3} (median {median:.3}) ns/proj={:.2} proj/s={:.4e}",
        format!("weft-{}", o.method.name()),
        s.simd_path().name(),
        s.particles().len(),
        o.frames,
        total_ms / 1e3,
        1e6 * median / projections,
        projections / median * 1e3,
    );
    if cg > 0 {
        println!("  {:.1} CG iterations a frame", cg as f64 / o.frames as f64);
    }
    println!(
        "  min {:.3} ms/frame, max {:.3} ms/frame; residual after {} frames: max |C| {:.3e} m, RMS {:.3e} m",
        times[0],
        times[times.len() - 1],
        o.warmup + o.frames,
        r.max,
        r.rms
    );
    Ok(())
}
