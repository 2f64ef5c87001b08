//! The closed-form f64 queries (`analytic.rs`) against parry's f32 answers, shape by shape,
//! at many deterministic pseudo-random points and segments, with rotated, translated and
//! moving poses.

use glam::{DQuat, DVec3};
use weft_solver::Motion;

use crate::collider::{Collider, ColliderDesc};
use crate::shape::ShapeDesc;

/// Agreement expected of positions and distances (m): parry rounds to f32 (~2e-7 m here).
const TOL: f64 = 1e-5;

/// splitmix64: a small deterministic generator.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−s, s]³.
    pub(crate) fn cube(&mut self, s: f64) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next()) * (2.0 * s) - DVec3::splat(s)
    }
}

/// One of each closed-form shape, in general position.
pub(crate) fn shapes() -> Vec<ShapeDesc> {
    vec![
        ShapeDesc::Sphere { radius: 0.7 },
        ShapeDesc::HalfSpace {
            normal: DVec3::new(0.3, 1.0, -0.2),
        },
        ShapeDesc::Cuboid {
            half_extents: DVec3::new(0.5, 0.3, 0.8),
        },
        ShapeDesc::Capsule {
            half_height: 0.6,
            radius: 0.4,
        },
    ]
}

/// Each shape at rest at the origin, rotated and translated, and carried by a rotation
/// about a pivot (at t = 0.37 s).
fn colliders() -> Vec<Collider> {
    let mut out = Vec::new();
    for shape in shapes() {
        let plain = ColliderDesc::new(shape.clone());
        let placed = ColliderDesc::new(shape)
            .at(DVec3::new(0.4, -0.3, 1.1))
            .rotated(DQuat::from_axis_angle(
                DVec3::new(1.0, 2.0, 0.5).normalize(),
                0.9,
            ));
        let moving = placed.clone().moving(Motion::Rotate {
            pivot: DVec3::new(0.2, 0.1, -0.3),
            axis: DVec3::new(-0.4, 0.3, 1.0),
            angular_velocity: 1.7,
        });
        for desc in [plain, placed, moving] {
            let mut c = Collider::new(&desc).expect("valid collider");
            c.set_time(0.36, 0.37);
            out.push(c);
        }
    }
    out
}

/// Whether the closest boundary point of `x` is ambiguous for `c` (two faces of a box almost
/// equally near, or the centre of a ball / the core of a capsule), so that f32 and f64 may
/// pick different, equally close points.
fn ambiguous(c: &Collider, x: DVec3) -> bool {
    let local = c.pose().inverse_transform_point(x.as_vec3()).as_dvec3();
    match c.kind() {
        "cuboid" => {
            let h = DVec3::new(0.5, 0.3, 0.8);
            let mut e = (local.abs() - h).to_array();
            e.sort_by(f64::total_cmp);
            e[2] <= 0.0 && e[2] - e[1] < 1e-3
        }
        "sphere" => local.length() < 1e-3,
        "capsule" => DVec3::new(local.x, 0.0, local.z).length() < 1e-3,
        _ => false,
    }
}

