//! A run of particles through the certified test against the same particles one at a time,
//! and that test against `MeshFrame::resolve` alone, on deforming and still meshes.

use glam::{DQuat, DVec3};
use weft_solver::{Contacts, SimdPath};

use super::resolve_list_run;
use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;
use crate::trimesh::chunk_lists::ChunkLists;
use crate::trimesh::frame::{MeshFrame, RunParticle};
use crate::trimesh::test_particles::{about, assert_same_bits, axes, over_runs};
use crate::trimesh::vs_parry::{bumpy_sheet, bumpy_sphere};
use crate::trimesh::{certified, edge_contact};

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
///
///
/// Without `certify`, the mesh certifies no particle (as a fast limb's mesh would not), and
/// `resolve` takes every particle.
fn passes(
    m: &TriangleMesh,
    case: (u64, bool, bool),
    n: usize,
    check: impl FnMut(&MeshFrame<'_>, &[DVec3], &mut Vec<DVec3>) -> usize,
) -> usize {
    passes_from(m, case, (n, None), check)
}

/// [`passes`] of particles about the mesh, or (`resting`: their drift per substep) of
/// particles resting on it, in front of its surface at 0.6–1.3 r, drifting towards its centre
/// and sideways by that much.
fn passes_from(
    m: &TriangleMesh,
    (seed, deforming, certify): (u64, bool, bool),
    (n, resting): (usize, Option<f64>),
    mut check: impl FnMut(&MeshFrame<'_>, &[DVec3], &mut Vec<DVec3>) -> usize,
) -> usize {
    let mut g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let friction = Friction::new(0.8, 0.6);
    let mut rng = Rng(seed);
    // Each particle's drift towards the mesh: towards its centre, or against the normal
    // where a resting particle was put.
    let (mut a, towards): (Vec<DVec3>, Vec<DVec3>) = match resting {
        None => {
            let a = about(&g, &mut rng, n, R);
            let towards = a.iter().map(|p| *p * 0.004).collect();
            (a, towards)
        }
        // Over random points of the faces facing up, along their normals.
        Some(drift) => (0..n)
            .map(|_| {
                loop {
                    let f = g.face((rng.next() * g.face_count() as f64) as usize % g.face_count());
                    let (u, v) = (rng.next(), rng.next());
                    let (u, v) = if u + v > 1.0 {
                        (1.0 - u, 1.0 - v)
                    } else {
                        (u, v)
                    };
                    let [a, b, c] = f.corners;
                    if f.normal.y > 0.3 {
                        let p = a + (b - a) * u + (c - a) * v;
                        break (
                            p + f.normal * R * (0.6 + 0.7 * rng.next()),
                            f.normal * drift,
                        );
                    }
                }
            })
            .unzip(),
    };
    let wander = resting.unwrap_or(0.001);
    let frames = if resting.is_some() { 6 } else { 3 };
    let mut contacts = 0;
    for frame_no in 0..frames {
        g.begin_frame(&shape(&m.vertices, 0.05 * (frame_no + 1) as f64, deforming));
        if !certify {
            g.frame_reach = f64::INFINITY;
        }
        for sub in 1..=SUBSTEPS {
            g.advance_to(sub as f64 / SUBSTEPS as f64);
            let prev = a.clone();
            for (j, p) in a.iter_mut().enumerate() {
                if j % 11 != 0 {
                    *p += -towards[j] + rng.cube(wander);
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
/// positions and the totals agree to the bit, with certificates and without.
fn run_matches_particles(m: &TriangleMesh, seed: u64, path: SimdPath, deforming: bool) {
    for certify in [true, false] {
        run_matches(m, (seed, deforming, certify), path);
    }
}

/// [`run_matches_particles`] with or without certificates (`case.2`).
fn run_matches(m: &TriangleMesh, case: (u64, bool, bool), path: SimdPath) {
    let n = 1003;
    let w: Vec<f64> = (0..n)
        .map(|i| if i % 11 == 0 { 0.0 } else { 1.0 })
        .collect();
    let thickness = vec![R; n];
    // Runs of 0..100, 100..613 and 613..1003: full blocks and remainders.
    let runs = [(0, 100), (100, 613), (613, n)];
    let mut one = ChunkLists::new(n);
    let mut many: Vec<ChunkLists> = runs.iter().map(|(s, e)| ChunkLists::new(e - s)).collect();
    let contacts = passes(m, case, n, |frame, prev, a| {
        let mut b = axes(a);
        let prev_axes = axes(prev);
        let mut expected = Contacts::default();
        for j in 0..n {
            if w[j] != 0.0 {
                let o = frame.resolve_listed(RunParticle::new(&mut one, j, prev[j], &mut a[j], R));
                expected = expected.merge(o.into());
            }
        }
        let total = over_runs(&mut b, (&prev_axes, &w), &runs, path, |k, mut run| {
            let (s, e) = runs[k];
            resolve_list_run(frame, &mut many[k], &thickness[s..e], &mut run)
        });
        assert_same_bits(a, &b, (total, expected), &format!("{path:?}, {case:?}"));
        total.contacts
    });
    assert!(contacts > 1000, "{path:?}, {case:?}: {contacts} contacts");
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

/// What the tests settled over a run of [`lanes_agree`].
#[derive(Debug)]
struct Settled {
    /// Particle-passes tested.
    tested: usize,
    /// Lanes the certified test settled: clear, pushed out of their face, in a hover ball.
    certified: [usize; 3],
    /// (lane, front triangle) distances the certified test worked out.
    fronts: usize,
    /// Particles the edge of their face settled (`edge_contact`).
    edges: usize,
}

/// From the same positions in every pass, `resolve_listed` (the certified test first, where the
/// mesh certifies) and `resolve` alone leave each particle within 10⁻¹² m of each other
/// (rounding apart: the certified test pushes along the face's plane, `resolve` through the
/// closest point). Returns what each test settled.
fn lanes_agree(m: &TriangleMesh, case: (u64, bool, bool), resting: Option<f64>) -> Settled {
    let n = 1003;
    let (mut with_test, mut alone) = (ChunkLists::new(n), ChunkLists::new(n));
    let mut worst = 0.0f64;
    let mut tested = 0;
    certified::SETTLED.with(|c| c.set([0; 3]));
    certified::FRONT_DISTANCES.with(|c| c.set(0));
    edge_contact::EDGES.with(|c| c.set(0));
    passes_from(m, case, (n, resting), |frame, prev, a| {
        let mut b = a.clone();
        let mut contacts = 0;
        for j in (0..n).filter(|j| j % 11 != 0) {
            contacts += frame
                .resolve_listed(RunParticle::new(&mut with_test, j, prev[j], &mut a[j], R))
                .contacts;
            frame.resolve(RunParticle::new(&mut alone, j, prev[j], &mut b[j], R));
            worst = worst.max((a[j] - b[j]).length());
            tested += 1;
        }
        contacts
    });
    assert!(worst <= 1e-12, "{case:?}: {worst:e} m apart");
    Settled {
        tested,
        certified: certified::SETTLED.with(|c| c.get()),
        fronts: certified::FRONT_DISTANCES.with(|c| c.get()),
        edges: edge_contact::EDGES.with(|c| c.get()),
    }
}

/// Without certificates every particle goes through `resolve` itself: the same bits, and the
/// certified test settles nothing.
#[test]
fn without_certificates_a_run_moves_particles_as_resolve_does() {
    for (m, seed, deforming) in [
        (bumpy_sphere(), 51, true),
        (bumpy_sheet(), 53, false),
        (TriangleMesh::icosphere(0.5, 4), 52, true),
    ] {
        let s = lanes_agree(&m, (seed, deforming, false), None);
        assert!(s.tested > 1000, "{s:?}");
        assert_eq!(s.certified, [0; 3], "no certificates");
    }
}

/// With certificates, on particles resting on the mesh (drifting 0.2 mm a substep), the
/// certified test settles most of the particles itself (clear, in a hover ball, or pushed out
/// of their face), works out front triangles' distances on the bumpy meshes, and leaves
/// particles over a convex edge to that edge (`edge_contact`); particles
/// about the mesh, deep inside and far away among them, still agree with `resolve` (on a
/// still closed mesh from the first pass: the deep ones get no certificate).
#[test]
fn the_certified_test_moves_particles_as_resolve_does() {
    lanes_agree(&TriangleMesh::icosphere(0.5, 3), (54, false, true), None);
    for (m, seed, deforming) in [
        (bumpy_sphere(), 51, true),
        (bumpy_sheet(), 53, false),
        (TriangleMesh::icosphere(0.5, 4), 52, true),
    ] {
        lanes_agree(&m, (seed, deforming, true), None);
        let s = lanes_agree(&m, (seed, deforming, true), Some(2e-4));
        let [_, pushed, hover] = s.certified;
        assert!(pushed > 1000, "{s:?}");
        if seed == 52 {
            // The smooth ball: most of its resting particles settled here, and hundreds over
            // an edge of their face by that edge.
            assert!(4 * (pushed + hover) > s.tested && hover > 1000, "{s:?}");
            assert!(s.edges > 300, "{s:?}");
        } else {
            // The bumpy meshes: their faces' front triangles worked out, and a few particles
            // over an edge settled by it past its faces' front triangles.
            assert!(s.fronts > 1000 && s.edges > 50, "{s:?}");
        }
    }
}

/// Two sheets facing each other, the upper one tilted, 1.8 r apart above the particle: a
/// particle 0.5 r above the lower one holds a certificate (every triangle off its face's ring,
/// the upper sheet's, about 1.3 r away), but pushed out to r it comes within r of the upper
/// sheet, beyond what the certificate covers. The certified test leaves it to the ring, which
/// pushes it back and forth between the sheets as `resolve` does (a single push, as the test
/// would make with no check of where it ends, leaves it elsewhere).
#[test]
fn a_push_beyond_the_certificate_is_left_to_the_ring() {
    let gap = 1.8 * R;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (y, up) in [(0.0, true), (gap, false)] {
        let base = vertices.len() as u32;
        let slope = if up { 0.0 } else { 0.2 };
        for (x, z) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            vertices.push(DVec3::new(x, y + slope * (x - 0.1), z));
        }
        // Counter-clockwise seen from the side each faces.
        if up {
            triangles.extend([[base, base + 2, base + 1], [base, base + 3, base + 2]]);
        } else {
            triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        }
    }
    let g = MeshGeometry::new(&vertices, &triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let frame = MeshFrame::still(&g, &pose, Friction::NONE);
    let (mut with_test, mut alone) = (ChunkLists::new(1), ChunkLists::new(1));
    let prev = DVec3::new(0.1, 0.5 * R, 0.05);
    let (mut a, mut b) = (prev, prev);
    frame.resolve_listed(RunParticle::new(&mut with_test, 0, prev, &mut a, R));
    frame.resolve(RunParticle::new(&mut alone, 0, prev, &mut b, R));
    assert_eq!(
        with_test.certs.face[0] as usize,
        g.nearest(prev, 1.0).expect("near").triangle
    );
    assert!((a - b).length() <= 1e-12, "{a} against {b}");
    let once = DVec3::new(prev.x, R, prev.z);
    assert!((a - once).length() > 1e-4, "{a}: pushed once");
}

/// Two sheets facing each other, the upper one coming down on a particle resting on the
/// lower one (a deforming mesh, 4 r to 1.5 r apart over six frames): certificates made while
/// the upper sheet is far must lapse as it travels (it comes within r of the particle), and
/// every pass agrees with `resolve`.
#[test]
fn a_surface_travelling_towards_a_certified_particle_lapses_its_certificate() {
    let sheets = |gap: f64| {
        let mut v = Vec::new();
        for y in [0.0, gap] {
            for (x, z) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
                v.push(DVec3::new(x, y + 0.1 * y * x, z));
            }
        }
        v
    };
    let triangles = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]];
    let mut g = MeshGeometry::new(&sheets(4.0 * R), &triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let (mut with_test, mut alone) = (ChunkLists::new(1), ChunkLists::new(1));
    let (mut a, mut b) = (DVec3::new(0.1, R, 0.05), DVec3::new(0.1, R, 0.05));
    let (mut certified, mut below_gap) = (0, false);
    for frame_no in 1..=6 {
        let gap = (4.0 - 2.5 * frame_no as f64 / 6.0) * R;
        g.begin_frame(&sheets(gap));
        for sub in 1..=SUBSTEPS {
            g.advance_to(sub as f64 / SUBSTEPS as f64);
            let frame = MeshFrame::still(&g, &pose, Friction::NONE);
            let prev = a;
            // Settling onto the lower sheet.
            a -= DVec3::Y * 1e-4;
            b -= DVec3::Y * 1e-4;
            certified::SETTLED.with(|c| c.set([0; 3]));
            frame.resolve_listed(RunParticle::new(&mut with_test, 0, prev, &mut a, R));
            certified += certified::SETTLED.with(|c| c.get()).iter().sum::<usize>();
            frame.resolve(RunParticle::new(&mut alone, 0, prev, &mut b, R));
            assert!(
                (a - b).length() <= 1e-12,
                "frame {frame_no}, substep {sub}: {a} against {b}"
            );
            below_gap |= gap < 2.0 * R;
        }
    }
    assert!(certified > 4 && below_gap, "{certified} passes certified");
}
