//! The task size of the per-particle parallel loops.

/// Particles per parallel task in the general loop's per-particle passes (and the external
/// accelerations'). Each particle's update reads only its own state, so results do not depend
/// on the thread count.
pub(crate) const CHUNK: usize = 1024;
