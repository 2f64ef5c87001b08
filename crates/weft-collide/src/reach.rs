//! Which particles a collider can touch in one projection: a test of a few flops that rejects
//! a particle only where the push-out would leave it untouched, so that a pass over every
//! particle spends its time on the ones in contact.

use glam::DVec3;

use crate::analytic::Analytic;
use crate::collider::Collider;

/// An axis-aligned box in f64: (min corner, max corner).
pub(crate) type Bounds = (DVec3, DVec3);

/// Relative slack on a ball's reach, far above the rounding of |x − c| − R (~1e-16).
pub(crate) const BALL_SLACK: f64 = 1e-9;

/// A half-space or ball at the current pose, as its closed form computes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Surface {
    /// A half-space: outward unit normal `n` of the plane through `at` (world).
    Plane {
        /// Outward unit normal.
        n: DVec3,
        /// A point of the plane.
        at: DVec3,
    },
    /// A ball about `centre`; `pole` is the normal taken at the centre itself.
    Ball {
        /// Centre (world).
        centre: DVec3,
        /// Radius (m).
        radius: f64,
        /// The local y axis in world (the closed form's fallback normal).
        pole: DVec3,
    },
}

/// A collider's reach at the current pose: where a particle of thickness r may be within r
/// of the surface (or inside it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Reach {
    /// Inside the box (grown by the search margin), or anywhere for `None`.
    Box(Option<Bounds>),
    /// A half-space's plane: the signed distance n · (x − at) ≤ r, the one
    /// [`Analytic::closest`] computes, bit for bit. A ball: |x − centre| − radius ≤ r, tested
    /// squared with [`BALL_SLACK`].
    Surface(Surface),
}

impl Reach {
    /// The reach of `c` at its current pose; `bounds` is its grown world box (`None` if it is
    /// unbounded), the fallback for shapes without a cheaper test.
    pub fn of(c: &Collider, bounds: Option<Bounds>) -> Self {
        if c.mesh().is_some() {
            return Self::Box(bounds);
        }
        let (pose, _, _) = c.poses64();
        match c.analytic() {
            // As `Analytic::closest` computes them.
            Some(Analytic::HalfSpace { normal }) => Self::Surface(Surface::Plane {
                n: pose.basis * normal,
                at: pose.translation,
            }),
            Some(Analytic::Sphere { radius }) => Self::Surface(Surface::Ball {
                centre: pose.translation,
                radius,
                pole: pose.basis.y_axis,
            }),
            _ => Self::Box(bounds),
        }
    }

    /// False only if a particle of thickness `r` at `x` is farther than r outside the surface
    /// (so that a push-out to distance r would not move it).
    #[inline]
    pub fn may_touch(&self, x: DVec3, r: f64) -> bool {
        match *self {
            Self::Box(b) => b.is_none_or(|(lo, hi)| x.cmpge(lo).all() && x.cmple(hi).all()),
            Self::Surface(Surface::Plane { n, at }) => n.dot(x - at) <= r,
            Self::Surface(Surface::Ball { centre, radius, .. }) => {
                let reach = (radius + r) * (1.0 + BALL_SLACK);
                (x - centre).length_squared() <= reach * reach
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collider::ColliderDesc;
    use crate::shape::ShapeDesc;
    use crate::test_rand::rand;

    /// Whether the closed-form push-out would move a particle of thickness r at x.
    fn pushes(c: &Collider, x: DVec3, r: f64) -> bool {
        c.closest(x, r)
            .is_some_and(|s| r - s.distance > 1e-6 * r.max(1e-3))
    }

    #[test]
    fn a_rejected_particle_is_never_one_the_collider_would_push() {
        let tilted = glam::DQuat::from_rotation_z(0.3) * glam::DQuat::from_rotation_x(-0.7);
        let colliders = [
            ColliderDesc::new(ShapeDesc::HalfSpace {
                normal: DVec3::new(0.2, 1.0, -0.1).normalize(),
            })
            .at(DVec3::new(0.1, -0.4, 0.2)),
            ColliderDesc::new(ShapeDesc::Sphere { radius: 0.5 }).at(DVec3::new(0.3, 0.1, -0.2)),
            ColliderDesc::new(ShapeDesc::Capsule {
                half_height: 0.3,
                radius: 0.2,
            })
            .at(DVec3::new(-0.2, 0.0, 0.1))
            .rotated(tilted),
        ];
        let mut state = 7u64;
        for desc in &colliders {
            let c = Collider::new(desc).expect("valid collider");
            let bounds = c.world_aabb(0.0).map(|a| {
                let m = DVec3::splat(0.05);
                (a.mins.as_dvec3() - m, a.maxs.as_dvec3() + m)
            });
            let reach = Reach::of(&c, bounds);
            let (mut near, mut rejected) = (0, 0);
            for _ in 0..20_000 {
                let x = DVec3::new(
                    1.2 * rand(&mut state),
                    1.2 * rand(&mut state),
                    1.2 * rand(&mut state),
                );
                let r = 0.0105 + 0.0095 * rand(&mut state);
                // The random point, and one placed just about r off the surface (±1 µm).
                let s = c
                    .closest(x, f64::INFINITY)
                    .expect("closed-form shapes answer");
                let edge = s.point + s.normal * (r + 1e-6 * rand(&mut state));
                for x in [x, edge] {
                    let touches = reach.may_touch(x, r);
                    assert!(
                        touches || !pushes(&c, x, r),
                        "{desc:?}: {x} rejected but pushed"
                    );
                    near += usize::from(pushes(&c, x, r));
                    rejected += usize::from(!touches);
                }
            }
            // Both kinds occur, so the assertion above was exercised.
            assert!(
                near > 0 && rejected > 0,
                "{desc:?}: {near} pushed, {rejected} rejected"
            );
        }
    }

    #[test]
    fn the_plane_and_ball_tests_are_exact_at_their_boundary() {
        let plane = Collider::new(&ColliderDesc::new(ShapeDesc::HalfSpace {
            normal: DVec3::Y,
        }))
        .expect("valid");
        let reach = Reach::of(&plane, None);
        assert!(matches!(reach, Reach::Surface(Surface::Plane { .. })));
        let r = 0.01;
        assert!(reach.may_touch(DVec3::new(3.0, r, -2.0), r));
        assert!(!reach.may_touch(DVec3::new(3.0, r + 1e-12, -2.0), r));
        let ball =
            Collider::new(&ColliderDesc::new(ShapeDesc::Sphere { radius: 0.5 })).expect("valid");
        let reach = Reach::of(&ball, None);
        assert!(matches!(reach, Reach::Surface(Surface::Ball { .. })));
        assert!(reach.may_touch(DVec3::new(0.0, 0.51, 0.0), r));
        assert!(!reach.may_touch(DVec3::new(0.0, 0.5101, 0.0), r));
    }
}
