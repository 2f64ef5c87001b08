//! Continuous collision of a moving point with a triangle: the first time within a substep
//! at which the point lies in the triangle, for a still triangle (segment–plane crossing,
//! Ericson §5.3.6) and for one whose corners move linearly over the substep (the point is
//! coplanar with the triangle at the roots of a cubic in t; Provot 1997, "Collision and
//! self-collision handling in cloth model dedicated to design garments"; Bridson, Fedkiw and
//! Anderson 2002, "Robust treatment of collisions, contact and friction for cloth animation",
//! §4).

use glam::DVec3;

/// Relative tolerance of the inside-the-triangle test at a crossing (of the triangle's
/// barycentric weights): a point crossing an edge shared by two triangles is caught by one.
const EDGE_SLACK: f64 = 1e-9;

/// A crossing: the fraction of the substep, the barycentric weights of the crossing point in
/// the triangle, and the side the point came from (+1: the side the normal points to).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Crossing {
    /// Fraction t ∈ [0, 1] of the path.
    pub t: f64,
    /// Barycentric weights of the crossing point.
    pub bary: [f64; 3],
    /// +1 if the point came from the side (b − a) × (c − a) points to, else −1.
    pub side: f64,
}

/// Barycentric weights of `p` (in the triangle's plane) in (a, b, c), if it lies inside
/// within [`EDGE_SLACK`].
#[inline]
fn inside(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<[f64; 3]> {
    let n = (b - a).cross(c - a);
    let area = n.length_squared();
    if area == 0.0 {
        return None;
    }
    let wa = (c - b).cross(p - b).dot(n) / area;
    let wb = (a - c).cross(p - c).dot(n) / area;
    let wc = 1.0 - wa - wb;
    let ok = wa >= -EDGE_SLACK && wb >= -EDGE_SLACK && wc >= -EDGE_SLACK;
    ok.then_some([wa, wb, wc])
}

/// Where the segment `from → to` crosses the plane of the still triangle (a, b, c) with unit
/// normal `n`, inside the triangle. `entering_only`: only a crossing from the normal's side
/// to the other (the outside to the inside of a closed mesh).
#[inline]
pub(crate) fn segment_crossing(
    from: DVec3,
    to: DVec3,
    [a, b, c]: [DVec3; 3],
    n: DVec3,
    entering_only: bool,
) -> Option<Crossing> {
    let hf = n.dot(from - a);
    let ht = n.dot(to - a);
    let crosses = if entering_only {
        hf >= 0.0 && ht < 0.0
    } else {
        (hf > 0.0 && ht < 0.0) || (hf < 0.0 && ht > 0.0)
    };
    if !crosses {
        return None;
    }
    let t = hf / (hf - ht);
    let bary = inside(from + (to - from) * t, a, b, c)?;
    Some(Crossing {
        t,
        bary,
        side: if hf >= 0.0 { 1.0 } else { -1.0 },
    })
}

/// The first time the point moving from `p0` to `p1` lies in the triangle moving from
/// `start` to `end` (corners linear in t over [0, 1]). `entering_only` as for
/// [`segment_crossing`]; the side is the one just before the crossing.
pub(crate) fn moving_crossing(
    p0: DVec3,
    p1: DVec3,
    start: [DVec3; 3],
    end: [DVec3; 3],
    entering_only: bool,
) -> Option<Crossing> {
    // f(t) = ((b − a) × (c − a)) · (p − a) at time t, a cubic c0 + c1 t + c2 t² + c3 t³.
    let e1 = start[1] - start[0];
    let e2 = start[2] - start[0];
    let q = p0 - start[0];
    let de1 = (end[1] - end[0]) - e1;
    let de2 = (end[2] - end[0]) - e2;
    let dq = (p1 - end[0]) - q;
    let n0 = e1.cross(e2);
    let n1 = e1.cross(de2) + de1.cross(e2);
    let n2 = de1.cross(de2);
    let c = [
        n0.dot(q),
        n0.dot(dq) + n1.dot(q),
        n1.dot(dq) + n2.dot(q),
        n2.dot(dq),
    ];
    let f = |t: f64| ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
    if c[0] == 0.0 {
        return None; // on the plane at the start: no side to keep (proximity handles it)
    }
    // Monotone pieces of [0, 1] between the roots of f' = c1 + 2 c2 t + 3 c3 t².
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut k = 1;
    let (qa, qb, qc) = (3.0 * c[3], 2.0 * c[2], c[1]);
    let add = |t: f64, cuts: &mut [f64; 4], k: &mut usize| {
        if t > 0.0 && t < 1.0 {
            cuts[*k] = t;
            *k += 1;
        }
    };
    if qa != 0.0 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let s = disc.sqrt();
            let (r1, r2) = ((-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa));
            let (r1, r2) = (r1.min(r2), r1.max(r2));
            add(r1, &mut cuts, &mut k);
            add(r2, &mut cuts, &mut k);
        }
    } else if qb != 0.0 {
        add(-qc / qb, &mut cuts, &mut k);
    }
    cuts[k] = 1.0;
    let at = |t: f64| {
        let lerp = |u: DVec3, v: DVec3| u + (v - u) * t;
        (
            lerp(p0, p1),
            [
                lerp(start[0], end[0]),
                lerp(start[1], end[1]),
                lerp(start[2], end[2]),
            ],
        )
    };
    let mut lo = 0.0;
    for &hi in &cuts[1..=k] {
        let (flo, fhi) = (f(lo), f(hi));
        // One root at most on a monotone piece: where f leaves the side it had at `lo`.
        let side = if flo > 0.0 {
            1.0
        } else if flo < 0.0 {
            -1.0
        } else {
            lo = hi;
            continue;
        };
        if fhi * side <= 0.0 && !(entering_only && side < 0.0) {
            let (mut a, mut b) = (lo, hi);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if f(m) * side > 0.0 {
                    a = m;
                } else {
                    b = m;
                }
                if b - a <= 1e-13 {
                    break;
                }
            }
            let (p, [ta, tb, tc]) = at(b);
            if let Some(bary) = inside(p, ta, tb, tc) {
                return Some(Crossing { t: b, bary, side });
            }
        }
        lo = hi;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic_vs_parry::Rng;

    /// A point and a triangle that both translate: at the reported time the point lies in
    /// the triangle's plane, and sampling finer than the substep finds no earlier crossing.
    #[test]
    fn moving_crossing_is_the_first_coplanar_inside_time() {
        let mut rng = Rng(3);
        let mut found = 0;
        for _ in 0..2000 {
            let start = [rng.cube(1.0), rng.cube(1.0), rng.cube(1.0)];
            let end = start.map(|v| v + rng.cube(0.8));
            let (p0, p1) = (rng.cube(1.0), rng.cube(1.0));
            let hit = moving_crossing(p0, p1, start, end, false);
            // The triangle's corners and the point at time t.
            let at = |t: f64| {
                let l = |u: DVec3, v: DVec3| u + (v - u) * t;
                let [a, b, c] = [0, 1, 2].map(|k| l(start[k], end[k]));
                (a, b, c, l(p0, p1))
            };
            // Reference: sample 4000 times; a change of side inside the triangle.
            let side = |t: f64| {
                let (a, b, c, p) = at(t);
                (
                    (b - a).cross(c - a).dot(p - a),
                    inside(p, a, b, c).is_some(),
                )
            };
            let mut reference = None;
            let steps = 4000;
            for s in 0..steps {
                let (t0, t1) = (s as f64 / steps as f64, (s + 1) as f64 / steps as f64);
                let ((f0, _), (f1, in1)) = (side(t0), side(t1));
                if f0 * f1 <= 0.0 && f0 != 0.0 && in1 {
                    reference = Some(t1);
                    break;
                }
            }
            if let Some(h) = hit {
                let (f, inside_then) = side(h.t);
                assert!(
                    inside_then && f.abs() < 1e-9,
                    "{h:?} is not a crossing ({f})"
                );
                found += 1;
            }
            if let Some(r) = reference {
                let h = hit.unwrap_or_else(|| {
                    let near = |t: f64| {
                        let (a, b, c, p) = at(t);
                        let n = (b - a).cross(c - a);
                        let area = n.length_squared();
                        [
                            (c - b).cross(p - b).dot(n) / area,
                            (a - c).cross(p - c).dot(n) / area,
                        ]
                    };
                    panic!(
                        "missed a crossing at {r}: {:?} {:?}",
                        near(r),
                        near(r - 1.0 / steps as f64)
                    )
                });
                assert!(
                    h.t <= r + 1e-9,
                    "hit {h:?} after the sampled crossing at {r}"
                );
            }
        }
        assert!(found > 100, "only {found} crossings");
    }

    #[test]
    fn segment_crossing_keeps_the_side() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Z];
        let n = DVec3::NEG_Y; // (x) × (z) = −y
        // A vertical segment through (x, ·, 0.2) from y = 1 down to y = −1.
        let cross = |x: f64, entering_only: bool| {
            segment_crossing(
                DVec3::new(x, 1.0, 0.2),
                DVec3::new(x, -1.0, 0.2),
                tri,
                n,
                entering_only,
            )
        };
        let down = cross(0.2, false).expect("crosses");
        assert_eq!((down.t, down.side), (0.5, -1.0));
        assert!(cross(0.2, true).is_none());
        assert!(cross(2.0, false).is_none());
    }
}
