//! The f64 mesh queries against brute force (every triangle's closest point; the winding
//! number for inside) and against parry's f32 projection, at pseudo-random points, many of
//! them near edges and vertices, on a closed bumpy sphere and an open bumpy sheet.

use glam::{DVec3, Quat, Vec3};

use super::MeshGeometry;
use super::closest::{Feature, closest_on_triangle};
use crate::analytic_vs_parry::Rng;
use crate::collider::{Collider, ColliderDesc};
use crate::mesh::TriangleMesh;
use crate::shape::ShapeDesc;

/// A closed, non-convex mesh: an icosphere with pseudo-random bumps.
pub(super) fn bumpy_sphere() -> TriangleMesh {
    let mut m = TriangleMesh::icosphere(0.5, 3);
    let mut rng = Rng(11);
    for v in &mut m.vertices {
        *v = (v.as_vec3() * (1.0 + 0.25 * rng.next() as f32)).as_dvec3();
    }
    m
}

/// An open mesh: a bumpy height field of 12 × 12 cells.
pub(super) fn bumpy_sheet() -> TriangleMesh {
    let n = 12u32;
    let mut rng = Rng(5);
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
            vertices.push(Vec3::new(x, 0.1 * rng.next() as f32, z).as_dvec3());
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            triangles.push([v, v + n + 1, v + 1]);
            triangles.push([v + 1, v + n + 1, v + n + 2]);
        }
    }
    TriangleMesh::new(vertices, triangles).expect("valid sheet")
}

/// Generalised winding number of a closed mesh at `x` (van Oosterom & Strackee 1983, the
/// solid angle of each triangle): 1 inside, 0 outside.
fn winding(m: &TriangleMesh, x: DVec3) -> f64 {
    let mut sum = 0.0;
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.vertices[i as usize] - x);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// Random query points: a third uniform in the box, the rest near vertices and edge middles.
fn points(m: &TriangleMesh, rng: &mut Rng, count: usize) -> Vec<DVec3> {
    (0..count)
        .map(|k| {
            let t =
                m.triangles[(rng.next() * m.triangles.len() as f64) as usize % m.triangles.len()];
            let [a, b, _] = t.map(|i| m.vertices[i as usize]);
            match k % 3 {
                0 => rng.cube(0.8),
                1 => a + rng.cube(0.05),
                _ => 0.5 * (a + b) + rng.cube(0.05),
            }
        })
        .collect()
}

#[test]
fn icosphere_is_closed_and_wound_outwards() {
    let m = TriangleMesh::icosphere(1.0, 2);
    assert_eq!(m.triangles.len(), 320);
    let g = MeshGeometry::new(&m.vertices, &m.triangles);
    assert!(g.closed());
    // Outward winding: positive volume (divergence theorem), near (4/3)π.
    let volume: f64 = (0..g.face_count())
        .map(|t| g.corners(t))
        .map(|[a, b, c]| a.dot(b.cross(c)) / 6.0)
        .sum();
    // The inscribed polyhedron's volume is a little below the ball's (4/3)π.
    assert!(
        volume > 4.0 && volume < 4.0 / 3.0 * std::f64::consts::PI,
        "{volume}"
    );
    assert!(!MeshGeometry::new(&bumpy_sheet().vertices, &bumpy_sheet().triangles).closed());
}

