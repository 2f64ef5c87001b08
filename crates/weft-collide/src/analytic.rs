//! Closed-form contact queries for the primitive shapes (sphere, half-space, cuboid, capsule)
//! in f64 world space: closest surface point, signed distance and outward normal, and the
//! first crossing of a segment with the surface (for the continuous sweep).
//!
//! These replace parry's generic f32 queries for the shapes that have a closed form; the
//! conventions are those of the parry path (`collider::local_closest`): the distance is
//! negative inside, a point on or inside the surface gets the outward normal of its closest
//! surface point, and nothing is returned farther than `max_dist` outside.

use glam::{DMat3, DQuat, DVec3};

use crate::shape::ShapeDesc;
use crate::surface::SurfacePoint;

/// Below this length (m) a direction is taken as undefined and a fixed fallback is used.
pub(crate) const TINY: f64 = 1e-12;

/// A rigid pose in f64: x_world = R x_local + t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WorldPose {
    /// Translation t (m).
    pub translation: DVec3,
    /// Rotation R as a unit quaternion.
    pub rotation: DQuat,
    /// R as a matrix (its columns are the local axes in world space).
    pub basis: DMat3,
}

impl WorldPose {
    /// The pose that rotates by `rotation` (normalised here), then translates by `translation`.
    pub fn new(translation: DVec3, rotation: DQuat) -> Self {
        let rotation = rotation.normalize();
        Self {
            translation,
            rotation,
            basis: DMat3::from_quat(rotation),
        }
    }

    /// World point of local point `p`.
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.basis * p + self.translation
    }

    /// Local point of world point `x`: Rᵀ (x − t).
    pub fn inverse_transform_point(&self, x: DVec3) -> DVec3 {
        self.basis.transpose() * (x - self.translation)
    }
}

/// A shape with closed-form queries, its parameters in f64 (its own frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Analytic {
    /// Ball of `radius` about the origin.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// Everything below the plane through the origin with unit `normal`.
    HalfSpace {
        /// Outward unit normal (local).
        normal: DVec3,
    },
    /// Box about the origin.
    Cuboid {
        /// Half extents (m).
        half: DVec3,
    },
    /// Points within `radius` of the segment from (0, −h, 0) to (0, h, 0).
    Capsule {
        /// Half the core segment's length h (m).
        half_height: f64,
        /// Radius (m).
        radius: f64,
    },
}

impl Analytic {
    /// The closed form of `shape`, or `None` for shapes left to parry (hull, mesh, compound).
    /// Its parameters are those parry holds (f32), widened: the closed form, parry's bounds
    /// and the drawing describe one shape.
    pub fn of(shape: &ShapeDesc) -> Option<Self> {
        let held = |x: f64| f64::from(x as f32);
        match *shape {
            ShapeDesc::Sphere { radius } => Some(Self::Sphere {
                radius: held(radius),
            }),
            ShapeDesc::HalfSpace { normal } => Some(Self::HalfSpace {
                normal: normal.as_vec3().as_dvec3().normalize(),
            }),
            ShapeDesc::Cuboid { half_extents } => Some(Self::Cuboid {
                half: half_extents.as_vec3().as_dvec3(),
            }),
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => Some(Self::Capsule {
                half_height: held(half_height),
                radius: held(radius),
            }),
            _ => None,
        }
    }

    /// The closest surface point to world point `x` at `pose`, if `x` is inside or within
    /// `max_dist` of the surface.
    pub fn closest(&self, pose: &WorldPose, x: DVec3, max_dist: f64) -> Option<SurfacePoint> {
        // Each shape's distance comes first; the rest only where it passes `max_dist`.
        match *self {
            Self::Sphere { radius } => {
                ball_closest(pose.translation, radius, x, max_dist, pose.basis.y_axis)
            }
            Self::HalfSpace { normal } => {
                // Distance to a plane n·x = n·t (Ericson, Real-Time Collision Detection, §5.1.1).
                let n = pose.basis * normal;
                let distance = n.dot(x - pose.translation);
                (distance <= max_dist).then(|| SurfacePoint {
                    point: x - n * distance,
                    normal: n,
                    distance,
                })
            }
            Self::Cuboid { half } => {
                let (q, n, distance) = cuboid_closest(half, pose.inverse_transform_point(x));
                (distance <= max_dist).then(|| SurfacePoint {
                    point: pose.transform_point(q),
                    normal: pose.basis * n,
                    distance,
                })
            }
            Self::Capsule {
                half_height,
                radius,
            } => {
                // Closest point on the core segment (Ericson §5.1.2: clamp the projection onto
                // the segment's line), then the ball of `radius` about it.
                let axis = pose.basis.y_axis;
                let s = axis
                    .dot(x - pose.translation)
                    .clamp(-half_height, half_height);
                let core = pose.translation + axis * s;
                // On the core segment itself every radial direction is closest: take local x.
                ball_closest(core, radius, x, max_dist, pose.basis.x_axis)
            }
        }
    }

