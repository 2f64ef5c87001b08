//! Distance constraint C = |p₀ − p₁| − d (Müller et al. 2007, eq. 9; the poster's Δp formula).

use glam::DVec3;

use super::{Shape, distance_curvature, distance_evaluate};

/// Keeps two particles at a rest distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distance {
    /// Rest length d (m).
    pub rest: f64,
}

impl Shape<2> for Distance {
    #[inline]
    fn evaluate(&self, p: &[DVec3; 2]) -> Option<(f64, [DVec3; 2])> {
        distance_evaluate(p, self.rest, 1e-9)
    }

    #[inline]
    fn curvature_product(&self, p: &[DVec3; 2], dp: &[DVec3; 2]) -> [DVec3; 2] {
        distance_curvature(p, dp)
    }
}
