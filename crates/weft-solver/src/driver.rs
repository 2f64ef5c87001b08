//! Driven pins: particles whose positions and velocities something outside the solver
//! prescribes at every substep's time (cloth vertices attached to an animated bone).
//!
//! A [`PinDriver`] is asked, once per substep and before anything reads the predicted
//! positions, where its particles are at the end of that substep; they are held there with
//! inverse mass 0, exactly like [`crate::KinematicPin`]s (same place in the loop, fused and
//! general paths alike). After the velocity update the driver's velocities replace the
//! chord (x − x_prev)/h, so a driven particle reports the velocity of what carries it.

use glam::DVec3;

/// Prescribes the positions and velocities of a fixed set of particles at any time.
///
/// Called from the step loop, inside rayon's pool: it must be cheap (a bone's transform applied
/// to a few hundred points) and must not call back into rayon's pool in a way that depends on
/// the thread count.
pub trait PinDriver: Send + Sync {
    /// The driven particles (global indices into the solver's store), fixed for the driver's
    /// life. No particle may appear twice.
    fn particles(&self) -> &[u32];

    /// Positions and velocities of [`Self::particles`] at time `t` (s), in the same order;
    /// both slices have `particles().len()` entries.
    fn drive(&self, t: f64, positions: &mut [DVec3], velocities: &mut [DVec3]);
}

impl std::fmt::Debug for dyn PinDriver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PinDriver")
            .field("particles", &self.particles().len())
            .finish()
    }
}