    /// First crossing of the segment `from → to` with the surface at `pose`, as
    /// `(fraction in [0, 1], outward normal at the crossing)`: the entry where `from` is
    /// outside, the exit where it is inside (as parry's non-solid ray cast).
    pub fn sweep(&self, pose: &WorldPose, from: DVec3, to: DVec3) -> Option<(f64, DVec3)> {
        let d = to - from;
        let (enter, leave) = match *self {
            Self::Sphere { radius } => {
                let (t0, t1) = ball_interval(pose.translation, radius, from, d)?;
                let at = |t: f64| (from + d * t - pose.translation).normalize_or(d);
                ((t0, at(t0)), (t1, at(t1)))
            }
            Self::HalfSpace { normal } => {
                // n·(from + t d − p0) ≤ 0 is one half-line of t (segment–plane, Ericson §5.3.1).
                let n = pose.basis * normal;
                let dist = n.dot(from - pose.translation);
                let rate = n.dot(d);
                if rate == 0.0 {
                    return None; // parallel: never crosses
                }
                let t = -dist / rate;
                if rate < 0.0 {
                    ((t, n), (f64::INFINITY, n))
                } else {
                    ((f64::NEG_INFINITY, n), (t, n))
                }
            }
            Self::Cuboid { half } => {
                let a = pose.inverse_transform_point(from);
                let ld = pose.basis.transpose() * d;
                let ((t0, n0), (t1, n1)) = slab_interval(half, a, ld)?;
                ((t0, pose.basis * n0), (t1, pose.basis * n1))
            }
            Self::Capsule {
                half_height,
                radius,
            } => {
                let (t0, t1) = capsule_interval(pose, half_height, radius, from, d)?;
                let at = |t: f64| {
                    let x = from + d * t;
                    let axis = pose.basis.y_axis;
                    let s = axis
                        .dot(x - pose.translation)
                        .clamp(-half_height, half_height);
                    (x - pose.translation - axis * s).normalize_or(d)
                };
                ((t0, at(t0)), (t1, at(t1)))
            }
        };
        // The segment is inside on [enter, leave]: it first meets the surface at the entry,
        // or, starting inside, at the exit.
        let (t, n) = if enter.0 >= 0.0 { enter } else { leave };
        (0.0..=1.0).contains(&t).then_some((t, n))
    }
}

/// The closest point on the surface of the ball of `radius` about `center` to `x`, if `x` is
/// inside or within `max_dist`: distance |x − c| − r along (x − c)/|x − c|, or along
/// `fallback` when `x` is at the centre.
fn ball_closest(
    center: DVec3,
    radius: f64,
    x: DVec3,
    max_dist: f64,
    fallback: DVec3,
) -> Option<SurfacePoint> {
    let v = x - center;
    let len = v.length();
    let distance = len - radius;
    if distance > max_dist {
        return None;
    }
    let normal = if len > TINY { v / len } else { fallback };
    Some(SurfacePoint {
        point: center + normal * radius,
        normal,
        distance,
    })
}

/// Closest boundary point of the box |p_i| ≤ h_i to local point `p`: (point, outward normal,
/// signed distance). Outside: the clamp of `p` to the box (Ericson §5.1.3). Inside or on the
/// surface: the nearest face, ties to the lowest axis.
fn cuboid_closest(half: DVec3, p: DVec3) -> (DVec3, DVec3, f64) {
    let excess = p.abs() - half;
    if excess.cmpgt(DVec3::ZERO).any() {
        let q = p.clamp(-half, half);
        let delta = p - q;
        let len = delta.length();
        return (q, delta / len, len);
    }
    let mut axis = 0;
    for k in 1..3 {
        if excess[k] > excess[axis] {
            axis = k;
        }
    }
    let side = if p[axis] >= 0.0 { 1.0 } else { -1.0 };
    let mut q = p;
    q[axis] = side * half[axis];
    let mut n = DVec3::ZERO;
    n[axis] = side;
    (q, n, excess[axis])
}

/// Parameters t where `from + t d` lies in the ball (|x − c| ≤ r), by the ray–sphere
/// quadratic (Ericson §5.3.2): t² (d·d) + 2t (m·d) + (m·m − r²) = 0 with m = from − c.
fn ball_interval(c: DVec3, r: f64, from: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let m = from - c;
    let a = d.dot(d);
    let b = m.dot(d);
    let cc = m.dot(m) - r * r;
    quadratic_interval(a, b, cc)
}

