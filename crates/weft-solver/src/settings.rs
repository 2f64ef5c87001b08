//! Time stepping settings.

use glam::DVec3;

use crate::error::ParamError;
use crate::method::Method;
use crate::sparse::CgLimits;
use weft_simd::SimdPath;

/// Whether position `x` is finite with no coordinate beyond `bound` in magnitude (the
/// divergence check, see [`Settings::divergence_bound`]). No branch: NaN fails `<=`, and an
/// infinite coordinate fails the second test whatever the bound.
#[inline(always)]
pub(crate) fn within_bound(x: DVec3, bound: f64) -> bool {
    let fine = |c: f64| (c.abs() <= bound) & (c.abs() < f64::INFINITY);
    fine(x.x) & fine(x.y) & fine(x.z)
}

/// Default of [`Settings::cg_max_iterations`]: a guard, not a budget. The stiffest shipped case,
/// the cantilever strip at 32 segments, needs up to about 500 a substep while it falls; capped
/// at 200 its solve stopped short every substep and the strip sagged to 55° against the
/// elastica's 41.5° (docs/validation.md).
pub const DEFAULT_CG_MAX_ITERATIONS: u32 = 1000;

/// Default of [`Settings::cg_tolerance`]: the loosest relative residual whose error stays far
/// below the substeps' own on the shipped scenes (docs/performance-notes.md, "Implicit springs").
pub const DEFAULT_CG_TOLERANCE: f64 = 1e-3;

/// How the solver steps: method, frame time step, substeps and iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The method.
    pub method: Method,
    /// Frame time step Δt (s); each frame is split into `substeps` substeps of h = Δt / substeps.
    pub dt: f64,
    /// Substeps per frame (≥ 1).
    pub substeps: u32,
    /// Constraint sweeps per substep (≥ 1; ignored by mass-spring).
    pub iterations: u32,
    /// A particle farther than this from the origin (m) means the simulation diverged.
    pub divergence_bound: f64,
    /// Most particles per parallel domain: the particles are cut into the fewest domains of
    /// at most this many that number a power of two, all of one size (a multiple of 8), so
    /// that the fork–join tree's halves hold equal work. Domains solve their own constraints
    /// concurrently; constraints across domains are solved after them, serially. The split,
    /// and so the result, depends on this and the mesh, never on the thread count. The default,
    /// 8,192, gives a 128² cloth one domain per core on two cores; smaller domains mean more
    /// constraints across domains (slower on one or two cores), larger ones fewer domains
    /// than cores on bigger machines. A cloth of 4,096 particles or more is cut in two at
    /// least, whatever this says, so that two threads share it.
    pub domain_size: usize,
    /// The kernel path of the constraint sweep: `None` takes `WEFT_SIMD` (`avx512`, `avx2`,
    /// `neon` or `scalar`, read once) or else the widest path the CPU runs; a path the CPU
    /// lacks falls back to the widest one it has. Changes the speed, never the result.
    pub simd: Option<SimdPath>,
    /// Implicit mass-spring: conjugate-gradient iterations at most per substep (≥ 1).
    pub cg_max_iterations: u32,
    /// Implicit mass-spring: the linear solve stops at ‖b − A Δv‖ ≤ this · ‖b‖ (in (0, 1)).
    pub cg_tolerance: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            method: Method::Xpbd,
            dt: 1.0 / 60.0,
            substeps: 10,
            iterations: 1,
            divergence_bound: 1.0e4,
            domain_size: 8192,
            simd: None,
            cg_max_iterations: DEFAULT_CG_MAX_ITERATIONS,
            cg_tolerance: DEFAULT_CG_TOLERANCE,
        }
    }
}

impl Settings {
    /// Substep length h = Δt / substeps (s).
    pub fn h(&self) -> f64 {
        self.dt / self.substeps as f64
    }

    /// Checks the values make sense.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &str, value: f64, expected| {
            Err(ParamError {
                name: name.to_owned(),
                value,
                expected,
            })
        };
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return bad("dt", self.dt, "finite and > 0");
        }
        if self.substeps == 0 {
            return bad("substeps", 0.0, ">= 1");
        }
        if self.iterations == 0 {
            return bad("iterations", 0.0, ">= 1");
        }
        if !(self.divergence_bound.is_finite() && self.divergence_bound > 0.0) {
            return bad("divergence_bound", self.divergence_bound, "finite and > 0");
        }
        if self.cg_max_iterations == 0 {
            return bad("cg_max_iterations", 0.0, ">= 1");
        }
        if !(self.cg_tolerance > 0.0 && self.cg_tolerance < 1.0) {
            return bad("cg_tolerance", self.cg_tolerance, "in (0, 1)");
        }
        Ok(())
    }

    /// The implicit method's linear-solve limits.
    pub(crate) fn cg_limits(&self) -> CgLimits {
        CgLimits {
            max_iterations: self.cg_max_iterations,
            tolerance: self.cg_tolerance,
        }
    }
}
