//! The closest points of two segments (Ericson, *Real-Time Collision Detection*, §5.1.9,
//! `ClosestPtSegmentSegment`) and the distance of a point to a triangle (§5.1.5, through
//! [`closest_on_triangle`]): the narrow phase of cloth contact and of its continuous check.

use glam::DVec3;

use crate::trimesh::closest::{Closest, closest_on_triangle};

/// The closest points of segments `p0 p1` and `q0 q1`: parameters `(s, t)` in [0, 1] with the
/// points `p0 + s (p1 − p0)` and `q0 + t (q1 − q0)` (Ericson §5.1.9).
#[inline]
pub(crate) fn segment_params(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> (f64, f64) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    const EPS: f64 = 1e-30;
    if a <= EPS && e <= EPS {
        return (0.0, 0.0);
    }
    if a <= EPS {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(r);
    if e <= EPS {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    let mut s = if denom > EPS * a * e {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

/// The distance between segments `p0 p1` and `q0 q1`.
#[inline]
pub(crate) fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let (s, t) = segment_params(p0, p1, q0, q1);
    (p0.lerp(p1, s)).distance(q0.lerp(q1, t))
}

/// The point of triangle `t` closest to `p`.
#[inline]
pub(crate) fn closest_point(p: DVec3, t: [DVec3; 3]) -> Closest {
    closest_on_triangle(p, t[0], t[1], t[2])
}

/// The distance from `p` to triangle `t`.
#[inline]
pub(crate) fn point_triangle_distance(p: DVec3, t: [DVec3; 3]) -> f64 {
    p.distance(closest_point(p, t).point)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the smallest distance over a fine grid of both parameters.
    fn brute(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
        let n = 400;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                best = best.min(p0.lerp(p1, s).distance(q0.lerp(q1, t)));
            }
        }
        best
    }

    #[test]
    fn segment_distance_matches_brute_force() {
        let mut seed = 7u64;
        let mut r = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for _ in 0..60 {
            let v: Vec<DVec3> = (0..4).map(|_| DVec3::new(r(), r(), r())).collect();
            let d = segment_distance(v[0], v[1], v[2], v[3]);
            let b = brute(v[0], v[1], v[2], v[3]);
            // The grid's spacing is 1/400 of segments at most 3.5 long.
            assert!(
                d <= b + 1e-12 && b - d < 0.01,
                "closed form {d}, brute force {b}"
            );
        }
        // Parallel segments.
        let d = segment_distance(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Y + DVec3::X * 2.0);
        assert!((d - 1.0).abs() < 1e-12);
    }
}
