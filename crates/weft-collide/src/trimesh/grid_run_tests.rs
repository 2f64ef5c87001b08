//! A run of particles through the block path against the same particles one at a time.

use glam::{DQuat, DVec3};
use weft_solver::{Contacts, SimdPath};

use super::resolve_grid_run;
use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;
use crate::trimesh::ccd::segment_crossing;
use crate::trimesh::contact_grid::ContactGrid;
use crate::trimesh::frame::MeshFrame;
use crate::trimesh::grid_contacts::GridParticles;
use crate::trimesh::test_particles::{about, assert_same_bits, axes, over_runs, under};
use crate::trimesh::vs_parry::{bumpy_sheet, bumpy_sphere};

/// Steps particles about `m` (at the origin, or `placed` elsewhere and turned) for several
/// substeps (two passes each: the substep's first and
/// one more), moving them towards the mesh's centre and sideways in between, once through
/// `resolve_grid_run` on kernel path `path` (in runs of uneven length) and once particle by
/// particle through `resolve_in_grid`; the positions, the totals and every particle's state
/// must agree to the bit.
fn run_matches_particles(m: &TriangleMesh, seed: u64, path: SimdPath, placed: bool) {
    let g = MeshGeometry::new(&m.vertices, &m.triangles);
    // At the origin, or moved and turned (still over the substep either way).
    let pose = if placed {
        let turn = DQuat::from_rotation_z(0.4) * DQuat::from_rotation_x(-0.9);
        WorldPose::new(DVec3::new(0.3, -1.2, 0.7), turn)
    } else {
        WorldPose::new(DVec3::ZERO, DQuat::IDENTITY)
    };
    let r = 0.02;
    let grid = ContactGrid::new(&g, r).expect("small grid");
    let friction = Friction::new(0.8, 0.6);
    let mut rng = Rng(seed);
    let n = 1003;
    let (one, many) = (GridParticles::new(n), GridParticles::new(n));
    let start: Vec<DVec3> = about(&g, &mut rng, n, r)
        .into_iter()
        .map(|p| pose.transform_point(p))
        .collect();
    let w: Vec<f64> = (0..n)
        .map(|i| if i % 11 == 0 { 0.0 } else { 1.0 })
        .collect();
    let thickness = vec![r; n];
    let (mut a, mut b) = (start.clone(), axes(&start));
    let (mut contacts, mut settled_any) = (0, false);
    for step in 0..10 {
        let prev = a.clone();
        let prev_axes = axes(&prev);
        for (j, p) in a.iter_mut().enumerate() {
            if w[j] != 0.0 {
                *p += (pose.translation - *p) * 0.02 + rng.cube(0.004);
                for k in 0..3 {
                    b[k][j] = p[k];
                }
            }
        }
        for fresh in [true, false] {
            let mut frame = MeshFrame::still(&g, &pose, friction);
            frame.fresh = fresh;
            frame.identity = !placed;
            assert!(frame.settles());
            let mut expected = Contacts::default();
            for j in 0..n {
                if w[j] != 0.0 {
                    let o = frame.resolve_in_grid((&grid, &one), j, prev[j], &mut a[j], r);
                    expected = expected.merge(o.into());
                }
            }
            // Runs of 0..100, 100..613 and 613..1003: full blocks and remainders.
            let runs = [(0, 100), (100, 613), (613, n)];
            let total = over_runs(&mut b, (&prev_axes, &w), &runs, path, |k, mut run| {
                let (s, e) = runs[k];
                resolve_grid_run(&frame, (&grid, &many), &thickness[s..e], &mut run)
            });
            let what = format!("{path:?}, step {step}, fresh {fresh}");
            assert_same_bits(&a, &b, (total, expected), &what);
            assert!(
                one.snapshot() == many.snapshot(),
                "{path:?}, step {step}: state"
            );
            contacts += total.contacts;
            settled_any |= total.contacts > 0;
        }
    }
    assert!(
        settled_any && contacts > 1000,
        "{path:?}: {contacts} contacts"
    );
}

