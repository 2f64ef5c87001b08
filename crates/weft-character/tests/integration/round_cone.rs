//! The round cone's closed form against brute force: the convex body's support function and
//! the union of interpolated spheres that the hull equals.

use std::f64::consts::TAU;
use std::sync::OnceLock;

use glam::DVec3;
use weft_character::RoundCone;

/// xorshift64*: deterministic points without a dependency.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn in_box(&mut self, lo: DVec3, hi: DVec3) -> DVec3 {
        lo + (hi - lo) * DVec3::new(self.unit(), self.unit(), self.unit())
    }
}

/// Brute force signed distance of a convex body from its support function
/// h(m) = max(m·a + r_a, m·b + r_b): SDF(p) = max over unit m of (m·p − h(m)), exact inside
/// and outside. By symmetry the maximiser lies in the plane through the axis and p, swept
/// here in 400,000 directions.
fn support_sdf(c: &RoundCone, p: DVec3) -> f64 {
    let u = (c.b - c.a).normalize();
    let radial = (p - c.a) - u * (p - c.a).dot(u);
    let e = if radial.length() > 1e-12 {
        radial.normalize()
    } else {
        u.any_orthonormal_vector()
    };
    directions()
        .iter()
        .map(|&(cos, sin)| {
            let m = e * cos + u * sin;
            let h = (m.dot(c.a) + c.ra).max(m.dot(c.b) + c.rb);
            m.dot(p) - h
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// 400,000 directions around the circle, as (cos θ, sin θ).
fn directions() -> &'static [(f64, f64)] {
    static TABLE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = 400_000;
        (0..n)
            .map(|k| {
                let th = TAU * k as f64 / n as f64;
                (th.cos(), th.sin())
            })
            .collect()
    })
}

/// Brute force distance from outside: the hull is the union of spheres centred at
/// (1 − λ) a + λ b with radius (1 − λ) r_a + λ r_b, so the distance is the smallest distance
/// to one of them (200,001 values of λ); also returns that sphere's nearest point.
fn union_distance(c: &RoundCone, p: DVec3) -> (f64, DVec3) {
    let n = 200_000;
    let mut best = (f64::INFINITY, DVec3::ZERO);
    for k in 0..=n {
        let l = k as f64 / n as f64;
        let centre = c.a.lerp(c.b, l);
        let r = c.ra + (c.rb - c.ra) * l;
        let d = (p - centre).length() - r;
        if d < best.0 {
            best = (d, centre + (p - centre).normalize() * r);
        }
    }
    best
}

fn shapes() -> Vec<RoundCone> {
    vec![
        // A forearm: tapering from 4.5 to 3.5 cm over 25 cm, tilted.
        RoundCone::new(
            DVec3::new(0.1, 0.2, -0.1),
            DVec3::new(0.25, 0.0, 0.1),
            0.045,
            0.035,
        ),
        // Widening the other way, strongly (a thigh upside down).
        RoundCone::new(
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.3, 0.05),
            0.05,
            0.12,
        ),
        // A plain capsule.
        RoundCone::new(
            DVec3::new(-0.2, 0.1, 0.0),
            DVec3::new(0.2, 0.1, 0.0),
            0.07,
            0.07,
        ),
        // Nearly degenerate: the small sphere almost inside the big one.
        RoundCone::new(DVec3::ZERO, DVec3::new(0.0, 0.0, 0.061), 0.1, 0.04),
    ]
}

#[test]
fn signed_distance_matches_brute_force_inside_and_outside() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut inside = 0;
    for c in shapes() {
        let lo = c.a.min(c.b) - DVec3::splat(0.25);
        let hi = c.a.max(c.b) + DVec3::splat(0.25);
        for _ in 0..60 {
            let p = rng.in_box(lo, hi);
            let got = c.signed_distance(p);
            let want = support_sdf(&c, p);
            assert!(
                (got - want).abs() < 2e-5,
                "{c:?} at {p}: closed form {got}, brute force {want}"
            );
            inside += usize::from(got < 0.0);
        }
        // Points just inside, on the axis.
        for k in 0..=10 {
            let p = c.a.lerp(c.b, k as f64 / 10.0);
            let got = c.signed_distance(p);
            assert!(
                (got - support_sdf(&c, p)).abs() < 2e-5,
                "{c:?} on the axis at {p}"
            );
            inside += 1;
        }
    }
    assert!(inside > 40, "too few inside points tested: {inside}");
}

#[test]
fn closest_points_and_normals_match_brute_force() {
    let mut rng = Rng(0x0123_4567_89ab_cdef);
    for c in shapes() {
        let lo = c.a.min(c.b) - DVec3::splat(0.3);
        let hi = c.a.max(c.b) + DVec3::splat(0.3);
        let mut outside = 0;
        while outside < 25 {
            let p = rng.in_box(lo, hi);
            let contact = c.contact(p);
            // The closest point lies on the surface, one distance away along the normal.
            assert!(support_sdf(&c, contact.point).abs() < 2e-5, "{c:?}: {p}");
            assert!((contact.point + contact.normal * contact.distance - p).length() < 1e-12);
            assert!((contact.normal.length() - 1.0).abs() < 1e-12);
            // The normal is the gradient of the distance.
            let h = 1e-6;
            let grad = DVec3::new(
                c.signed_distance(p + DVec3::X * h) - c.signed_distance(p - DVec3::X * h),
                c.signed_distance(p + DVec3::Y * h) - c.signed_distance(p - DVec3::Y * h),
                c.signed_distance(p + DVec3::Z * h) - c.signed_distance(p - DVec3::Z * h),
            ) / (2.0 * h);
            assert!(
                (grad - contact.normal).length() < 1e-5,
                "{grad} vs {}",
                contact.normal
            );
            if contact.distance > 0.0 {
                outside += 1;
                let (d, q) = union_distance(&c, p);
                assert!(
                    (contact.distance - d).abs() < 1e-7,
                    "{c:?} at {p}: {} vs {d}",
                    contact.distance
                );
                assert!(
                    (contact.point - q).length() < 1e-4,
                    "{c:?} at {p}: {} vs {q}",
                    contact.point
                );
            }
        }
    }
}

#[test]
fn a_capsule_and_a_swallowed_sphere_reduce_to_their_simple_forms() {
    let cap = RoundCone::new(DVec3::ZERO, DVec3::new(0.0, 1.0, 0.0), 0.1, 0.1);
    assert!((cap.signed_distance(DVec3::new(0.5, 0.3, 0.0)) - 0.4).abs() < 1e-15);
    assert!((cap.signed_distance(DVec3::new(0.0, 1.5, 0.0)) - 0.4).abs() < 1e-15);
    assert!((cap.signed_distance(DVec3::new(0.0, 0.5, 0.05)) + 0.05).abs() < 1e-15);
    let swallowed = RoundCone::new(DVec3::ZERO, DVec3::new(0.0, 0.05, 0.0), 0.2, 0.1);
    let p = DVec3::new(0.0, -0.5, 0.0);
    assert!((swallowed.signed_distance(p) - 0.3).abs() < 1e-15);
    let c = swallowed.contact(DVec3::ZERO);
    assert!((c.distance + 0.2).abs() < 1e-15 && (c.normal.length() - 1.0).abs() < 1e-15);
}
