//! A tapered capsule ("round cone"): the convex hull of two spheres, with a closed-form f64
//! signed distance, closest point and normal (spheres and capsules are special cases).
//!
//! In the plane through the axis and the query point (radial coordinate x ≥ 0, axial y from
//! the centre `a`), the surface is the arc of circle (0, 0; r_a), the segment of the common
//! tangent line and the arc of circle (0, l; r_b). The tangent's outward normal is
//! n = (cos φ, sin φ) with sin φ = (r_a − r_b) / l, since n · (c_b − c_a) = r_a − r_b for a
//! line tangent to both circles. Projecting the point on the tangent's direction
//! t = (−sin φ, cos φ) picks the closest feature: s < 0 → sphere a, s > l cos φ → sphere b,
//! otherwise the cone, at signed distance n · q − r_a. This is exact inside as well as
//! outside (the same decomposition as Quílez's `sdRoundCone`,
//! <https://iquilezles.org/articles/distfunctions/>).

use glam::DVec3;

/// Signed distance, closest surface point and outward normal at a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Signed distance to the surface (m): negative inside.
    pub distance: f64,
    /// Closest point on the surface.
    pub point: DVec3,
    /// Outward unit normal at `point` (the gradient of the distance at the query point).
    pub normal: DVec3,
}

/// Convex hull of the spheres (a, r_a) and (b, r_b); a capsule when r_a = r_b.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundCone {
    /// Centre of the first sphere.
    pub a: DVec3,
    /// Centre of the second sphere.
    pub b: DVec3,
    /// Radius at `a` (m).
    pub ra: f64,
    /// Radius at `b` (m).
    pub rb: f64,
}

/// Signed distance and contact for a sphere; `fallback` is the normal at the centre.
#[inline]
pub fn sphere_contact(center: DVec3, radius: f64, p: DVec3, fallback: DVec3) -> Contact {
    let d = p - center;
    let len = d.length();
    let normal = if len > 0.0 { d / len } else { fallback };
    Contact {
        distance: len - radius,
        point: center + normal * radius,
        normal,
    }
}

/// [`sphere_contact`] if `p` lies within `reach` of the sphere or inside, else `None` (before
/// the normal's division); the same bits.
#[inline]
fn sphere_within(
    center: DVec3,
    radius: f64,
    p: DVec3,
    fallback: DVec3,
    reach: f64,
) -> Option<Contact> {
    let d = p - center;
    let len = d.length();
    let distance = len - radius;
    // Written so that a NaN distance is no contact, as in `contact_within`'s filter.
    (distance <= reach).then(|| {
        let normal = if len > 0.0 { d / len } else { fallback };
        Contact {
            distance,
            point: center + normal * radius,
            normal,
        }
    })
}

impl RoundCone {
    /// A round cone from its sphere centres and radii.
    pub fn new(a: DVec3, b: DVec3, ra: f64, rb: f64) -> Self {
        Self { a, b, ra, rb }
    }

    /// A sphere, as the round cone with both ends at `center`.
    pub fn sphere(center: DVec3, radius: f64) -> Self {
        Self::new(center, center, radius, radius)
    }

    /// The constants every query needs (axis, length, tangent angle), computed once.
    pub fn prepare(&self) -> PreparedCone {
        let ab = self.b - self.a;
        let l = ab.length();
        let dr = self.ra - self.rb;
        if l <= dr.abs() {
            // One sphere inside the other (or coincident centres): the hull is the larger one.
            let (c, r) = if self.ra >= self.rb {
                (self.a, self.ra)
            } else {
                (self.b, self.rb)
            };
            return PreparedCone {
                a: c,
                b: c,
                ra: r,
                rb: r,
                u: DVec3::Y,
                l: 0.0,
                sin: 0.0,
                cos: 1.0,
                sphere: true,
            };
        }
        let sin = dr / l;
        PreparedCone {
            a: self.a,
            b: self.b,
            ra: self.ra,
            rb: self.rb,
            u: ab / l,
            l,
            sin,
            cos: (1.0 - sin * sin).sqrt(),
            sphere: false,
        }
    }

    /// Signed distance, closest point and normal for the point `p`.
    pub fn contact(&self, p: DVec3) -> Contact {
        self.prepare().contact(p)
    }

    /// Signed distance (m), negative inside.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.contact(p).distance
    }

    /// Closest point on the surface.
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        self.contact(p).point
    }

    /// Outward unit normal of the surface nearest `p`.
    pub fn normal(&self, p: DVec3) -> DVec3 {
        self.contact(p).normal
    }
}

/// A [`RoundCone`] with its per-query constants: unit axis u, length l and the tangent's
/// angle φ (sin φ = (r_a − r_b) / l); a sphere when one end's sphere holds the other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedCone {
    a: DVec3,
    b: DVec3,
    ra: f64,
    rb: f64,
    u: DVec3,
    l: f64,
    sin: f64,
    cos: f64,
    sphere: bool,
}

impl PreparedCone {
    /// Signed distance, closest point and normal for the point `p` (see the module's text).
    #[inline]
    pub fn contact(&self, p: DVec3) -> Contact {
        if self.sphere {
            return sphere_contact(self.a, self.ra, p, DVec3::Y);
        }
        let u = self.u;
        let pa = p - self.a;
        let y = pa.dot(u);
        let radial = pa - u * y;
        let x = radial.length();
        let e = if x > 0.0 {
            radial / x
        } else {
            u.any_orthonormal_vector()
        };
        let (sin, cos) = (self.sin, self.cos);
        let s = -sin * x + cos * y;
        if s < 0.0 {
            return sphere_contact(self.a, self.ra, p, -u);
        }
        if s > self.l * cos {
            return sphere_contact(self.b, self.rb, p, u);
        }
        let normal = e * cos + u * sin;
        let distance = cos * x + sin * y - self.ra;
        Contact {
            distance,
            point: p - normal * distance,
            normal,
        }
    }