#[test]
fn a_run_moves_each_particle_as_the_one_particle_path_does_bit_for_bit() {
    for path in [
        SimdPath::Avx512,
        SimdPath::Avx2,
        SimdPath::Neon,
        SimdPath::Scalar,
    ] {
        for placed in [false, true] {
            run_matches_particles(&bumpy_sphere(), 31, path, placed);
            run_matches_particles(&TriangleMesh::icosphere(0.5, 4), 32, path, placed);
            run_matches_particles(&bumpy_sheet(), 33, path, placed);
        }
    }
}

/// Particles 1.5 r under an open cap, left there for a substep (so that each keeps the
/// triangle it came nearest to), then moved 3r along the normal, through the cap, in one
/// substep: a path r/2 or longer must be left to the sweep, not settled by the first test in
/// front of the face, so each stays on the side it came from, on the block path of every
/// kernel path and on the one-particle path.
#[test]
fn a_long_path_through_an_open_cap_is_swept_not_settled_in_front() {
    // An open cap of a sphere: convex, so its faces' clearances reach past r and the first
    // test would settle a particle in front of one.
    let ball = TriangleMesh::icosphere(0.5, 3);
    let cap: Vec<[u32; 3]> = ball
        .triangles
        .iter()
        .copied()
        .filter(|t| t.iter().all(|&i| ball.vertices[i as usize].y > 0.0))
        .collect();
    let m = TriangleMesh::new(ball.vertices.clone(), cap).expect("valid cap");
    let g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let r = 0.01;
    let grid = ContactGrid::new(&g, r).expect("small grid");
    let mut rng = Rng(34);
    let n = 203;
    let on = under(&g, &mut rng, n, (0.3, 1.0));
    let behind: Vec<DVec3> = on.iter().map(|&(p, nrm)| p - nrm * 1.5 * r).collect();
    // 3r along the normal from `x`: through the cap.
    let through = |x: &[DVec3]| -> Vec<DVec3> {
        x.iter()
            .zip(&on)
            .map(|(x, &(_, nrm))| *x + nrm * 3.0 * r)
            .collect()
    };
    let w = vec![1.0; n];
    let thickness = vec![r; n];
    // No particle's path over the second substep crosses the cap (brute force over every
    // triangle).
    let kept = |from: &[DVec3], to: &[DVec3], what: &str| {
        for (j, (from, to)) in from.iter().zip(to).enumerate() {
            let crossed = m.triangles.iter().any(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                let normal = (b - a).cross(c - a).normalize();
                segment_crossing(*from, *to, [a, b, c], normal, false).is_some()
            });
            assert!(
                !crossed,
                "{what}, particle {j}: crossed from {from} to {to}"
            );
        }
    };
    let frame = MeshFrame::still(&g, &pose, Friction::new(0.8, 0.6));
    // One particle at a time: a substep at rest, then one through the cap.
    let state = GridParticles::new(n);
    let step = |from: &[DVec3], to: Vec<DVec3>| -> Vec<DVec3> {
        let mut x = to;
        for j in 0..n {
            frame.resolve_in_grid((&grid, &state), j, from[j], &mut x[j], r);
        }
        x
    };
    let rest = step(&behind, behind.clone());
    let end = step(&rest, through(&rest));
    kept(&rest, &end, "one particle");
    // A block at a time, on every kernel path.
    for path in SimdPath::ALL {
        let state = GridParticles::new(n);
        let step = |from: &[DVec3], to: Vec<DVec3>| -> Vec<DVec3> {
            let mut x = axes(&to);
            over_runs(&mut x, (&axes(from), &w), &[(0, n)], path, |_, mut run| {
                resolve_grid_run(&frame, (&grid, &state), &thickness, &mut run)
            });
            (0..n)
                .map(|j| DVec3::new(x[0][j], x[1][j], x[2][j]))
                .collect()
        };
        let rest = step(&behind, behind.clone());
        let end = step(&rest, through(&rest));
        kept(&rest, &end, &format!("{path:?}"));
    }
}
