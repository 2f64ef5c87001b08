//! A run of particles through the lane test against the same particles one at a time, and the
//! lane test against `MeshFrame::resolve` alone, on deforming and still meshes.

use glam::{DQuat, DVec3};
use weft_solver::{Contacts, SimdPath};

use super::resolve_list_run;
use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;
use crate::trimesh::candidates::{ChunkLists, MeshFrame};
use crate::trimesh::test_particles::{about, assert_same_bits, axes, over_runs};
use crate::trimesh::vs_parry::{bumpy_sheet, bumpy_sphere};

thread_local! {
    /// Lanes the lane test settled itself (clear, or pushed out of their face) on this thread.
    pub(super) static SETTLED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    /// Lanes whose other listed triangles the flat test cleared (`below`) on this thread.
    pub(super) static FLAT: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Thickness of every particle (m).
const R: f64 = 0.02;

/// Substeps per frame of the deforming meshes.
const SUBSTEPS: usize = 4;

/// The mesh's vertices at time `t`: still, or breathing (each vertex scaled about the origin
/// by 1 + 3 % sin(2π(t + 2y)), a few mm a substep).
fn shape(rest: &[DVec3], t: f64, deforming: bool) -> Vec<DVec3> {
    rest.iter()
        .map(|v| {
            if deforming {
                *v * (1.0 + 0.03 * (std::f64::consts::TAU * (t + 2.0 * v.y)).sin())
            } else {
                *v
            }
        })
        .collect()
}

/// Frames of particles about `m` (deforming or still), a few substeps each with two passes
/// (the substep's first and one more), the particles moved towards the mesh's centre and
/// sideways before each substep. `check(frame, prev, x)` runs each pass on the particles at
/// `x` (moved in place; `prev` at the substep's start) and checks what it must; returns the
/// contacts made.
fn passes(
    m: &TriangleMesh,
    seed: u64,
    deforming: bool,
    n: usize,
    mut check: impl FnMut(&MeshFrame<'_>, &[DVec3], &mut Vec<DVec3>) -> usize,
) -> usize {
    let mut g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let friction = Friction::new(0.8, 0.6);
    let mut rng = Rng(seed);
    let mut a = about(&g, &mut rng, n, R);
    let mut contacts = 0;
    for frame_no in 0..3 {
        g.begin_frame(&shape(&m.vertices, 0.05 * (frame_no + 1) as f64, deforming));
        for sub in 1..=SUBSTEPS {
            g.advance_to(sub as f64 / SUBSTEPS as f64);
            let prev = a.clone();
            for (j, p) in a.iter_mut().enumerate() {
                if j % 11 != 0 {
                    *p += -*p * 0.004 + rng.cube(0.001);
                }
            }
            for fresh in [true, false] {
                let mut frame = MeshFrame::still(&g, &pose, friction);
                frame.fresh = fresh;
                assert!(frame.lists_settle());
                contacts += check(&frame, &prev, &mut a);
            }
        }
    }
    contacts
}

/// Runs of particles through `resolve_list_run` on kernel path `path` (runs of uneven length,
/// each with its own lists) and the same particles one by one through `resolve_listed`: the
/// positions and the totals agree to the bit.
fn run_matches_particles(m: &TriangleMesh, seed: u64, path: SimdPath, deforming: bool) {
    let n = 1003;
    let w: Vec<f64> = (0..n)
        .map(|i| if i % 11 == 0 { 0.0 } else { 1.0 })
        .collect();
    let thickness = vec![R; n];
    // Runs of 0..100, 100..613 and 613..1003: full blocks and remainders.
    let runs = [(0, 100), (100, 613), (613, n)];
    let mut one = ChunkLists::new(n);
    let mut many: Vec<ChunkLists> = runs.iter().map(|(s, e)| ChunkLists::new(e - s)).collect();
    let contacts = passes(m, seed, deforming, n, |frame, prev, a| {
        let mut b = axes(a);
        let prev_axes = axes(prev);
        let mut expected = Contacts::default();
        for j in 0..n {
            if w[j] != 0.0 {
                let o = frame.resolve_listed(&mut one, j, prev[j], &mut a[j], R);
                expected = expected.merge(o.into());
            }
        }
        let total = over_runs(&mut b, (&prev_axes, &w), &runs, path, |k, mut run| {
            let (s, e) = runs[k];
            resolve_list_run(frame, &mut many[k], &thickness[s..e], &mut run)
        });
        assert_same_bits(a, &b, (total, expected), &format!("{path:?}"));
        total.contacts
    });
    assert!(contacts > 1000, "{path:?}: {contacts} contacts");
}

#[test]
fn a_run_moves_each_particle_as_the_one_particle_path_does_bit_for_bit() {
    for path in [
        SimdPath::Avx512,
        SimdPath::Avx2,
        SimdPath::Neon,
        SimdPath::Scalar,
    ] {
        run_matches_particles(&bumpy_sphere(), 41, path, true);
        run_matches_particles(&TriangleMesh::icosphere(0.5, 4), 42, path, true);
        run_matches_particles(&bumpy_sheet(), 43, path, false);
        run_matches_particles(&bumpy_sheet(), 44, path, true);
    }
}

/// From the same positions in every pass, `resolve_listed` (the lane test first) and
/// `resolve` alone leave each particle within 10⁻¹² m of each other (rounding apart: the lane
/// test pushes along the face's plane, `resolve` through the closest point), and the lane test
/// settles a good share of the particles itself. Returns how many lanes the flat test cleared
/// and how many the lane test settled.
fn lane_test_agrees(m: &TriangleMesh, seed: u64, deforming: bool) -> (usize, usize) {
    let n = 1003;
    let (mut with_test, mut alone) = (ChunkLists::new(n), ChunkLists::new(n));
    let mut worst = 0.0f64;
    let mut tested = 0;
    SETTLED.with(|c| c.set(0));
    FLAT.with(|c| c.set(0));
    passes(m, seed, deforming, n, |frame, prev, a| {
        let mut b = a.clone();
        let mut contacts = 0;
        for j in (0..n).filter(|j| j % 11 != 0) {
            contacts += frame
                .resolve_listed(&mut with_test, j, prev[j], &mut a[j], R)
                .contacts;
            frame.resolve(&mut alone, j, prev[j], &mut b[j], R);
            worst = worst.max((a[j] - b[j]).length());
            tested += 1;
        }
        contacts
    });
    let settled = SETTLED.with(|c| c.get());
    assert!(worst <= 1e-12, "{worst:e} m apart");
    assert!(
        settled * 4 > tested,
        "the lane test settled {settled} of {tested} particle-passes"
    );
    (FLAT.with(|c| c.get()), settled)
}

#[test]
fn the_lane_test_moves_particles_as_resolve_does() {
    lane_test_agrees(&bumpy_sphere(), 51, true);
    lane_test_agrees(&bumpy_sheet(), 53, false);
    // On a convex mesh every neighbour of a touched face lies below its plane: the flat test
    // clears most of what the lane test settles.
    let (flat, settled) = lane_test_agrees(&TriangleMesh::icosphere(0.5, 4), 52, true);
    assert!(flat * 2 > settled, "flat {flat} of {settled} settled");
}
