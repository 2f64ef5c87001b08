//! The fixed split of the particles into parallel tasks.

use glam::DVec3;
use weft_solver::Particles;

/// Particles per parallel task. Fixed, and every particle's contacts depend on that particle
/// alone, so results are the same bit for bit for any number of threads.
pub(crate) const CHUNK: usize = 1024;

/// The particles' positions to move, with their previous positions and inverse masses to read.
pub(crate) fn moving_views(p: &mut Particles) -> (&mut [DVec3], &[DVec3], &[f64]) {
    let Particles {
        positions,
        prev_positions,
        inv_masses,
        ..
    } = p;
    (positions, prev_positions, inv_masses)
}
