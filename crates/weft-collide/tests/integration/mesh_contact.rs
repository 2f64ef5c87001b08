//! Contact with triangle meshes through the f64 path: particles inside a closed mesh leave
//! through the near side, a cloth dropped on a fine sphere-shaped mesh stays a thickness off
//! it, and a thin blade (a deforming mesh) moving fast through a hanging cloth does not pass
//! through it.

use crate::common;

use std::sync::Arc;

use weft_collide::{ColliderDesc, CollisionWorld, Friction, Keyframes, ShapeDesc, TriangleMesh};
use weft_solver::glam::DVec3;
use weft_solver::{
    ClothParams, Forces, GridDesc, Mass, Orientation, Particles, Settings, Solver, SolverBuilder,
    SubstepContext,
};

const THICKNESS: f64 = 0.01;

fn solver_with(mesh: &weft_solver::ClothMesh, forces: Forces) -> Solver {
    let mut builder = SolverBuilder::new(Settings::default(), forces).expect("settings");
    builder
        .add_cloth("cloth", mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    builder.build()
}

/// Shortest distance from the origin to the mesh's surface (brute force over triangles).
fn inner_radius(m: &TriangleMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.vertices[i as usize]);
            // The origin's closest point: minimise over a fine barycentric sampling is too
            // slow; the faces of a convex mesh about the origin are nearest at their plane.
            let n = (b - a).cross(c - a).normalize();
            n.dot(a).abs()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Small 3 × 3 patches started inside a closed icosphere (radius 0.5), one just under the
/// surface (within a thickness) and one deep (0.3 m in, beyond any candidate list): both
/// leave through the nearest surface (+x here), not through the far side.
#[test]
fn particles_inside_a_closed_mesh_leave_through_the_near_side() {
    for depth in [0.004, 0.3] {
        let x0 = 0.5 - depth;
        let patch = GridDesc {
            resolution: (3, 3),
            size: (0.02, 0.02),
            center: DVec3::new(x0, 0.0, 0.0),
            orientation: Orientation::Vertical,
            mass: Mass::Total(0.01),
            pins: vec![],
        }
        .build()
        .expect("grid");
        let mut solver = solver_with(
            &patch,
            Forces {
                gravity: DVec3::ZERO,
                ..Forces::default()
            },
        );
        // Rotate the patch into the y–z plane so that it faces +x.
        for x in solver.particles_mut().positions.iter_mut() {
            *x = DVec3::new(x0, x.y, x.x - x0);
        }
        let p = solver.particles_mut();
        p.prev_positions.clone_from(&p.positions);
        let mut world = CollisionWorld::new(&solver);
        world
            .add_collider(&ColliderDesc::new(ShapeDesc::TriMesh(
                TriangleMesh::icosphere(0.5, 4),
            )))
            .expect("mesh");
        solver.step_with(&mut world).expect("step");
        for x in &solver.particles().positions {
            assert!(
                x.x > 0.48 && x.length() >= 0.5 - 0.002 + THICKNESS * 0.99,
                "depth {depth}: a particle ended at {x}"
            );
        }
    }
}

/// A 1.2 m cloth (48 × 48) falls onto an icosphere of 20,480 triangles and radius 0.4:
/// after every substep no particle is nearer the centre than the mesh's inner radius (its
/// faces' nearest points) plus the thickness, less 1 % of the thickness.
#[test]
fn cloth_on_a_fine_sphere_mesh_stays_a_thickness_off() {
    let radius = 0.4;
    let sphere = TriangleMesh::icosphere(radius, 5);
    assert_eq!(sphere.triangles.len(), 20_480);
    let inner = inner_radius(&sphere);
    assert!(
        radius - inner < 5e-4,
        "tessellation error {}",
        radius - inner
    );
    let cloth = GridDesc {
        resolution: (48, 48),
        size: (1.2, 1.2),
        center: DVec3::new(0.0, radius + 0.1, 0.0),
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.3),
        pins: vec![],
    }
    .build()
    .expect("grid");
    let mut solver = solver_with(
        &cloth,
        Forces {
            damping: 1.0,
            ..Forces::default()
        },
    );
    let mut world = CollisionWorld::new(&solver);
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::TriMesh(sphere)).with_friction(Friction::new(0.8, 0.6)),
        )
        .expect("mesh");
    let mut nearest = f64::INFINITY;
    let mut contacts = 0;
    common::run(&mut solver, &mut world, 90, |_, p| {
        for x in &p.positions {
            nearest = nearest.min(x.length());
        }
    });
    let p = solver.particles();
    for x in &p.positions {
        contacts += usize::from(x.length() < inner + 1.5 * THICKNESS);
    }
    println!(
        "nearest approach to the centre {nearest:.6} m (inner radius {inner:.6} + thickness {THICKNESS}); \
         {contacts} particles in contact; {} lists built",
        world.mesh_list_builds()
    );
    assert!(
        contacts > 200,
        "only {contacts} particles rest on the sphere"
    );
    assert!(
        nearest >= inner + 0.99 * THICKNESS,
        "a particle came within {} m of the centre",
        nearest
    );
}

