//! Scratch probe (not committed).
use weft_collide::*;
use weft_solver::glam::{Quat, Vec3};
use weft_solver::*;
fn main() {
    let ms: f32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(0.4);
    let angle = 20f32.to_radians();
    let tilt = Quat::from_rotation_z(angle);
    let normal = tilt * Vec3::Y;
    let half = Vec3::new(1.5, 0.1, 0.5);
    let off = Vec3::splat(
        std::env::args()
            .nth(2)
            .and_then(|a| a.parse().ok())
            .unwrap_or(0.0),
    );
    let top = tilt * Vec3::new(0.0, half.y, 0.0) + off;
    let mut mesh = GridDesc {
        resolution: (2, 2),
        size: (0.3, 0.3),
        center: Vec3::ZERO,
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.05),
        pins: vec![],
    }
    .build()
    .unwrap();
    for x in &mut mesh.positions {
        *x = tilt * *x + top + normal * 0.005;
    }
    let mut b = SolverBuilder::new(Settings::default(), Forces::default()).unwrap();
    b.add_cloth("p", &mesh, ClothParams::default(), 0.005)
        .unwrap();
    let mut solver = b.build();
    let mut world = CollisionWorld::new(&solver);
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Cuboid { half_extents: half })
                .rotated(tilt)
                .at(off)
                .with_friction(Friction::new(ms, 0.3)),
        )
        .unwrap();
    let down = -(tilt * Vec3::X);
    for f in 0..6 {
        solver.step_with(&mut world).unwrap();
        let p = solver.particles();
        println!(
            "{f} v_t {:.5} v_n {:.5} d {:.6} c {}",
            p.velocities[0].dot(down),
            p.velocities[0].dot(normal),
            (p.positions[0] - top).dot(normal),
            world.stats().collider_contacts
        );
    }
}
