//! Kinematic bodies ([`KinematicBody`]): a fast bar does not tunnel through a hanging curtain,
//! whether it translates or swings, and friction drags a towel along with a capsule sliding
//! under it (frictionless, the towel stays).

use crate::common;

use std::sync::Arc;

use weft_collide::{BodyPart, CollisionWorld, Friction, KinematicBody, RoundCone};
use weft_solver::glam::{DQuat, DVec3};
use weft_solver::{
    ClothParams, Forces, GridDesc, Mass, Orientation, Settings, Solver, SolverBuilder,
};

const THICKNESS: f64 = 0.01;

/// A single round cone, given in its frame, carried by a rigid motion of time.
struct Bar {
    local: RoundCone,
    pose: Box<dyn Fn(f64) -> (DQuat, DVec3) + Send + Sync>,
}

impl KinematicBody for Bar {
    fn part_count(&self) -> usize {
        1
    }

    fn parts_at(&self, t: f64, out: &mut Vec<BodyPart>) {
        let (rotation, translation) = (self.pose)(t);
        let at = |p: DVec3| rotation * p + translation;
        out.clear();
        out.push(BodyPart {
            shape: RoundCone::new(
                at(self.local.a),
                at(self.local.b),
                self.local.ra,
                self.local.rb,
            ),
            rotation,
            translation,
        });
    }
}

