//! Long-range attachment (Kim et al. 2012): C = |p − a| − L, active only when C > 0.

use glam::DVec3;

use super::{Shape, distance_curvature};

/// Keeps a particle within a maximum distance of its pinned anchor (`[particle, anchor]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tether {
    /// Maximum distance L (m).
    pub max_length: f64,
}

impl Shape<2> for Tether {
    #[inline]
    fn evaluate(&self, p: &[DVec3; 2]) -> Option<(f64, [DVec3; 2])> {
        let d = p[0] - p[1];
        let len = d.length();
        if len <= self.max_length || len < 1e-9 {
            return None;
        }
        let n = d / len;
        Some((len - self.max_length, [n, -n]))
    }

    #[inline]
    fn curvature_product(&self, p: &[DVec3; 2], dp: &[DVec3; 2]) -> [DVec3; 2] {
        distance_curvature(p, dp)
    }
}
