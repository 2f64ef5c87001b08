//! The candidate lists' arena: compaction keeps every particle's list and leaves the arena in
//! particle order with no stale entry. A particle's contact rounds: they stop early only where
//! no triangle is within the thickness.

use glam::{DQuat, DVec3};

use super::{ChunkLists, MeshFrame, ROUNDS};
use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;
use crate::trimesh::closest::closest_on_triangle;
use crate::trimesh::vs_parry::bumpy_sphere;

/// Each particle's list, as a sorted copy.
fn lists_of(lists: &ChunkLists) -> Vec<Vec<u32>> {
    lists
        .range
        .iter()
        .map(|&(s, len)| {
            let mut l = lists.tris[s as usize..(s + len) as usize].to_vec();
            l.sort_unstable();
            l
        })
        .collect()
}

#[test]
fn compaction_keeps_the_lists_in_particle_order() {
    let m = TriangleMesh::icosphere(0.5, 3);
    let g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let frame = MeshFrame::still(&g, &pose, Friction::NONE);
    let mut rng = Rng(3);
    let n = 200;
    let mut x: Vec<DVec3> = (0..n)
        .map(|_| rng.cube(1.0).normalize_or(DVec3::Y) * (0.5 + 0.03 * rng.next()))
        .collect();
    let mut lists = ChunkLists::new(n);
    let r = 0.01;
    let mut stale = 0;
    for _ in 0..6 {
        // Every particle drifts 6 mm: most lists are rebuilt, appended to the arena.
        for (j, xj) in x.iter_mut().enumerate() {
            let prev = *xj;
            *xj += rng.cube(0.006);
            frame.resolve(&mut lists, j, prev, xj, r);
        }
        let before = lists_of(&lists);
        stale += lists.tris.len() - lists.live;
        lists.compact();
        assert_eq!(lists_of(&lists), before);
        assert_eq!(lists.tris.len(), lists.live);
        let mut next = 0;
        for &(s, len) in &lists.range {
            assert_eq!(s, next, "lists out of particle order");
            next += len;
        }
    }
    assert!(stale > 200, "{stale} stale entries");
    assert!(lists.live > 300, "{} listed, {stale} stale", lists.live);
}

/// The distance from `x` to the nearest triangle, by brute force.
fn distance(g: &MeshGeometry, x: DVec3) -> f64 {
    g.faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.corners;
            (x - closest_on_triangle(x, a, b, c).point).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Particles resting on, sliding over and pressed into a bumpy (non-convex) closed mesh, with
/// friction, over several substeps: whenever their rounds stop before the last, no triangle is
/// nearer than the thickness (less the rounds' tolerance), by brute force.
#[test]
fn rounds_stop_early_only_clear_of_every_triangle() {
    let m = bumpy_sphere();
    let g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let frame = MeshFrame::still(&g, &pose, Friction::new(0.8, 0.6));
    let mut rng = Rng(12);
    let r = 0.02;
    let n = 400;
    // Start on the surface: the nearest point of a random direction's ray, pushed out r.
    let mut x: Vec<DVec3> = (0..n)
        .map(|_| {
            let dir = rng.cube(1.0).normalize_or(DVec3::Y);
            let p = g.nearest(dir, f64::INFINITY).expect("nearest");
            p.closest.point + p.normal * r * (0.5 + rng.next())
        })
        .collect();
    let mut lists = ChunkLists::new(n);
    let (mut early, mut pushed) = (0, 0);
    for _ in 0..8 {
        for (j, xj) in x.iter_mut().enumerate() {
            let prev = *xj;
            // A small step: down towards the centre (gravity-like) and sideways.
            *xj += -*xj * 0.02 + rng.cube(0.004);
            let out = frame.resolve(&mut lists, j, prev, xj, r);
            pushed += usize::from(out.contacts > 0);
            if out.contacts < ROUNDS {
                early += 1;
                let d = distance(&g, *xj);
                assert!(
                    d >= r * (1.0 - 2e-6),
                    "particle {j}: {d} < {r} after {out:?}"
                );
            }
        }
    }
    assert!(
        pushed > 1000 && early > 2000,
        "{pushed} pushed, {early} stopped early"
    );
}