/// A blade: a vertical 0.3 m × 0.3 m quad in the x–y plane (open, two triangles) at depth z.
fn blade_at(z: f64) -> Vec<DVec3> {
    [(-0.15, 0.35), (0.15, 0.35), (0.15, 0.65), (-0.15, 0.65)]
        .map(|(x, y)| DVec3::new(x, y, z))
        .to_vec()
}

/// A hanging curtain (x–y plane at z = 0, pinned along its top at y = 1) and a blade that
/// sweeps through it along +z at 24 m/s (keys 15 ms apart; the world moves it linearly over
/// each 1/60 s frame, about 3.6 cm per substep, 3.6 thicknesses), as a deforming mesh driven
/// by keyframes, then stops. While it moves, no particle within the blade's footprint gets
/// behind it (where the world has it at each substep's end): all stay on the side they
/// started on, a thickness off.
#[test]
fn fast_blade_does_not_tunnel_through_a_hanging_cloth() {
    let cloth = common::hanging_curtain(32);
    let mut solver = solver_with(&cloth, Forces::default());
    let mut world = CollisionWorld::new(&solver);
    let (z0, z1, t0, t1) = (-0.2, 0.16, 0.05, 0.065);
    let speed = (z1 - z0) / (t1 - t0);
    let keys = Keyframes::new(vec![t0, t1], vec![blade_at(z0), blade_at(z1)]).expect("keys");
    let rest = blade_at(z0);
    // Seen from +z the corners run counter-clockwise: the normal is +z.
    let blade = TriangleMesh::new(rest, vec![[0, 1, 2], [0, 2, 3]]).expect("blade");
    world
        .add_deforming_mesh(
            &ColliderDesc::new(ShapeDesc::TriMesh(blade)),
            Arc::new(keys),
        )
        .expect("blade");
    let (mut worst, mut pushed) = (f64::INFINITY, 0usize);
    let mut moving = 0;
    // While the blade moves (after it stops, the cloth may wrap around its edges).
    let check = |_: &SubstepContext, p: &Particles, w: &CollisionWorld| {
        let z = w.colliders()[0].mesh_vertices().expect("a mesh")[0].z;
        if z <= z0 || z >= z1 {
            return;
        }
        moving += 1;
        for x in &p.positions {
            if x.x.abs() < 0.14 && x.y > 0.36 && x.y < 0.64 {
                worst = worst.min(x.z - z);
                pushed += usize::from(x.z > 0.05);
            }
        }
    };
    {
        let mut hook = common::Watch {
            world: &mut world,
            check,
        };
        for _ in 0..4 {
            solver.step_with(&mut hook).expect("stable");
        }
    }
    assert!(moving >= 5, "the blade moved over {moving} substeps");
    println!("blade at {speed} m/s: nearest particle ahead of it {worst:.5} m; {pushed} pushed");
    assert!(
        worst >= 0.9 * THICKNESS,
        "a particle got within {worst} m of the blade's front (or behind it)"
    );
    assert!(pushed > 100, "the blade never pushed the cloth");
}