    /// [`Self::contact`] if `p` lies within `reach` of the surface or inside, else `None`;
    /// points clearly farther (outside the slab of the axis or the cylinder around it, grown by
    /// `reach`) are rejected before any square root, and points beyond `reach` before the
    /// normal's division. The same arithmetic as [`Self::contact`], so the same bits.
    #[inline]
    pub fn contact_within(&self, p: DVec3, reach: f64) -> Option<Contact> {
        let pa = p - self.a;
        let rmax = self.ra.max(self.rb) + reach;
        if self.sphere {
            if pa.length_squared() > rmax * rmax {
                return None;
            }
            return sphere_within(self.a, self.ra, p, DVec3::Y, reach);
        }
        let u = self.u;
        let y = pa.dot(u);
        if y < -self.ra - reach || y > self.l + self.rb + reach {
            return None;
        }
        if pa.length_squared() - y * y > rmax * rmax {
            return None;
        }
        let radial = pa - u * y;
        let x = radial.length();
        let (sin, cos) = (self.sin, self.cos);
        let s = -sin * x + cos * y;
        if s < 0.0 {
            return sphere_within(self.a, self.ra, p, -u, reach);
        }
        if s > self.l * cos {
            return sphere_within(self.b, self.rb, p, u, reach);
        }
        let distance = cos * x + sin * y - self.ra;
        (distance <= reach).then(|| {
            let e = if x > 0.0 {
                radial / x
            } else {
                u.any_orthonormal_vector()
            };
            let normal = e * cos + u * sin;
            Contact {
                distance,
                point: p - normal * distance,
                normal,
            }
        })
    }

    /// The cone's spheres: (centre a, r_a, centre b, r_b); a == b for a sphere.
    pub fn ends(&self) -> (DVec3, f64, DVec3, f64) {
        (self.a, self.ra, self.b, self.rb)
    }

    /// Distance from `p` to the axis segment a–b, less the larger radius: a lower bound on the
    /// signed distance to the surface (exact for a capsule outside it).
    pub fn axis_bound(&self, p: DVec3) -> f64 {
        let pa = p - self.a;
        let y = pa.dot(self.u).clamp(0.0, self.l);
        (pa - self.u * y).length() - self.ra.max(self.rb)
    }

    /// First point of the segment `from → to` on the surface, by sphere tracing the exact
    /// signed distance (Hart 1996: a step of the distance never crosses the surface):
    /// `(fraction, outward normal there)`, or `None` if the segment stays outside or starts
    /// inside. A path that grazes the surface for more than `steps` steps counts as a hit
    /// where the tracing stopped if its end lies inside.
    pub fn sweep(
        &self,
        from: DVec3,
        to: DVec3,
        tolerance: f64,
        steps: usize,
    ) -> Option<(f64, DVec3)> {
        let d = to - from;
        let len = d.length();
        let first = self.contact(from);
        if first.distance < 0.0 || len == 0.0 {
            return None;
        }
        let mut t = 0.0;
        let mut c = first;
        for _ in 0..steps {
            if c.distance <= tolerance {
                // On the surface already at the start: a hit only when moving inward.
                return (t > 0.0 || d.dot(c.normal) < 0.0).then_some((t, c.normal));
            }
            t += c.distance / len;
            if t >= 1.0 {
                return None;
            }
            c = self.contact(from + d * t);
        }
        if c.distance <= tolerance || self.contact(to).distance < 0.0 {
            Some((t, c.normal))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rand;

    /// On points around spheres, capsules and tapered cones (inside, near and far, on the axis
    /// and on the centres), `contact_within` is `contact` kept where its distance is within
    /// the reach, to the bit.
    #[test]
    fn contact_within_is_contact_filtered_by_reach() {
        let mut s = 0x0c0e_5eed_u64;
        let cones = [
            RoundCone::sphere(DVec3::new(0.1, 0.2, -0.3), 0.05),
            RoundCone::new(DVec3::ZERO, DVec3::new(0.0, 0.3, 0.0), 0.04, 0.04),
            RoundCone::new(
                DVec3::new(0.1, 0.0, 0.0),
                DVec3::new(0.2, 0.25, 0.1),
                0.06,
                0.03,
            ),
            RoundCone::new(DVec3::ZERO, DVec3::new(0.01, 0.0, 0.0), 0.05, 0.02),
        ];
        let (mut kept, mut dropped) = (0, 0);
        for cone in cones {
            let prepared = cone.prepare();
            let (a, ra, b, rb) = prepared.ends();
            let mut points: Vec<DVec3> = vec![a, b, (a + b) * 0.5];
            for _ in 0..4000 {
                let t = 0.5 + 0.8 * rand(&mut s);
                let off = DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s));
                points.push(a.lerp(b, t) + off * (ra.max(rb) * 2.5));
            }
            for p in points {
                for reach in [0.0, 0.004, 0.02] {
                    let full = prepared.contact(p);
                    let want = (full.distance <= reach).then_some(full);
                    let got = prepared.contact_within(p, reach);
                    assert_eq!(
                        got.map(|c| (c.distance.to_bits(), c.point, c.normal)),
                        want.map(|c| (c.distance.to_bits(), c.point, c.normal)),
                        "{cone:?} at {p}, reach {reach}"
                    );
                    if want.is_some() {
                        kept += 1;
                    } else {
                        dropped += 1;
                    }
                }
            }
        }
        assert!(
            kept > 1000 && dropped > 1000,
            "{kept} kept, {dropped} dropped"
        );
    }
}