fn curtain_solver() -> Solver {
    let mesh = common::hanging_curtain(32);
    let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("settings");
    b.add_cloth("curtain", &mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    b.build()
}

/// A bar 0.3 m long along x, of radius 0.015 m, moves through the curtain (x–y plane, z = 0)
/// at 24 m/s between `t0` and `t1` (4 cm per substep: more than its 3 cm diameter, so a
/// particle it passes ends the substep clean behind it). Its frame's origin is the bar's
/// centre, its y axis across the bar in the plane of the motion and its z axis ahead. After
/// every substep each particle's place in the bar's frame is compared with the last one: one
/// that went from ahead of the bar to behind it through the bar's cross-section (|across| < R
/// where its path crossed the bar's plane), within its length, went through it. Cloth that
/// wraps round the bar and trails behind it is not counted. Returns how many particle-substeps
/// were seen pushed ahead (z > 3 cm).
fn no_tunnel(pose: impl Fn(f64) -> (DQuat, DVec3) + Send + Sync + 'static, t1: f64) -> usize {
    const R: f64 = 0.015;
    let mut solver = curtain_solver();
    let mut world = CollisionWorld::new(&solver);
    let local = RoundCone::new(
        DVec3::new(-0.15, 0.0, 0.0),
        DVec3::new(0.15, 0.0, 0.0),
        R,
        R,
    );
    let pose = Arc::new(pose);
    let p2 = pose.clone();
    world
        .add_body(
            Arc::new(Bar {
                local,
                pose: Box::new(move |t| p2(t)),
            }),
            Friction::default(),
        )
        .expect("bar");
    let (mut through, mut pushed) = (0usize, 0usize);
    let in_frame = |t: f64, x: DVec3| {
        let (q, c) = pose(t);
        q.inverse() * (x - c)
    };
    let mut last: Vec<DVec3> = solver
        .particles()
        .positions
        .iter()
        .map(|&x| in_frame(0.0, x))
        .collect();
    common::run(&mut solver, &mut world, 6, |ctx, p| {
        for (x, was) in p.positions.iter().zip(&mut last) {
            let now = in_frame(ctx.time, *x);
            if was.z > 0.0 && now.z <= 0.0 {
                let s = was.z / (was.z - now.z);
                let at = *was + (now - *was) * s;
                through += usize::from(at.x.abs() < 0.14 && at.y.abs() < R);
            }
            *was = now;
            if ctx.time <= t1 + 1e-9 {
                pushed += usize::from(x.z > 0.03);
            }
        }
    });
    assert_eq!(through, 0, "particles went through the bar {through} times");
    pushed
}

#[test]
fn fast_translating_bar_does_not_tunnel_through_a_curtain() {
    let (z0, z1, t0, t1) = (-0.2, 0.16, 0.05, 0.065);
    let pushed = no_tunnel(
        move |t| {
            let s = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
            (DQuat::IDENTITY, DVec3::new(0.0, 0.5, z0 + (z1 - z0) * s))
        },
        t1,
    );
    println!("translating bar: {pushed} particle-substeps pushed ahead");
    assert!(pushed > 100, "the bar never pushed the cloth ({pushed})");
}

/// The bar hangs 0.4 m below a hinge along x behind the curtain and swings forward through it
/// at 60 rad/s (24 m/s), like a kicking shin: swept in its rotating frame.
#[test]
fn fast_swinging_bar_does_not_tunnel_through_a_curtain() {
    let hinge = DVec3::new(0.0, 0.9, -0.25);
    let (t0, t1, omega) = (0.05, 0.05 + 1.2 / 60.0, 60.0);
    let pushed = no_tunnel(
        move |t| {
            let angle = omega * (t.clamp(t0, t1) - t0);
            // About +x, the bar's frame turns its z (ahead) toward −y... so turn about −x:
            // the bar goes from below the hinge toward +z.
            let q = DQuat::from_rotation_x(-angle);
            (q, hinge + q * DVec3::new(0.0, -0.4, 0.0))
        },
        t1,
    );
    println!("swinging bar: {pushed} particle-substeps pushed ahead");
    assert!(pushed > 100, "the bar never pushed the cloth ({pushed})");
}

/// A 0.3 m towel lies over a horizontal capsule (radius 0.1 m, 2 m long along x). After
/// 0.5 s of settling the capsule slides along its own axis at 0.4 m/s: only friction can move
/// the towel. With friction it is dragged up to the capsule's speed and then sticks; without,
/// it does not move along the axis (it slides off sideways, a towel balanced on a frictionless
/// rod being unstable). Returns the towel's move along x, its speed and its lowest particle.
fn towel_on_sliding_capsule(friction: Friction) -> (f64, f64, f64) {
    let mesh = GridDesc {
        resolution: (16, 16),
        size: (0.3, 0.3),
        center: DVec3::new(0.0, 0.62, 0.0),
        orientation: Orientation::Horizontal,
        mass: Mass::Total(0.05),
        pins: vec![],
    }
    .build()
    .expect("towel");
    let forces = Forces {
        damping: 0.5,
        ..Forces::default()
    };
    let mut b = SolverBuilder::new(Settings::default(), forces).expect("settings");
    b.add_cloth("towel", &mesh, ClothParams::default(), THICKNESS)
        .expect("cloth");
    let mut solver = b.build();
    let mut world = CollisionWorld::new(&solver);
    let (start, speed) = (0.5, 0.4);
    world
        .add_body(
            Arc::new(Bar {
                local: RoundCone::new(
                    DVec3::new(-1.0, 0.0, 0.0),
                    DVec3::new(1.0, 0.0, 0.0),
                    0.1,
                    0.1,
                ),
                pose: Box::new(move |t| {
                    (
                        DQuat::IDENTITY,
                        DVec3::new(speed * (t - start).max(0.0), 0.5, 0.0),
                    )
                }),
            }),
            friction,
        )
        .expect("capsule");
    let centroid = |s: &Solver| {
        let p = &s.particles();
        (
            p.positions.iter().map(|x| x.x).sum::<f64>() / p.len() as f64,
            p.velocities.iter().map(|v| v.x).sum::<f64>() / p.len() as f64,
        )
    };
    for _ in 0..30 {
        solver.step_with(&mut world).expect("step");
    }
    let (x0, _) = centroid(&solver);
    for _ in 0..90 {
        solver.step_with(&mut world).expect("step");
    }
    let (x1, v1) = centroid(&solver);
    let lowest = solver
        .particles()
        .positions
        .iter()
        .map(|x| x.y)
        .fold(f64::MAX, f64::min);
    (x1 - x0, v1, lowest)
}

#[test]
fn friction_drags_cloth_with_a_moving_limb() {
    // The capsule moves 0.4 m/s × (2.0 s − 0.5 s) = 0.6 m.
    let (moved, v, lowest) = towel_on_sliding_capsule(Friction::default());
    println!("with friction: towel moved {moved:.4} m, moving at {v:.4} m/s");
    assert!(
        lowest > 0.3,
        "the towel fell off (lowest particle at y = {lowest})"
    );
    assert!(
        moved > 0.45,
        "friction dragged the towel only {moved} m of 0.6"
    );
    assert!(
        (v - 0.4).abs() < 0.02,
        "towel at {v} m/s, capsule at 0.4: not sticking"
    );
    let (moved, v, _) = towel_on_sliding_capsule(Friction::NONE);
    println!("frictionless: towel moved {moved:.5} m, moving at {v:.5} m/s");
    assert!(
        moved.abs() < 0.01,
        "a frictionless capsule dragged the towel {moved} m"
    );
    assert!(v.abs() < 0.01, "frictionless towel moving at {v} m/s");
}