/// Roots of a t² + 2 b t + c ≤ 0 as an interval, for a ≥ 0; `None` if empty. With a = 0 the
/// inequality is c ≤ 0 for every t only if b = 0 (the callers' a = 0 means b = 0).
fn quadratic_interval(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a <= 0.0 {
        return (c <= 0.0).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    Some(((-b - root) / a, (-b + root) / a))
}

/// A crossing of a segment with a surface: (parameter t, outward normal there).
type Crossing = (f64, DVec3);

/// Parameters where `a + t d` lies in the box |p_i| ≤ h_i, with the outward normals of the
/// entry and exit faces, by intersecting the three slabs (Ericson §5.3.3).
fn slab_interval(half: DVec3, a: DVec3, d: DVec3) -> Option<(Crossing, Crossing)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut n0, mut n1) = (DVec3::ZERO, DVec3::ZERO);
    for k in 0..3 {
        if d[k] == 0.0 {
            if a[k].abs() > half[k] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[k];
        // Entering through the face that faces against d, leaving through the other.
        let (near, far) = if d[k] > 0.0 {
            ((-half[k] - a[k]) * inv, (half[k] - a[k]) * inv)
        } else {
            ((half[k] - a[k]) * inv, (-half[k] - a[k]) * inv)
        };
        if near > t0 {
            t0 = near;
            n0 = DVec3::ZERO;
            n0[k] = -d[k].signum();
        }
        if far < t1 {
            t1 = far;
            n1 = DVec3::ZERO;
            n1[k] = d[k].signum();
        }
        if t0 > t1 {
            return None;
        }
    }
    Some(((t0, n0), (t1, n1)))
}

/// Parameters where `from + t d` lies in the capsule. The capsule is convex and the union of
/// a finite cylinder and two balls, so the set is one interval: from the earliest entry into
/// a part to the latest exit from one.
fn capsule_interval(
    pose: &WorldPose,
    half_height: f64,
    radius: f64,
    from: DVec3,
    d: DVec3,
) -> Option<(f64, f64)> {
    let axis = pose.basis.y_axis;
    let m = from - pose.translation;
    let mut span: Option<(f64, f64)> = None;
    let mut add = |part: Option<(f64, f64)>| {
        if let Some((a, b)) = part {
            span = Some(span.map_or((a, b), |(s0, s1)| (s0.min(a), s1.max(b))));
        }
    };
    // Infinite cylinder |m⊥ + t d⊥| ≤ r (components across the axis) …
    let m_across = m - axis * axis.dot(m);
    let d_across = d - axis * axis.dot(d);
    let cylinder = quadratic_interval(
        d_across.dot(d_across),
        m_across.dot(d_across),
        m_across.dot(m_across) - radius * radius,
    )
    // … cut to the slab −h ≤ axis·(m + t d) ≤ h.
    .and_then(|(c0, c1)| {
        let (y, rate) = (axis.dot(m), axis.dot(d));
        let (s0, s1) = if rate == 0.0 {
            if y.abs() > half_height {
                return None;
            }
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            let (p, q) = ((-half_height - y) / rate, (half_height - y) / rate);
            (p.min(q), p.max(q))
        };
        let (t0, t1) = (c0.max(s0), c1.min(s1));
        (t0 <= t1).then_some((t0, t1))
    });
    add(cylinder);
    for end in [-half_height, half_height] {
        add(ball_interval(
            pose.translation + axis * end,
            radius,
            from,
            d,
        ));
    }
    span
}

#[cfg(test)]
mod tests {

    use crate::analytic_vs_parry::{Rng, shapes};
    use crate::collider::{Collider, ColliderDesc};

    use super::*;

    /// What lets the world push a particle out of a closed-form shape once, without a
    /// re-query: after a push along the normal to distance r, the particle is at distance r,
    /// and any move in the plane normal to that normal (friction's) keeps it at least there.
    #[test]
    fn one_push_along_the_normal_clears_the_shell() {
        let r = 0.05;
        let mut rng = Rng(1);
        for shape in shapes() {
            let kind = shape.kind();
            let c = Collider::new(
                &ColliderDesc::new(shape)
                    .at(DVec3::new(0.2, 0.1, -0.4))
                    .rotated(DQuat::from_axis_angle(
                        DVec3::new(1.0, 1.0, 0.0).normalize(),
                        0.7,
                    )),
            )
            .expect("valid");
            assert!(c.one_push_clears(), "{kind}");
            let mut pushed = 0;
            for _ in 0..3000 {
                let x = rng.cube(1.2) + DVec3::new(0.2, 0.1, -0.4);
                let Some(s) = c.closest(x, r) else {
                    continue;
                };
                let out = x + s.normal * (r - s.distance);
                let after = c.closest(out, 2.0 * r).expect("at r");
                assert!(
                    (after.distance - r).abs() < 1e-12,
                    "{kind}: {x} → {after:?}"
                );
                // A tangential move of up to 2r.
                let t = rng.cube(0.5);
                let t = (t - s.normal * s.normal.dot(t)) * (4.0 * r);
                let slid = c
                    .closest(out + t, 2.0 * r)
                    .map_or(f64::INFINITY, |s| s.distance);
                assert!(slid >= r - 1e-12, "{kind}: {x} slid to distance {slid}");
                pushed += 1;
            }
            assert!(pushed > 200, "{kind}: only {pushed} pushes");
        }
    }
}
