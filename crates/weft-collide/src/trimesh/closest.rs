//! The closest point of a triangle to a point, in closed form (Ericson, *Real-Time Collision
//! Detection*, §5.1.5, `ClosestPtPointTriangle`): the Voronoi region of the point (a vertex,
//! an edge or the face) is found from six dot products, and the point projected onto it.

use glam::DVec3;

/// Which part of a triangle a closest point lies on. Edge `k` joins corners `k` and `k + 1`
/// (mod 3); vertex `k` is corner `k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Feature {
    /// The interior of the face.
    Face,
    /// Edge k (corners k, k + 1).
    Edge(u8),
    /// Corner k.
    Vertex(u8),
}

/// A closest point on a triangle: the point, its barycentric weights of the corners, and the
/// feature it lies on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Closest {
    /// The closest point (m).
    pub point: DVec3,
    /// Barycentric weights (w_a, w_b, w_c), summing to 1.
    pub bary: [f64; 3],
    /// The feature holding the point.
    pub feature: Feature,
}

/// The point of triangle (a, b, c) closest to `p` (Ericson §5.1.5).
#[inline(always)]
pub(crate) fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Closest {
    let at = |point, bary, feature| Closest {
        point,
        bary,
        feature,
    };
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(a, [1.0, 0.0, 0.0], Feature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return at(b, [0.0, 1.0, 0.0], Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return at(a + ab * v, [1.0 - v, v, 0.0], Feature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return at(c, [0.0, 0.0, 1.0], Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return at(a + ac * w, [1.0 - w, 0.0, w], Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(b + (c - b) * w, [0.0, 1.0 - w, w], Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    at(a + ab * v + ac * w, [1.0 - v - w, v, w], Feature::Face)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic_vs_parry::Rng;

    /// Against a brute-force minimum over a fine barycentric grid of the triangle and its
    /// edges: the closed form is never farther, and the grid's best is within its spacing.
    #[test]
    fn closed_form_matches_brute_force() {
        let mut rng = Rng(7);
        let mut regions = [0usize; 3];
        for _ in 0..400 {
            let (a, b, c) = (rng.cube(1.0), rng.cube(1.0), rng.cube(1.0));
            let p = rng.cube(2.0);
            let q = closest_on_triangle(p, a, b, c);
            let n = 200;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    let x = a + (b - a) * u + (c - a) * v;
                    best = best.min((p - x).length());
                }
            }
            let d = (p - q.point).length();
            assert!(d <= best + 1e-12, "{p} {a} {b} {c}: {d} > {best}");
            let edge = (b - a).length().max((c - a).length());
            assert!(best - d <= 1.5 * edge / n as f64, "{d} vs grid {best}");
            let [wa, wb, wc] = q.bary;
            assert!((a * wa + b * wb + c * wc - q.point).length() < 1e-12);
            assert!(wa >= 0.0 && wb >= 0.0 && wc >= 0.0);
            match q.feature {
                Feature::Face => regions[0] += 1,
                Feature::Edge(_) => regions[1] += 1,
                Feature::Vertex(_) => regions[2] += 1,
            }
        }
        assert!(regions.iter().all(|&k| k > 10), "regions seen: {regions:?}");
    }
}
