//! The candidate lists' arena: compaction keeps every particle's list and leaves the arena in
//! particle order with no stale entry. A particle's contact rounds: they stop early only where
//! no triangle is within the thickness.

use crate::trimesh::frame::RunParticle;
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
            frame.resolve(RunParticle::new(&mut lists, j, prev, xj, r));
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
    (0..g.face_count())
        .map(|t| {
            let [a, b, c] = g.corners(t);
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
            let out = frame.resolve(RunParticle::new(&mut lists, j, prev, xj, r));
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

/// Makes particle `j`'s list valid at `x` on a path from `from` (`MeshFrame::ensure`); where
/// it stood without a rebuild, checks by brute force that it holds every triangle within `r`
/// of `x` (at the substep's end) and of `from` (at its start), and returns those triangles
/// and whether the bound on the mesh's travel alone held it; `None` after a rebuild.
fn standing_list(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    j: usize,
    (x, from): (DVec3, DVec3),
    r: f64,
) -> Option<(Vec<usize>, bool)> {
    let g = frame.geometry;
    let built = lists.builds;
    let by_travel = frame.valid_by_travel(lists, j, x, from, r);
    frame.ensure(lists, j, x, from, r);
    if lists.builds > built {
        return None;
    }
    let (s, len) = lists.range[j];
    let list = &lists.tris[s as usize..(s + len) as usize];
    let mut in_reach = Vec::new();
    for t in 0..g.face_count() {
        let [a, b, c] = g.corners(t);
        let d_end = (x - closest_on_triangle(x, a, b, c).point).length();
        let [a, b, c] = g.start_corners(t);
        let d_start = (from - closest_on_triangle(from, a, b, c).point).length();
        if d_end <= r || d_start <= r {
            assert!(
                list.contains(&(t as u32)),
                "particle {j}: triangle {t} at {d_end} (end) / {d_start} (start) not listed"
            );
            in_reach.push(t);
        }
    }
    Some((in_reach, by_travel))
}

/// Particles riding on a ball that moves fast (4 cm a frame, far more than the lists' skin
/// every substep) and ripples, over 12 frames of 10 substeps: wherever a list stands without
/// a rebuild, it holds every triangle within the thickness of the particle and of its path's
/// start (brute force, at the substep's end and start); and riding certificates (`riding`)
/// carry most of the lists through.
#[test]
fn riding_lists_hold_every_triangle_in_reach() {
    let m = TriangleMesh::icosphere(0.5, 3);
    let mut g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let rest = m.vertices.clone();
    let shape = |frame: usize| -> Vec<DVec3> {
        let t = frame as f64 / 60.0;
        let shift = DVec3::new(2.4 * t, 0.6 * (7.0 * t).sin(), 0.0);
        (rest.iter())
            .map(|v| *v * (1.0 + 0.03 * (9.0 * t + 6.0 * v.y).sin()) + shift)
            .collect()
    };
    let mut rng = Rng(21);
    let r = 0.01;
    let n = 300;
    // On the surface, 0.2 r to 3 r off it.
    let mut x: Vec<DVec3> = (0..n)
        .map(|_| {
            let dir = rng.cube(1.0).normalize_or(DVec3::Y);
            let p = g.nearest(dir, f64::INFINITY).expect("nearest");
            p.closest.point + p.normal * r * (0.2 + 2.8 * rng.next())
        })
        .collect();
    let mut lists = ChunkLists::new(n);
    let substeps = 10;
    let (mut checked, mut riding, mut builds) = (0, 0, 0);
    for frame in 1..=12 {
        let before = g.end.clone();
        g.begin_frame(&shape(frame));
        let motion: Vec<DVec3> = (g.frame.1.iter().zip(&before))
            .map(|(b, a)| *b - *a)
            .collect();
        for k in 1..=substeps {
            let w = k as f64 / substeps as f64;
            g.advance_to(w);
            let frame_of = MeshFrame::still(&g, &pose, Friction::NONE);
            for (j, xj) in x.iter_mut().enumerate() {
                let from = *xj;
                // Carried by the nearest vertex's motion (most), with a jitter of up to 2 mm.
                let near_v = (0..rest.len())
                    .min_by(|&a, &b| {
                        (g.start[a] - from)
                            .length_squared()
                            .total_cmp(&(g.start[b] - from).length_squared())
                    })
                    .unwrap_or(0);
                *xj += motion[near_v] / substeps as f64 + rng.cube(0.002);
                let Some((in_reach, by_travel)) =
                    standing_list(&frame_of, &mut lists, j, (*xj, from), r)
                else {
                    builds += 1;
                    continue;
                };
                riding += usize::from(!by_travel);
                checked += in_reach.len();
            }
            // Particles that drift off are put back near the surface.
            for xj in x.iter_mut() {
                let p = g.nearest(*xj, f64::INFINITY).expect("nearest");
                if p.distance.abs() > 4.0 * r {
                    *xj = p.closest.point + p.normal * 2.0 * r;
                }
            }
        }
    }
    assert!(checked > 10_000, "{checked} triangles in reach checked");
    assert!(
        riding > 10_000,
        "{riding} lists stood on their riding certificate"
    );
    assert!(builds < (12 * 10 * n / 3) as u64, "{builds} builds");
}

/// Three square sheets of one mesh: a floor sliding 4 cm a frame with the particles riding
/// above it, a ceiling 10 cm above sliding with it and closing in at 6 cm a frame (from
/// beyond a list's reach to through the particles within one frame), and a still wall ahead
/// that the particles reach: wherever a list stands without a rebuild, it holds every
/// triangle within the thickness of the particle and its path's start, the ceiling's and the
/// wall's included.
#[test]
fn riding_lists_see_a_part_closing_in() {
    let (n_side, size) = (16, 0.4);
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for sheet in 0..3 {
        let base = vertices.len() as u32;
        for i in 0..=n_side {
            for k in 0..=n_side {
                let (u, v) = (i as f64 / n_side as f64, k as f64 / n_side as f64);
                vertices.push(match sheet {
                    0 => DVec3::new(size * (u - 0.5), 0.0, size * (v - 0.5)),
                    1 => DVec3::new(size * (u - 0.5), 0.1, size * (v - 0.5)),
                    _ => DVec3::new(0.3, 0.25 * (u - 0.5), size * (v - 0.5)),
                });
            }
        }
        let at = |i: u32, k: u32| base + i * (n_side as u32 + 1) + k;
        for i in 0..n_side as u32 {
            for k in 0..n_side as u32 {
                triangles.push([at(i, k), at(i + 1, k), at(i + 1, k + 1)]);
                triangles.push([at(i, k), at(i + 1, k + 1), at(i, k + 1)]);
            }
        }
    }
    let per_sheet = vertices.len() / 3;
    let mut g = MeshGeometry::new(&vertices, &triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let shape = |frame: usize| -> Vec<DVec3> {
        let slide = DVec3::X * 0.04 * frame as f64;
        let close = DVec3::Y * -0.06 * frame as f64;
        (vertices.iter().enumerate())
            .map(|(v, p)| match v / per_sheet {
                0 => *p + slide,
                1 => *p + slide + close,
                _ => *p,
            })
            .collect()
    };
    let mut rng = Rng(5);
    let r = 0.01;
    let n = 200;
    let mut x: Vec<DVec3> = (0..n)
        .map(|_| {
            let c = rng.cube(0.12);
            DVec3::new(c.x, 0.004 + 0.016 * rng.next(), c.z)
        })
        .collect();
    let mut lists = ChunkLists::new(n);
    let substeps = 10;
    let (mut near_ceiling, mut near_wall, mut riding) = (0, 0, 0);
    for frame in 1..=6 {
        g.begin_frame(&shape(frame));
        for k in 1..=substeps {
            g.advance_to(k as f64 / substeps as f64);
            let frame_of = MeshFrame::still(&g, &pose, Friction::NONE);
            for (j, xj) in x.iter_mut().enumerate() {
                let from = *xj;
                *xj += DVec3::X * 0.004 + rng.cube(0.0005);
                let Some((in_reach, by_travel)) =
                    standing_list(&frame_of, &mut lists, j, (*xj, from), r)
                else {
                    continue;
                };
                riding += usize::from(!by_travel);
                for t in in_reach {
                    let sheet = g.triangles[t][0] as usize / per_sheet;
                    near_ceiling += usize::from(sheet == 1);
                    near_wall += usize::from(sheet == 2);
                }
            }
        }
    }
    assert!(
        near_ceiling > 500,
        "{near_ceiling} times the ceiling in reach"
    );
    assert!(near_wall > 100, "{near_wall} times the wall in reach");
    assert!(
        riding > 1000,
        "{riding} lists stood on their riding certificate"
    );
}

/// A list built with a riding certificate on a substep's first projection and built again as
/// a plain list on a later one (no motion to ride with) loses the certificate, so that it
/// cannot vouch for the new list; and a plain build in a chunk that made no certificate
/// records none for it (its checks then read none).
#[test]
fn a_plain_rebuild_drops_the_riding_certificate() {
    let vertices = [
        DVec3::new(-0.5, 0.0, -0.5),
        DVec3::new(0.5, 0.0, -0.5),
        DVec3::new(0.5, 0.0, 0.5),
        DVec3::new(-0.5, 0.0, 0.5),
    ];
    let triangles = [[0, 2, 1], [0, 3, 2]];
    let mut g = MeshGeometry::new(&vertices, &triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    // The floor slides 4 cm a frame: a plain list's skin would not last it.
    g.begin_frame(&vertices.map(|v| v + DVec3::X * 0.04));
    g.advance_to(0.1);
    let r = 0.01;
    let mut lists = ChunkLists::new(2);
    let (from, x) = (DVec3::new(0.0, 0.012, 0.0), DVec3::new(0.004, 0.012, 0.0));
    let first = MeshFrame::still(&g, &pose, Friction::NONE);
    first.ensure(&mut lists, 0, x, from, r);
    assert_eq!(lists.riding[0].frame, g.frame_id, "a riding list first");
    assert_eq!(lists.riding_frame, g.frame_id);
    let later = MeshFrame {
        fresh: false,
        ..MeshFrame::still(&g, &pose, Friction::NONE)
    };
    let moved = x + DVec3::X * 0.05;
    later.ensure(&mut lists, 0, moved, moved, r);
    assert_eq!(lists.builds, 2);
    assert_eq!(
        lists.riding[0],
        super::Riding::NONE,
        "the certificate stayed"
    );
    // Back where the certificate held: the plain list does not, so it is built again.
    later.ensure(&mut lists, 0, x, x, r);
    assert_eq!(lists.builds, 3);
    // A plain build in another chunk, which made no certificate: none recorded.
    let mut other = ChunkLists::new(1);
    later.ensure(&mut other, 0, x, x, r);
    assert_eq!((other.riding_frame, other.riding[0].frame), (0, 0));
}
