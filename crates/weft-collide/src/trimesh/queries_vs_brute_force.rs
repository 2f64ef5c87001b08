//! The BVH queries of a mesh (`within`, `nearest`) against brute force over every triangle, at
//! pseudo-random points near the surface, inside it and far away (where the f32 planes'
//! rounding margin must grow with the point's size), with radii that fall exactly on a
//! triangle's distance.

use glam::DVec3;

use super::MeshGeometry;
use super::closest::closest_on_triangle;
use super::vs_parry::bumpy_sphere;
use crate::analytic_vs_parry::Rng;
use crate::mesh::TriangleMesh;

/// A bumpy sphere, a convex icosphere (from far above a face, its interior is nearest), and
/// the bumpy sphere a third of the way through a frame in which its vertices move up to 5 cm
/// in and out (its planes are the frame end's: their bounds must allow for the travel to come).
fn meshes() -> Vec<MeshGeometry> {
    let [bumpy, ico] = [bumpy_sphere(), TriangleMesh::icosphere(0.5, 3)];
    let mut moving = MeshGeometry::new(&bumpy.vertices, &bumpy.triangles);
    let to: Vec<DVec3> = (moving.end.iter().enumerate())
        .map(|(k, v)| *v * (1.0 + 0.1 * (0.7 * k as f64).sin()))
        .collect();
    moving.begin_frame(&to);
    moving.advance_to(1.0 / 3.0);
    assert!(
        moving.moving && moving.slack > 0.02,
        "a frame with travel to come"
    );
    vec![
        MeshGeometry::new(&bumpy.vertices, &bumpy.triangles),
        MeshGeometry::new(&ico.vertices, &ico.triangles),
        moving,
    ]
}

/// Squared distance from `x` to every triangle, in storage order.
fn distances_squared(g: &MeshGeometry, x: DVec3) -> Vec<f64> {
    (0..g.face_count())
        .map(|t| {
            let [a, b, c] = g.corners(t);
            (x - closest_on_triangle(x, a, b, c).point).length_squared()
        })
        .collect()
}

/// Query points: near the surface, anywhere in and around the mesh, and 10 m to 1 km away,
/// half of those straight above a face (where a face's plane is the whole distance).
fn points(g: &MeshGeometry, rng: &mut Rng, count: usize) -> Vec<DVec3> {
    (0..count)
        .map(|k| {
            let f = g.face((rng.next() * g.face_count() as f64) as usize % g.face_count());
            let above = |h: f64| f.corners.iter().sum::<DVec3>() / 3.0 + f.normal * h;
            match k % 6 {
                0 => rng.cube(0.8),
                1 => rng.cube(1.0).normalize_or(DVec3::X) * (0.45 + 0.1 * rng.next()),
                2 => rng.cube(1.0).normalize_or(DVec3::X) * 10.0,
                3 => rng.cube(1.0).normalize_or(DVec3::X) * 1000.0,
                4 => above(10.0 * (1.0 + rng.next())),
                _ => above(1000.0 * (1.0 + rng.next())),
            }
        })
        .collect()
}

/// The least radius whose square is no less than `d2`: a triangle at squared distance `d2`
/// is just within it.
fn radius_at(d2: f64) -> f64 {
    let mut r = d2.sqrt();
    while r * r < d2 {
        r = f64::from_bits(r.to_bits() + 1);
    }
    r
}

#[test]
fn within_lists_exactly_the_triangles_within_the_radius() {
    let mut rng = Rng(7);
    let mut listed = 0;
    for g in meshes() {
        for x in points(&g, &mut rng, 1200) {
            let d2 = distances_squared(&g, x);
            let mut sorted = d2.clone();
            sorted.sort_by(f64::total_cmp);
            // A radius exactly at the k-th nearest triangle's distance, one between two, and
            // one short of the nearest.
            let k = if rng.next() < 0.5 {
                0
            } else {
                (rng.next() * 20.0) as usize
            };
            for radius in [
                radius_at(sorted[k]),
                0.5 * (sorted[k].sqrt() + sorted[k + 1].sqrt()),
                0.5 * sorted[0].sqrt(),
            ] {
                let r2 = radius * radius;
                let expect: Vec<u32> = (0..d2.len() as u32)
                    .filter(|&t| d2[t as usize] <= r2)
                    .collect();
                // Beyond: the nearest anywhere, or known to lie within a bound (exact, loose,
                // or left short by rounding: a second search).
                let nearest = sorted[0].sqrt();
                let bounds = [
                    f64::INFINITY,
                    nearest,
                    2.0 * nearest,
                    nearest * (1.0 - 1e-9),
                ];
                for beyond in std::iter::once(None).chain(bounds.map(Some)) {
                    let mut out = Vec::new();
                    let near = g.within(x, radius, beyond, &mut out);
                    out.sort_unstable();
                    assert_eq!(out, expect, "{x} within {radius}");
                    listed += out.len();
                    // The nearest listed triangle or, beyond, the nearest of all.
                    match near {
                        Some(p) => assert_eq!(p.distance.abs(), sorted[0].sqrt(), "{x}"),
                        None => assert!(expect.is_empty() && beyond.is_none(), "{x}"),
                    }
                }
            }
        }
    }
    assert!(listed > 5000, "{listed} listed");
}

#[test]
fn nearest_is_the_nearest_of_all_triangles() {
    let mut rng = Rng(8);
    for g in meshes() {
        for x in points(&g, &mut rng, 1200) {
            let best = distances_squared(&g, x)
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            let p = g.nearest(x, f64::INFINITY).expect("a nearest triangle");
            assert_eq!(p.distance.abs(), best.sqrt(), "{x}");
            // Within a limit: found if and only if the nearest is within it.
            assert!(g.nearest(x, best.sqrt() * 0.999).is_none(), "{x}");
            assert!(g.nearest(x, best.sqrt() * 1.001).is_some(), "{x}");
        }
    }
}
