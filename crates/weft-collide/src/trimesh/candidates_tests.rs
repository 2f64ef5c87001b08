//! The candidate lists' arena: compaction keeps every particle's list and leaves the arena in
//! particle order with no stale entry.

use glam::{DQuat, DVec3};

use super::{ChunkLists, MeshFrame};
use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;

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
    let frame = MeshFrame {
        geometry: &g,
        pose: &pose,
        prev_pose: &pose,
        identity: true,
        still: true,
        fresh: true,
        friction: Friction::NONE,
    };
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
