//! The windy flag that the kernel-path and fused-frame determinism tests run, and the means to
//! run it on a given number of threads, fused or through the general loop.

use weft_solver::glam::DVec3;
use weft_solver::{
    ClothMesh, ClothParams, Family, Forces, Method, Settings, Solver, SolverBuilder, SubstepHook,
    Wind,
};

/// A hook that does nothing but says it is active, forcing the general loop.
pub struct Active;

impl SubstepHook for Active {}

/// Runs `f` inside a rayon pool of `threads` threads.
pub fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

/// `method` with 4 substeps of 2 iterations in domains of `domain_size` particles.
pub fn flag_settings(method: Method, domain_size: usize) -> Settings {
    Settings {
        method,
        substeps: 4,
        iterations: 2,
        domain_size,
        ..Settings::default()
    }
}

/// A `resolution` flag pinned along its top edge, with distance and damped dihedral bending and compliant, damped
/// stretch, in 3 m/s linear wind (drag 0.2) with global damping 0.1: the builder holding it
/// (add pins before building) and its mesh.
pub fn windy_flag(resolution: (usize, usize), settings: Settings) -> (SolverBuilder, ClothMesh) {
    flag_with(resolution, settings, true)
}

/// [`windy_flag`] without dihedral bending, which only the general loop handles: its frames
/// run fused unless a hook asks otherwise.
pub fn fusable_flag(resolution: (usize, usize), settings: Settings) -> (SolverBuilder, ClothMesh) {
    flag_with(resolution, settings, false)
}

fn flag_with(
    resolution: (usize, usize),
    settings: Settings,
    dihedral: bool,
) -> (SolverBuilder, ClothMesh) {
    let mesh = super::top_pinned_grid(resolution);
    let params = ClothParams::default()
        .edit(Family::BendDistance, |p| p.enabled = true)
        // Dihedral bending too, damped: its own lane kernel (AVX-512, AVX2 and portable
        // vectors, and one lane for the rest) must give the same bits on every path.
        .edit(Family::BendDihedral, |p| {
            p.enabled = dihedral;
            p.compliance = 1e-3;
            p.damping = 0.1;
        })
        .edit(Family::Stretch, |p| {
            p.compliance = 1e-6;
            p.damping = 0.5;
        });
    let forces = Forces {
        wind: Wind {
            velocity: DVec3::new(0.0, 0.0, 3.0),
            drag: 0.2,
            aero: None,
        },
        damping: 0.1,
        ..Forces::default()
    };
    let mut b = SolverBuilder::new(settings, forces).expect("valid");
    b.add_cloth("flag", &mesh, params, 0.01).expect("valid");
    (b, mesh)
}

/// Steps one frame, through the general loop when `general` (an active hook), else fused.
pub fn step(s: &mut Solver, general: bool) {
    if general {
        s.step_with(&mut Active).expect("stable");
    } else {
        s.step().expect("stable");
    }
}

/// 30 frames ([`step`]) with particle `corner` grabbed at frame 5, dragged through frame 14
/// and released at 15.
pub fn drag_corner(s: &mut Solver, corner: usize, general: bool) {
    for frame in 0..30 {
        match frame {
            5 => s.grab(corner).expect("particle exists"),
            6..15 => s.drag_to(DVec3::new(0.3, -0.6 + 0.02 * frame as f64, 0.4)),
            15 => s.release(),
            _ => {}
        }
        step(s, general);
    }
}

/// The bits of every position, then every velocity.
pub fn state_bits(s: &Solver) -> Vec<[u64; 3]> {
    let p = s.particles();
    p.positions
        .iter()
        .chain(&p.velocities)
        .map(|v| v.to_array().map(f64::to_bits))
        .collect()
}
