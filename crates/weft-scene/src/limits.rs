//! Limits a load enforces before it reads or allocates: the largest file read, and the memory
//! the scene may need once built, estimated from its particle count before any cloth exists.

use crate::scene::DEFAULT_MAX_FILE_BYTES;
use crate::schema::SceneFile;

/// What a load may read and allocate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest scene or mesh file read (bytes).
    pub max_file_bytes: u64,
    /// Memory the built scene may need (bytes), and where that figure comes from (for the
    /// message, e.g. "MemAvailable" or "--max-memory"); `None`: no limit.
    pub max_memory: Option<(u64, String)>,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_memory: None,
        }
    }
}

/// Bytes one particle of a built scene needs: its mesh (positions, masses, triangles, stretch
/// and shear edges), the solver's store, constraints, domains and scratch, and one frame of
/// log messages with their encode and compression buffers. The peak resident set of
/// `weft run --out` over 512² and 1024² grids is 1010 bytes per particle (2026-11-24, AMD
/// EPYC, AVX-512 path); rounded up for scenes with more constraints.
pub const BYTES_PER_PARTICLE: u64 = 1200;

/// Extra bytes per particle with self-collision on (the spatial grid and contact lists):
/// measured 240 on a 512² grid, rounded up.
pub const PER_PARTICLE_SELF_COLLISION: u64 = 400;

/// Particles of every grid cloth in `file`, read from the resolutions alone (a mesh cloth's
/// file is capped by [`Limits::max_file_bytes`] instead).
pub(crate) fn grid_particles(file: &SceneFile) -> Vec<(String, u64)> {
    file.cloth
        .iter()
        .filter(|(_, s)| s.mesh.is_none())
        .map(|(name, s)| {
            let [nx, ny] = s.resolution.unwrap_or([20, 20]);
            let n = (nx.clamp(0, 4096) as u64) * (ny.clamp(0, 4096) as u64);
            (name.clone(), n)
        })
        .collect()
}

/// The memory `particles` need once built.
pub fn estimate_bytes(particles: u64, self_collision: bool) -> u64 {
    let per = BYTES_PER_PARTICLE
        + if self_collision {
            PER_PARTICLE_SELF_COLLISION
        } else {
            0
        };
    particles.saturating_mul(per)
}

/// `bytes` for people: "3.2 GiB".
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= (1u64 << 30) as f64 {
        format!("{:.1} GiB", b / (1u64 << 30) as f64)
    } else {
        format!("{:.0} MiB", (b / (1u64 << 20) as f64).ceil())
    }
}
