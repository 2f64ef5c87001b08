//! Coulomb friction on a tilted box: a cloth sticks when μs > tan θ and slides otherwise, with
//! the sliding distance of a block on an incline, ½ g (sin θ − μk cos θ) t².

use crate::common;

use weft_collide::{ColliderDesc, CollisionWorld, Friction, ShapeDesc};
use weft_solver::glam::{DQuat, DVec3};
use weft_solver::{ClothParams, Forces, GridDesc, Mass, Orientation, Settings, SolverBuilder};

const ANGLE_DEG: f64 = 20.0;
const THICKNESS: f64 = 0.005;
const SECONDS: f64 = 0.5;

/// Downhill displacement of the cloth's centroid after `SECONDS` on the slope (m).
fn slide(friction: Friction) -> f64 {
    let angle = ANGLE_DEG.to_radians();
    let tilt = DQuat::from_rotation_z(angle);
    let normal = tilt * DVec3::Y;
    let half = DVec3::new(1.5, 0.1, 0.5);
    let top = tilt * DVec3::new(0.0, half.y, 0.0);
    let mut mesh = GridDesc {
        resolution: (10, 10),
        size: (0.3, 0.3),
        center: DVec3::ZERO,
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.05),
        pins: vec![],
    }
    .build()
    .expect("grid");
    for x in &mut mesh.positions {
        *x = tilt * *x + top + normal * THICKNESS;
    }
    let forces = Forces::default(); // no air damping: the incline formula holds exactly
    let mut builder = SolverBuilder::new(Settings::default(), forces).expect("settings");
    builder
        .add_cloth("patch", &mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    let mut solver = builder.build();
    let mut world = CollisionWorld::new(&solver);
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Cuboid { half_extents: half })
                .rotated(tilt)
                .with_friction(friction),
        )
        .expect("box");
    let centroid = |p: &[DVec3]| p.iter().sum::<DVec3>() / p.len() as f64;
    let start = centroid(&solver.particles().positions);
    let frames = (SECONDS * 60.0).round() as usize;
    let mut worst = f64::INFINITY;
    common::run(&mut solver, &mut world, frames, |_, p| {
        for x in &p.positions {
            worst = worst.min((*x - top).dot(normal));
        }
    });
    assert!(
        worst > THICKNESS * 0.9,
        "a particle sank to {worst} m from the slope surface"
    );
    let downhill = -(tilt * DVec3::X);
    (centroid(&solver.particles().positions) - start).dot(downhill)
}

#[test]
fn cloth_sticks_above_tan_angle_and_slides_below() {
    let angle = ANGLE_DEG.to_radians();
    let tan = angle.tan();
    let g = 9.81;
    // μs = 0.6 > tan 20° = 0.364: static friction holds the cloth.
    let stuck = slide(Friction::new(0.6, 0.5));
    // μ = 0.15 < tan 20°: it slides with a = g (sin θ − μk cos θ).
    let mu = 0.15;
    let sliding = slide(Friction::new(mu, mu));
    let expected = 0.5 * g * (angle.sin() - mu * angle.cos()) * SECONDS * SECONDS;
    // Frictionless: a = g sin θ.
    let free = slide(Friction::NONE);
    let expected_free = 0.5 * g * angle.sin() * SECONDS * SECONDS;
    println!(
        "tan θ = {tan:.3}; μs 0.6: {stuck:.5} m; μ 0.15: {sliding:.4} m (incline formula \
         {expected:.4} m); μ 0: {free:.4} m (formula {expected_free:.4} m)"
    );
    assert!(stuck.abs() < 2e-3, "cloth with μs > tan θ moved {stuck} m");
    // The threshold is tan θ itself: μs 5 % above sticks, 5 % below slides (μk 0.3).
    let just_above = slide(Friction::new(1.05 * tan, 0.3));
    let just_below = slide(Friction::new(0.95 * tan, 0.3));
    let expected_below = 0.5 * g * (angle.sin() - 0.3 * angle.cos()) * SECONDS * SECONDS;
    println!(
        "μs = 1.05 tan θ: {just_above:.5} m; μs = 0.95 tan θ: {just_below:.4} m (formula \
         {expected_below:.4} m)"
    );
    assert!(
        just_above.abs() < 2e-3,
        "μs = 1.05 tan θ moved {just_above} m"
    );
    assert!(
        (just_below - expected_below).abs() < 0.15 * expected_below,
        "μs = 0.95 tan θ slid {just_below} m, formula {expected_below} m"
    );
    assert!(
        (sliding - expected).abs() < 0.1 * expected,
        "sliding {sliding} m, incline formula {expected} m"
    );
    assert!(
        (free - expected_free).abs() < 0.1 * expected_free,
        "frictionless {free} m, formula {expected_free} m"
    );
}
