//! Error values of the solver crate.

use glam::DVec3;
use thiserror::Error;

use crate::method::Method;
pub use crate::params::ParamError;
use crate::stability::StabilityBound;

/// A cloth mesh that cannot be simulated.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MeshError {
    /// The mesh has no triangle.
    #[error("mesh has no triangles")]
    Empty,
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} uses vertex {index}, but the mesh has only {vertices} vertices")]
    IndexOutOfRange {
        /// The triangle's index.
        triangle: usize,
        /// The bad vertex index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A triangle has zero area or repeats a vertex.
    #[error("triangle {triangle} is degenerate (zero area or repeated vertex)")]
    DegenerateTriangle {
        /// The triangle's index.
        triangle: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// The vertex's index.
        vertex: u32,
    },
    /// A vertex is used by no triangle.
    #[error("vertex {vertex} belongs to no triangle")]
    UnusedVertex {
        /// The vertex's index.
        vertex: u32,
    },
    /// More than two triangles share one edge.
    #[error("edge {a}-{b} is shared by more than two triangles (non-manifold mesh)")]
    NonManifoldEdge {
        /// One end of the edge.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// A pinned index does not exist.
    #[error("pinned particle {index} does not exist (the cloth has {vertices})")]
    PinOutOfRange {
        /// The bad index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// Mass or density not finite and positive.
    #[error("mass must be finite and positive, got {value}")]
    InvalidMass {
        /// The value given.
        value: f64,
    },
    /// A grid needs at least 2×2 particles.
    #[error("a grid needs at least 2x2 particles, got {columns}x{rows}")]
    GridTooSmall {
        /// Columns given.
        columns: usize,
        /// Rows given.
        rows: usize,
    },
    /// Grid size not finite and positive.
    #[error("grid size must be finite and positive, got {width} x {height}")]
    InvalidSize {
        /// Width given.
        width: f64,
        /// Height given.
        height: f64,
    },
}

/// A failure while stepping.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SolverError {
    /// The simulation blew up: a position became non-finite or left the sane bound.
    #[error(
        "{method} simulation diverged at frame {frame}: particle {particle} reached {position} \
         (divergence bound {bound} m){}",
        limit_hint(*.method, *.h, .stability)
    )]
    Diverged {
        /// The method that was running.
        method: Method,
        /// The frame being stepped (0-based).
        frame: u64,
        /// The first offending particle.
        particle: usize,
        /// Its position.
        position: DVec3,
        /// The bound that was crossed (m).
        bound: f64,
        /// The substep length (s).
        h: f64,
        /// The explicit-spring stability bound of the whole solver (every cloth).
        stability: StabilityBound,
    },
    /// The stop flag (see `Solver::set_stop`) was raised inside a frame, which was abandoned.
    #[error("stopped inside frame {frame}")]
    Interrupted {
        /// The frame that was abandoned (0-based).
        frame: u64,
    },
    /// A particle index that does not exist.
    #[error("particle {index} does not exist (the solver has {count})")]
    NoSuchParticle {
        /// The index given.
        index: usize,
        /// Number of particles.
        count: usize,
    },
    /// A pin driver lists a particle twice.
    #[error("pin driver lists particle {particle} twice")]
    DrivenTwice {
        /// The repeated particle.
        particle: usize,
    },
}

/// A cloth or pin that cannot be added to a solver.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum BuildError {
    /// A parameter is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A pin names a vertex or cloth that does not exist.
    #[error("cloth {cloth} has no vertex {vertex}")]
    NoSuchVertex {
        /// The cloth's index.
        cloth: usize,
        /// The vertex given.
        vertex: u32,
    },
    /// The cloth's vertex count does not match its masses.
    #[error("cloth `{name}` has {positions} positions but {masses} masses")]
    MassCount {
        /// The cloth's name.
        name: String,
        /// Number of positions.
        positions: usize,
        /// Number of masses.
        masses: usize,
    },
}

/// Which limit a divergence passed: the springs' stability limit, or none the solver knows.
fn limit_hint(method: Method, h: f64, b: &StabilityBound) -> String {
    let (sure, mode) = (b.max_substep(), b.mode_max_substep());
    let ms = |s: f64| s * 1e3;
    if !method.is_explicit() {
        return "; lower the stiffness or the time step, or add substeps".to_owned();
    }
    if h >= mode {
        format!(
            "; substep h = {:.3} ms is past the springs' stability limit h < {:.3} ms of their \
             highest mode ω = {:.0} rad/s (semi-implicit Euler needs h²ω² + 2hγ < 4; \
             guaranteed below {:.3} ms by Gershgorin's bound ω ≤ {:.0} rad/s): soften the \
             springs or add substeps",
            ms(h),
            ms(mode),
            b.mode_omega,
            ms(sure),
            b.omega
        )
    } else if h >= sure {
        format!(
            "; substep h = {:.3} ms is inside the springs' highest-mode limit {:.3} ms but past \
             the guaranteed one, {:.3} ms (Gershgorin bound ω ≤ {:.0} rad/s)",
            ms(h),
            ms(mode),
            ms(sure),
            b.omega
        )
    } else {
        format!(
            "; substep h = {:.3} ms was inside the springs' guaranteed stability limit {:.3} ms \
             (ω ≤ {:.0} rad/s), so contact, pins, forces or stretched tethers drove it",
            ms(h),
            ms(sure),
            b.omega
        )
    }
}