/// Closest point, distance and inside/outside against brute force and the winding number,
/// and against parry's projection, with the collider placed and rotated.
#[test]
fn closest_points_and_signs_match_brute_force_and_parry() {
    let mut rng = Rng(21);
    for (name, m) in [
        ("bumpy sphere", bumpy_sphere()),
        ("bumpy sheet", bumpy_sheet()),
    ] {
        let closed = name == "bumpy sphere";
        let place = Vec3::new(0.3, -0.2, 0.9);
        let turn = Quat::from_axis_angle(Vec3::new(0.2, 1.0, -0.4).normalize(), 1.1);
        let c = Collider::new(
            &ColliderDesc::new(ShapeDesc::TriMesh(m.clone()))
                .at(place.as_dvec3())
                .rotated(turn.as_dquat()),
        )
        .expect("mesh collider");
        let pose = crate::analytic::WorldPose::new(place.as_dvec3(), turn.as_dquat());
        let mut features = [0usize; 3];
        let (mut inside, mut parry_checked) = (0, 0);
        for local in points(&m, &mut rng, 1500) {
            let x = pose.transform_point(local);
            let ours = c.closest(x, 10.0).expect("within 10 m");
            // Brute force over every triangle, in the mesh's frame.
            let mut best = (f64::INFINITY, DVec3::ZERO, Feature::Face);
            for t in &m.triangles {
                let [a, b, cc] = t.map(|i| m.vertices[i as usize]);
                let q = closest_on_triangle(local, a, b, cc);
                let d = (local - q.point).length();
                if d < best.0 {
                    best = (d, q.point, q.feature);
                }
            }
            match best.2 {
                Feature::Face => features[0] += 1,
                Feature::Edge(_) => features[1] += 1,
                Feature::Vertex(_) => features[2] += 1,
            }
            assert!(
                (ours.distance.abs() - best.0).abs() < 1e-9,
                "{name} {x}: {ours:?} vs {best:?}"
            );
            assert!(
                (pose.inverse_transform_point(ours.point) - best.1).length() < 1e-6
                    || (ours.distance.abs() - best.0).abs() < 1e-12,
                "{name}: closest point {ours:?} vs {best:?}"
            );
            // The normal joins the surface point and x (away from the inside).
            if best.0 > 1e-6 {
                let along = (x - ours.point) / best.0;
                let expect = if ours.distance < 0.0 { -along } else { along };
                assert!(
                    (ours.normal - expect).length() < 1e-6,
                    "{name}: normal {ours:?}"
                );
            }
            if closed {
                let w = winding(&m, local);
                assert!((w - w.round()).abs() < 1e-6, "winding {w}");
                if best.0 > 1e-9 {
                    assert_eq!(
                        ours.distance < 0.0,
                        w.round() == 1.0,
                        "{name} {x}: {ours:?}, winding {w}"
                    );
                }
                inside += usize::from(ours.distance < 0.0);
            } else {
                assert!(ours.distance >= 0.0 || best.0 > 0.0, "{name}");
            }
            // parry (f32): same distance; same side where the point is clearly off the surface.
            if let Some(p) = c.parry_closest(x, 10.0) {
                assert!(
                    (p.distance.abs() - best.0).abs() < 2e-5,
                    "{name} {x}: parry {p:?} vs {best:?}"
                );
                if closed && best.0 > 1e-4 {
                    assert_eq!(
                        p.distance < 0.0,
                        ours.distance < 0.0,
                        "{name} {x}: parry {p:?} vs {ours:?}"
                    );
                }
                parry_checked += 1;
            }
        }
        assert!(
            features.iter().all(|&k| k > 50),
            "{name}: regions {features:?}"
        );
        assert!(
            parry_checked > 1000,
            "{name}: parry answered {parry_checked}"
        );
        if closed {
            assert!(inside > 100, "{name}: {inside} inside");
        }
    }
}

/// Segment crossings of the mesh against brute force over every triangle.
#[test]
fn sweep_finds_the_first_crossing() {
    let m = bumpy_sphere();
    let c = Collider::new(&ColliderDesc::new(ShapeDesc::TriMesh(m.clone()))).expect("mesh");
    let mut rng = Rng(4);
    let mut hits = 0;
    for _ in 0..500 {
        let (from, to) = (rng.cube(0.9), rng.cube(0.9));
        let mut best: Option<f64> = None;
        for t in &m.triangles {
            let [a, b, cc] = t.map(|i| m.vertices[i as usize]);
            let n = (b - a).cross(cc - a).normalize();
            if let Some(h) = super::ccd::segment_crossing(from, to, [a, b, cc], n, true) {
                best = Some(best.map_or(h.t, |b: f64| b.min(h.t)));
            }
        }
        let ours = c.sweep(from, to).map(|h| h.0);
        assert_eq!(ours.is_some(), best.is_some(), "{from} → {to}");
        if let (Some(a), Some(b)) = (ours, best) {
            assert!((a - b).abs() < 1e-12);
            hits += 1;
        }
    }
    assert!(hits > 50, "{hits} hits");
}
