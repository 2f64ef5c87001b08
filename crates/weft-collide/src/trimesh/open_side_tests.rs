//! An open surface keeps a particle on the side it came from, even beside a sharp fold, on
//! the candidate lists' path and on the contact grid's.

use glam::{DQuat, DVec3};

use crate::analytic::WorldPose;
use crate::analytic_vs_parry::Rng;
use crate::friction::Friction;
use crate::mesh::TriangleMesh;
use crate::trimesh::MeshGeometry;
use crate::trimesh::ccd::segment_crossing;
use crate::trimesh::chunk_lists::ChunkLists;
use crate::trimesh::contact_grid::ContactGrid;
use crate::trimesh::frame::{MeshFrame, RunParticle};
use crate::trimesh::grid_contacts::GridParticles;
use crate::trimesh::test_particles::under;
use crate::trimesh::vs_parry::bumpy_sheet;

/// Thickness of every particle (m).
const R: f64 = 0.01;

/// Particles on `m`'s sheet.
const N: usize = 203;

/// How a particle is resolved: the candidate lists or the contact grid.
#[derive(Clone, Copy, Debug)]
enum Path {
    Lists,
    Grid,
}

/// Particles 1.5 r off `m` on side `side` (+1: along the normal at their nearest point, −1:
/// against it), left there for a substep, then driven `depth` r through the surface in one
/// substep: how many end up on the far side (their last substep's path crosses a triangle,
/// brute force over every one).
fn crossed(m: &TriangleMesh, path: Path, seed: u64, depth: f64, side: f64) -> usize {
    let g = MeshGeometry::new(&m.vertices, &m.triangles);
    let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
    let mut rng = Rng(seed);
    let on = under(&g, &mut rng, N, (0.35, 0.5));
    let start: Vec<DVec3> = on.iter().map(|&(p, n)| p + n * 1.5 * R * side).collect();
    let frame = MeshFrame::still(&g, &pose, Friction::new(0.8, 0.6));
    let grid = ContactGrid::new(&g, R).expect("small grid");
    let state = GridParticles::new(N);
    let mut lists = ChunkLists::new(N);
    let mut step = |from: &[DVec3], mut x: Vec<DVec3>| -> Vec<DVec3> {
        for j in 0..N {
            match path {
                Path::Lists => {
                    frame.resolve(RunParticle::new(&mut lists, j, from[j], &mut x[j], R))
                }
                Path::Grid => frame.resolve_in_grid((&grid, &state), j, from[j], &mut x[j], R),
            };
        }
        x
    };
    let rest = step(&start, start.clone());
    let through: Vec<DVec3> = rest
        .iter()
        .zip(&on)
        .map(|(x, &(_, n))| *x - n * depth * R * side)
        .collect();
    let end = step(&rest, through);
    rest.iter()
        .zip(&end)
        .filter(|(from, to)| {
            m.triangles.iter().any(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                let normal = (b - a).cross(c - a).normalize();
                segment_crossing(**from, **to, [a, b, c], normal, false).is_some()
            })
        })
        .count()
}

/// On a height field whose slopes exceed 1, a particle driven through the sheet is swept
/// back r off the face it crossed; beside a fold that point can lie through the face across
/// it, and a push out of that face along its closest direction carried 5 % of these
/// particles to the far side before contacts held each particle to its side.
#[test]
fn a_particle_driven_through_a_folded_open_sheet_stays_on_its_side() {
    let sheet = bumpy_sheet();
    for path in [Path::Lists, Path::Grid] {
        for depth in [2.0, 3.0, 5.0, 10.0] {
            for side in [1.0, -1.0] {
                let through: usize = (0..10)
                    .map(|seed| crossed(&sheet, path, seed, depth, side))
                    .sum();
                assert_eq!(
                    through,
                    0,
                    "{path:?}, driven {depth} r from side {side}: {through} of {} through",
                    10 * N
                );
            }
        }
    }
}
