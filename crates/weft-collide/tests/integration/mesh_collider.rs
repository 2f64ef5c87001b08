//! A cloth dropped on a triangle-mesh collider loaded from an OBJ file does not pass through.

use crate::common;

use weft_collide::scenarios::{THICKNESS, mesh_drop};
use weft_solver::Method;

#[test]
fn cloth_dropped_on_obj_mesh_stays_outside() {
    let (mut solver, mut world) = mesh_drop(Method::Xpbd, 20).expect("scenario builds");
    let blob = world.colliders()[0].clone();
    assert_eq!(blob.kind(), "triangle mesh");
    let mut worst = f64::INFINITY;
    let mut touched = false;
    common::run(&mut solver, &mut world, 120, |_, p| {
        for x in &p.positions {
            // Signed distance to the mesh surface (negative inside), searched up to 1 m.
            if let Some(s) = blob.closest(*x, 1.0) {
                worst = worst.min(s.distance);
                touched |= s.distance < 2.0 * THICKNESS;
            }
        }
    });
    let p = solver.particles();
    let top = p.positions.iter().map(|x| x.y).fold(f64::MIN, f64::max);
    println!(
        "closest approach to the mesh {worst:.5} m (thickness {THICKNESS}); highest particle \
         {top:.4} m; KE {:.2e} J",
        p.kinetic_energy()
    );
    assert!(touched, "the cloth never reached the mesh");
    assert!(
        worst >= 0.9 * THICKNESS,
        "a particle came within {worst} m of the mesh surface (thickness {THICKNESS})"
    );
    // Resting on the blob (top near 0.45 + 0.4·(1 ± bumps)), not on the ground.
    assert!(
        top > 0.7,
        "the cloth fell to {top} m: it went through the blob"
    );
}

/// A cloth shot at 30 m/s (5 cm per substep, five thicknesses) at a thin two-triangle mesh is
/// stopped by the swept test instead of tunnelling through.
#[test]
fn fast_cloth_does_not_tunnel_through_thin_mesh() {
    use weft_collide::{ColliderDesc, CollisionWorld, ShapeDesc, TriangleMesh};
    use weft_solver::glam::DVec3;
    use weft_solver::{ClothParams, Forces, GridDesc, Mass, Orientation, Settings, SolverBuilder};
    let quad = TriangleMesh::new(
        vec![
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(-1.0, 0.0, 1.0),
        ],
        // Counter-clockwise seen from above: the outside is +y.
        vec![[0, 2, 1], [0, 3, 2]],
    )
    .expect("valid quad");
    let mesh = GridDesc {
        resolution: (8, 8),
        size: (0.4, 0.4),
        center: DVec3::new(0.0, 0.3, 0.0),
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.1),
        pins: vec![],
    }
    .build()
    .expect("grid");
    let mut builder = SolverBuilder::new(Settings::default(), Forces::default()).expect("ok");
    builder
        .add_cloth("sheet", &mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    let mut solver = builder.build();
    solver
        .particles_mut()
        .velocities
        .fill(DVec3::new(0.0, -30.0, 0.0));
    let mut world = CollisionWorld::new(&solver);
    world
        .add_collider(&ColliderDesc::new(ShapeDesc::TriMesh(quad)))
        .expect("mesh collider");
    let mut lowest = f64::INFINITY;
    let mut swept = 0;
    let mut hook = common::Watch {
        world: &mut world,
        check: |_: &weft_solver::SubstepContext, p: &weft_solver::Particles, _: &CollisionWorld| {
            for x in &p.positions {
                lowest = lowest.min(x.y);
            }
        },
    };
    for _ in 0..20 {
        solver.step_with(&mut hook).expect("step");
        swept += hook.world.stats().swept;
    }
    println!("lowest particle {lowest:.5} m; swept stops in last substeps {swept}");
    assert!(
        lowest >= 0.9 * THICKNESS,
        "a particle reached y = {lowest}: it tunnelled through the mesh"
    );
}
