//! A tapered capsule ("round cone"): the convex hull of two spheres, with a closed-form f64
//! signed distance, closest point and normal.
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

/// Signed distance and contact for a sphere.
pub(crate) fn sphere_contact(center: DVec3, radius: f64, p: DVec3, fallback: DVec3) -> Contact {
    let d = p - center;
    let len = d.length();
    let normal = if len > 0.0 { d / len } else { fallback };
    Contact {
        distance: len - radius,
        point: center + normal * radius,
        normal,
    }
}

impl RoundCone {
    /// A round cone from its sphere centres and radii.
    pub fn new(a: DVec3, b: DVec3, ra: f64, rb: f64) -> Self {
        Self { a, b, ra, rb }
    }

    /// Signed distance, closest point and normal for the point `p`.
    pub fn contact(&self, p: DVec3) -> Contact {
        let ab = self.b - self.a;
        let l = ab.length();
        let dr = self.ra - self.rb;
        // One sphere inside the other (or coincident centres): the hull is the larger one.
        if l <= dr.abs() {
            let (c, r) = if self.ra >= self.rb {
                (self.a, self.ra)
            } else {
                (self.b, self.rb)
            };
            return sphere_contact(c, r, p, DVec3::Y);
        }
        let u = ab / l;
        let pa = p - self.a;
        let y = pa.dot(u);
        let radial = pa - u * y;
        let x = radial.length();
        let e = if x > 0.0 {
            radial / x
        } else {
            u.any_orthonormal_vector()
        };
        let sin = dr / l;
        let cos = (1.0 - sin * sin).sqrt();
        let s = -sin * x + cos * y;
        if s < 0.0 {
            return sphere_contact(self.a, self.ra, p, -u);
        }
        if s > l * cos {
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
