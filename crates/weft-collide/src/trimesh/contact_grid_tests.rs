//! The contact grid against brute force: a cell lists every triangle within reach of its
//! points, cells the surface misses are wholly inside or outside, clearances are lower bounds,
//! and contacts through the grid are the contacts through per-particle lists.

use glam::{DQuat, DVec3};

use super::{ContactGrid, Side};
use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;
use crate::trimesh::chunk_lists::ChunkLists;
use crate::trimesh::closest::closest_on_triangle;
use crate::trimesh::frame::{MeshFrame, ROUNDS, RunParticle};
use crate::trimesh::grid_contacts::GridParticles;
use crate::trimesh::vs_parry::{bumpy_sheet, bumpy_sphere};

fn geometry(m: &TriangleMesh) -> MeshGeometry {
    MeshGeometry::new(&m.vertices, &m.triangles)
}

/// Distance from `x` to triangle `t`.
fn distance(g: &MeshGeometry, t: usize, x: DVec3) -> f64 {
    let [a, b, c] = g.corners(t);
    (x - closest_on_triangle(x, a, b, c).point).length()
}

/// Points near and around a mesh within 0.8 m of the origin.
fn points(g: &MeshGeometry, rng: &mut Rng, count: usize, near: f64) -> Vec<DVec3> {
    (0..count)
        .map(|k| {
            if k % 2 == 0 {
                rng.cube(0.8)
            } else {
                let f = g.face((rng.next() * g.face_count() as f64) as usize % g.face_count());
                let centre = f.corners.iter().sum::<DVec3>() / 3.0;
                centre + f.normal * near * (2.0 * rng.next() - 1.0) + rng.cube(near)
            }
        })
        .collect()
}

#[test]
fn a_cell_lists_every_triangle_within_reach_of_its_points() {
    let mut rng = Rng(21);
    for (m, reach) in [
        (bumpy_sphere(), 0.02),
        (bumpy_sheet(), 0.01),
        (bumpy_sphere(), 0.07),
    ] {
        let g = geometry(&m);
        let grid = ContactGrid::new(&g, reach).expect("small grid");
        let mut within = 0;
        for x in points(&g, &mut rng, 4000, 2.0 * reach) {
            let list = grid.cell(x).map_or(&[][..], |c| grid.list(c));
            for t in 0..g.face_count() {
                if distance(&g, t, x) <= reach {
                    within += 1;
                    assert!(list.contains(&(t as u32)), "{x}: triangle {t} not listed");
                }
            }
        }
        assert!(within > 500, "only {within} triangles within reach");
    }
}

#[test]
fn cells_the_surface_misses_are_wholly_inside_or_outside() {
    let mut rng = Rng(22);
    let g = geometry(&bumpy_sphere());
    let grid = ContactGrid::new(&g, 0.02).expect("small grid");
    let (mut inside, mut outside) = (0, 0);
    for x in points(&g, &mut rng, 20000, 0.1) {
        let side = grid.side(grid.cell(x));
        if side == Side::Surface {
            continue;
        }
        let signed = g.nearest(x, f64::INFINITY).expect("nearest").distance;
        assert_eq!(
            side == Side::Inside,
            signed < 0.0,
            "{x}: {side:?}, {signed}"
        );
        if signed < 0.0 {
            inside += 1;
        } else {
            outside += 1;
        }
    }
    assert!(
        inside > 500 && outside > 5000,
        "{inside} inside, {outside} outside"
    );
    // An open sheet has no inside.
    let sheet = geometry(&bumpy_sheet());
    let grid = ContactGrid::new(&sheet, 0.01).expect("small grid");
    for x in points(&sheet, &mut rng, 2000, 0.1) {
        assert_ne!(grid.side(grid.cell(x)), Side::Inside);
    }
}