#[test]
fn closest_points_agree_with_parry() {
    let mut rng = Rng(7);
    let max_dist = 0.5;
    for c in colliders() {
        let (mut inside, mut outside) = (0, 0);
        let centre = c.pose().translation.as_dvec3();
        for _ in 0..4000 {
            let x = centre + rng.cube(1.2);
            let a = c.closest(x, max_dist);
            let p = c.parry_closest(x, max_dist);
            let (a, p) = match (a, p) {
                (Some(a), Some(p)) => (a, p),
                (None, None) => continue,
                (a, p) => {
                    // Only right at the max_dist cut-off may they disagree.
                    let d = a.or(p).map_or(f64::NAN, |s| s.distance);
                    assert!((d - max_dist).abs() < TOL, "{}: {x} {a:?} {p:?}", c.kind());
                    continue;
                }
            };
            let what = format!("{} at {x}: analytic {a:?}, parry {p:?}", c.kind());
            assert!((a.distance - p.distance).abs() < TOL, "{what}");
            if ambiguous(&c, x) {
                continue;
            }
            assert!((a.point - p.point).length() < TOL, "{what}");
            if a.distance.abs() > 1e-3 {
                // parry's normal is the f32 offset normalised: good to ~1e-7 / |d|.
                assert!((a.normal - p.normal).length() < 1e-4, "{what}");
            }
            assert!((a.normal.length() - 1.0).abs() < 1e-12, "{what}");
            if a.distance < 0.0 {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        // Enough of each for the comparison to mean something.
        assert!(
            inside > 100 && outside > 100,
            "{}: {inside} in, {outside} out",
            c.kind()
        );
    }
}

#[test]
fn sweeps_agree_with_parry() {
    let mut rng = Rng(11);
    for c in colliders() {
        let mut hits = 0;
        let centre = c.pose().translation.as_dvec3();
        for _ in 0..2000 {
            let from = centre + rng.cube(1.5);
            let to = centre + rng.cube(1.5);
            // The world sweeps only paths that start outside.
            if c.parry_closest(from, 10.0)
                .is_none_or(|s| s.distance < 1e-4)
            {
                continue;
            }
            let len = (to - from).length();
            let a = c.sweep(from, to);
            let p = c.parry_sweep(from, to);
            let what = format!("{} {from} → {to}: analytic {a:?}, parry {p:?}", c.kind());
            let grazing = |n: DVec3| n.dot((to - from) / len).abs() < 1e-3;
            let (a, p) = match (a, p) {
                (Some(a), Some(p)) => (a, p),
                (None, None) => continue,
                (a, p) => {
                    // Only a graze or a hit right at the end of the path may be missed.
                    let (t, n) = a.or(p).expect("one hit");
                    assert!(grazing(n) || (1.0 - t) * len < TOL, "{what}");
                    continue;
                }
            };
            if grazing(a.1) {
                continue;
            }
            assert!((a.0 - p.0).abs() * len < TOL, "{what}");
            assert!(
                a.1.dot(to - from) <= 0.0,
                "{what}: normal must face the start"
            );
            let hit = from + (to - from) * a.0;
            if !(c.kind() == "cuboid" && near_box_edge(&c, hit)) {
                assert!((a.1 - p.1).length() < 1e-3, "{what}");
            }
            hits += 1;
        }
        assert!(hits > 100, "{}: only {hits} hits", c.kind());
    }
}

/// Whether `x` is within 0.1 mm of two faces of the test cuboid (where the hit face of a
/// sweep is a toss-up).
fn near_box_edge(c: &Collider, x: DVec3) -> bool {
    let local = c.pose().inverse_transform_point(x.as_vec3()).as_dvec3();
    let h = DVec3::new(0.5, 0.3, 0.8);
    (local.abs() - h)
        .to_array()
        .iter()
        .filter(|e| e.abs() < 1e-4)
        .count()
        >= 2
}

/// A point on the surface of a primitive gets distance 0 and the outward normal; at the
/// centre of a ball and on the core of a capsule, a fixed unit normal.
#[test]
fn surface_and_degenerate_points() {
    let sphere =
        Collider::new(&ColliderDesc::new(ShapeDesc::Sphere { radius: 1.0 })).expect("sphere");
    let on = sphere.closest(DVec3::new(0.6, 0.8, 0.0), 0.1).expect("on");
    assert_eq!(on.distance, 0.0);
    assert!((on.normal - DVec3::new(0.6, 0.8, 0.0)).length() < 1e-15);
    let centre = sphere.closest(DVec3::ZERO, 0.1).expect("centre");
    assert_eq!((centre.distance, centre.normal), (-1.0, DVec3::Y));
    let cuboid = Collider::new(&ColliderDesc::new(ShapeDesc::Cuboid {
        half_extents: DVec3::new(1.0, 2.0, 3.0),
    }))
    .expect("cuboid");
    let face = cuboid
        .closest(DVec3::new(0.3, -2.0, 0.5), 0.1)
        .expect("face");
    assert_eq!((face.distance, face.normal), (0.0, DVec3::NEG_Y));
    let capsule = Collider::new(&ColliderDesc::new(ShapeDesc::Capsule {
        half_height: 1.0,
        radius: 0.5,
    }))
    .expect("capsule");
    let core = capsule
        .closest(DVec3::new(0.0, 0.4, 0.0), 0.1)
        .expect("core");
    assert_eq!(core.distance, -0.5);
    assert_eq!(core.normal, DVec3::X);
    assert!(capsule.closest(DVec3::new(0.0, 2.0, 0.0), 0.4).is_none());
}
