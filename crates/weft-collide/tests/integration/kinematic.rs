//! A kinematic collider follows its prescribed motion exactly and pushes the cloth ahead of it.

use crate::common;
use weft_collide::{ColliderDesc, CollisionWorld, Friction, ShapeDesc};
use weft_solver::glam::{DQuat, DVec3, Vec3};

use weft_solver::{ClothParams, Forces, Motion, Settings, SolverBuilder};

const THICKNESS: f64 = 0.01;
const RADIUS: f64 = 0.15;

#[test]
fn moving_sphere_follows_its_motion_and_pushes_a_curtain() {
    // A 0.8 m curtain hangs in the x–y plane from its pinned top edge at y = 1.
    let mesh = common::hanging_curtain(16);
    let forces = Forces {
        damping: 1.0,
        ..Forces::default()
    };
    let mut builder = SolverBuilder::new(Settings::default(), forces).expect("settings");
    builder
        .add_cloth("curtain", &mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    let mut solver = builder.build();
    let mut world = CollisionWorld::new(&solver);
    // The sphere starts 0.4 m behind the curtain and moves through its plane at 0.5 m/s.
    let start = DVec3::new(0.0, 0.55, -0.4);
    let velocity = DVec3::new(0.0, 0.0, 0.5);
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Sphere { radius: RADIUS })
                .at(start)
                .moving(Motion::Linear { velocity })
                .with_friction(Friction::new(0.3, 0.2)),
        )
        .expect("sphere");
    let seconds = 1.6;
    let mut worst_pose_error = 0.0f64;
    let mut worst_gap = f64::INFINITY;
    let frames = (seconds * 60.0) as usize;
    for _ in 0..frames {
        solver.step_with(&mut world).expect("step");
        let t = solver.time();
        let centre = world.colliders()[0].pose().translation.as_dvec3();
        let expected = start + velocity * t;
        worst_pose_error = worst_pose_error.max(centre.distance(expected));
        for x in &solver.particles().positions {
            worst_gap = worst_gap.min(x.distance(centre) - (RADIUS + THICKNESS));
        }
    }
    let centre = start + velocity * seconds;
    let front = centre.z + RADIUS + THICKNESS;
    // The particle straight ahead of the sphere's centre.
    let ahead = solver
        .particles()
        .positions
        .iter()
        .copied()
        .filter(|x| (x.x.abs() < 0.06) && (x.y - centre.y).abs() < 0.06)
        .fold(f64::MIN, |m, x| m.max(x.z));
    println!(
        "pose error {worst_pose_error:.2e} m; closest approach {worst_gap:.5} m; sphere front at \
         z = {front:.3}, cloth ahead at z = {ahead:.3}"
    );
    assert!(
        worst_pose_error < 1e-5,
        "collider off its motion by {worst_pose_error} m"
    );
    assert!(
        worst_gap >= -0.1 * THICKNESS,
        "a particle got {worst_gap} m inside the moving sphere's thickness shell"
    );
    // The sphere went 0.4 m past the curtain's plane: the cloth in front of it was carried.
    assert!(
        ahead > front - 0.02,
        "cloth ahead of the sphere at z = {ahead}, sphere front at {front}: not pushed"
    );
}

#[test]
fn rotating_box_pose_matches_motion() {
    let solver = weft_collide::scenarios::sphere_drop(weft_solver::Method::Xpbd, 4)
        .expect("scenario")
        .0;
    let mut world = CollisionWorld::new(&solver);
    let motion = Motion::Rotate {
        pivot: DVec3::new(1.0, 0.0, 0.0),
        axis: DVec3::Y,
        angular_velocity: 2.0,
    };
    let rest = DVec3::new(2.0, 0.5, 0.0);
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Cuboid {
                half_extents: DVec3::splat(0.1),
            })
            .at(rest)
            .rotated(DQuat::from_rotation_x(0.3))
            .moving(motion),
        )
        .expect("box");
    let mut c = world.colliders()[0].clone();
    for t in [0.0, 0.25, 1.0, 3.0] {
        c.set_time(t, t);
        let m = motion.transform(t);
        let expected = m.apply(rest);
        assert!(
            c.pose().translation.as_dvec3().distance(expected) < 1e-5,
            "t = {t}: {} vs {expected}",
            c.pose().translation
        );
        let r = m.rotation * DQuat::from_rotation_x(0.3);
        assert!(
            c.pose().rotation.as_dquat().dot(r).abs() > 1.0 - 1e-6,
            "t = {t}"
        );
        // A point on the box surface is displaced as the motion prescribes.
        let corner = c.pose().transform_point(Vec3::splat(0.1)).as_dvec3();
        c.set_time(t, t + 0.01);
        let moved = c.displacement_at(c.pose().transform_point(Vec3::splat(0.1)).as_dvec3());
        let expected_move = motion
            .transform(t + 0.01)
            .apply(DQuat::from_rotation_x(0.3) * DVec3::splat(0.1) + rest)
            - corner;
        assert!(
            (moved - expected_move).length() < 1e-5,
            "{moved} vs {expected_move}"
        );
    }
}