#[test]
fn clearance_is_a_lower_bound_on_the_distance_to_triangles_in_front() {
    let g = geometry(&bumpy_sphere());
    let reach = 0.02;
    let grid = ContactGrid::new(&g, reach).expect("small grid");
    let (mut clear, mut blocked) = (0, 0);
    for t in (0..g.face_count()).step_by(7) {
        let f = g.face(t);
        let [a, b, c] = f.corners;
        // Points on the triangle: the least distance from them to a triangle is at least the
        // triangles' distance, hence at least the clearance.
        let samples: Vec<DVec3> = (0..=8)
            .flat_map(|i| (0..=8 - i).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                a * (1.0 - u - v) + b * u + c * v
            })
            .collect();
        let bound = grid.clearance(t);
        for u in 0..g.face_count() {
            if g.face(u)
                .corners
                .iter()
                .any(|v| f.normal.dot(*v - a) > 1e-9)
            {
                let least = samples
                    .iter()
                    .map(|&p| distance(&g, u, p))
                    .fold(f64::INFINITY, f64::min);
                assert!(least >= bound, "triangle {t}: {u} at {least} < {bound}");
            }
        }
        if bound >= 2.0 * reach {
            clear += 1;
        } else {
            blocked += 1;
        }
    }
    // The bumps put most triangles' neighbours in front of their planes.
    assert!(
        clear > 0 && blocked > 50,
        "{clear} clear, {blocked} blocked"
    );
    // A convex mesh: every triangle is clear well beyond the contact reach.
    let ball = geometry(&TriangleMesh::icosphere(0.5, 3));
    let grid = ContactGrid::new(&ball, reach).expect("small grid");
    assert!((0..ball.face_count()).all(|t| grid.clearance(t) >= 4.0 * reach));
}

/// Particles started around and on a mesh, stepping towards its centre and sideways for
/// several substeps with friction: each ends every substep where the per-particle lists put it
/// (to rounding). Particles started deep inside a closed mesh may differ (after a push out
/// from deep inside the lists' search ends, the grid looks again where the particle landed),
/// so they are held to what both must do: clear of every triangle whenever the rounds stop
/// early (brute force).
fn grid_matches_lists(m: &TriangleMesh, seed: u64) {
    let g = geometry(m);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let r = 0.02;
    let grid = ContactGrid::new(&g, r).expect("small grid");
    let frame = MeshFrame::still(&g, &pose, Friction::new(0.8, 0.6));
    let state = GridParticles::new(600);
    let mut rng = Rng(seed);
    let n = 600;
    let start: Vec<DVec3> = (0..n)
        .map(|k| {
            let dir = rng.cube(1.0).normalize_or(DVec3::Y);
            let p = g.nearest(dir, f64::INFINITY).expect("nearest");
            // Outside near the surface, on it, and (one in six) deep inside.
            let h = if k % 6 == 0 { -3.0 } else { 2.0 * rng.next() };
            p.closest.point + p.normal * r * h
        })
        .collect();
    let (mut a, mut b) = (start.clone(), start);
    let mut lists = ChunkLists::new(n);
    let (mut pushed, mut swept) = (0, 0);
    for step in 0..12 {
        for j in 0..n {
            let drift = -a[j] * 0.02
                + rng.cube(0.004)
                + if step == 5 {
                    rng.cube(0.03)
                } else {
                    DVec3::ZERO
                };
            let (pa, pb) = (a[j], b[j]);
            a[j] += drift;
            b[j] += drift;
            let oa = frame.resolve(RunParticle::new(&mut lists, j, pa, &mut a[j], r));
            let ob = frame.resolve_in_grid((&grid, &state), j, pb, &mut b[j], r);
            if ob.contacts < ROUNDS {
                let d = (0..g.face_count())
                    .map(|t| distance(&g, t, b[j]))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d >= r * (1.0 - 2e-6),
                    "particle {j}: {d} < {r} after {ob:?}"
                );
            }
            if j % 6 == 0 {
                continue;
            }
            assert!(
                (a[j] - b[j]).length() <= 1e-9,
                "step {step}, particle {j}: lists {} {oa:?}, grid {} {ob:?}",
                a[j],
                b[j]
            );
            assert_eq!(oa.swept, ob.swept, "step {step}, particle {j}");
            pushed += usize::from(ob.contacts > 0);
            swept += ob.swept;
        }
    }
    assert!(
        pushed > 1000 && swept > 10,
        "{pushed} pushed, {swept} swept"
    );
}

