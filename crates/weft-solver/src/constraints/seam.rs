//! Seam constraint: C = |p₀ − p₁| − r(t), with a rest length r that ramps from the pair's
//! initial gap to zero over a closing time, then holds the pair together (zero rest length).
//!
//! This is the distance constraint (Müller et al. 2007, eq. 9) with a time-dependent rest
//! length; Marvelous Designer-style sewing pulls matched seam vertices together this way.

use glam::DVec3;

use super::{Shape, distance_curvature, distance_evaluate};

/// Pulls two seam vertices together: rest length `gap · max(0, 1 − t/T)` at time t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seam {
    /// The pair's distance when the seam was made (m).
    pub gap: f64,
    /// Closing time T (s): the rest length reaches zero at t = T (at once when T = 0).
    pub closing_time: f64,
    /// Current rest length (m), set by [`Seam::set_time`].
    pub rest: f64,
}

impl Seam {
    /// A closed seam at most this far open (m) is held shut once more after the contacts of
    /// each substep (see `ConstraintSet::hold_seams`).
    pub const HOLD_GAP: f64 = 0.01;

    /// A seam over a pair `gap` apart that closes over `closing_time` seconds.
    pub fn new(gap: f64, closing_time: f64) -> Self {
        let mut s = Self {
            gap,
            closing_time,
            rest: gap,
        };
        s.set_time(0.0);
        s
    }

    /// The rest length at time `t` (s): gap · max(0, 1 − t/T), zero once closed.
    pub fn rest_at(&self, t: f64) -> f64 {
        if self.closing_time <= 0.0 {
            0.0
        } else {
            self.gap * (1.0 - t / self.closing_time).clamp(0.0, 1.0)
        }
    }

    /// Sets the rest length for time `t` (s).
    pub fn set_time(&mut self, t: f64) {
        self.rest = self.rest_at(t);
    }
}

impl Shape<2> for Seam {
    #[inline]
    fn evaluate(&self, p: &[DVec3; 2]) -> Option<(f64, [DVec3; 2])> {
        // Closed to rounding: C ≈ 0 and the direction undefined, nothing to do.
        distance_evaluate(p, self.rest, 1e-12)
    }

    #[inline]
    fn curvature_product(&self, p: &[DVec3; 2], dp: &[DVec3; 2]) -> [DVec3; 2] {
        distance_curvature(p, dp)
    }
}