#[test]
fn contacts_through_the_grid_are_those_through_the_lists_on_a_closed_mesh() {
    grid_matches_lists(&bumpy_sphere(), 23);
    grid_matches_lists(&TriangleMesh::icosphere(0.5, 4), 24);
}

#[test]
fn contacts_through_the_grid_are_those_through_the_lists_on_an_open_sheet() {
    grid_matches_lists(&bumpy_sheet(), 25);
}

#[test]
fn the_gap_is_the_chebyshev_distance_to_the_nearest_listing_cell() {
    let g = geometry(&bumpy_sphere());
    let grid = ContactGrid::new(&g, 0.02).expect("small grid");
    let [nx, ny, nz] = grid.dims;
    let listing: Vec<[usize; 3]> = (0..nz)
        .flat_map(|k| (0..ny).flat_map(move |j| (0..nx).map(move |i| [i, j, k])))
        .filter(|&[i, j, k]| {
            let c = (k * ny + j) * nx + i;
            grid.starts[c + 1] > grid.starts[c]
        })
        .collect();
    assert!(!listing.is_empty());
    let mut rng = Rng(26);
    let mut far = 0;
    for _ in 0..400 {
        let cell = [nx, ny, nz].map(|d| (rng.next() * d as f64) as usize % d);
        let chebyshev = listing
            .iter()
            .map(|l| (0..3).map(|a| l[a].abs_diff(cell[a])).max().unwrap_or(0))
            .min()
            .unwrap_or(usize::MAX);
        let c = (cell[2] * ny + cell[1]) * nx + cell[0];
        assert_eq!(
            usize::from(grid.gap[c]),
            chebyshev.min(255),
            "cell {cell:?}"
        );
        far += usize::from(chebyshev >= 2);
    }
    assert!(far > 50, "only {far} cells two or more from the surface");
}

#[test]
fn a_clear_ball_holds_no_point_within_reach_of_the_mesh() {
    let mut rng = Rng(27);
    for (m, reach) in [(bumpy_sphere(), 0.02), (bumpy_sheet(), 0.01)] {
        let g = geometry(&m);
        let grid = ContactGrid::new(&g, reach).expect("small grid");
        let (mut near, mut far, mut beyond) = (0, 0, 0);
        for k in 0..6000 {
            // Around the mesh, and (one in four) beyond the grid.
            let x = if k % 4 == 0 {
                rng.cube(3.0)
            } else {
                points(&g, &mut rng, 1, 0.15)[0]
            };
            let cell = grid.cell(x);
            if grid.side(cell) != Side::Outside || cell.is_some_and(|c| !grid.list(c).is_empty()) {
                continue;
            }
            let bound = grid.clear_distance(cell, x);
            let least = (0..g.face_count())
                .map(|t| distance(&g, t, x))
                .fold(f64::INFINITY, f64::min);
            assert!(least >= bound, "{x}: nearest triangle {least} < {bound}");
            assert!(
                bound > reach * (1.0 - 1e-6) || cell.is_none(),
                "{x}: {bound}"
            );
            match cell {
                None => beyond += 1,
                Some(c) if grid.gap[c] >= 2 => far += 1,
                Some(_) => near += 1,
            }
        }
        assert!(
            near > 100 && far > 100 && beyond > 100,
            "{near} next to the surface, {far} farther, {beyond} beyond the grid"
        );
    }
}
