//! Closed-form colliders, still triangle meshes (on their contact grids) and deforming ones
//! (on candidate lists kept per run of particles) inside the solver's fused frame
//! (`SubstepHook::particle_contacts`) give the same bits, contact counts and statistics as the
//! general loop, on 1 and 2 threads;
//! and the general loop gives the same bits whether or not it leaves each substep's velocity
//! update to the next integration pass (`SubstepHook::uses_velocities`).

use weft_collide::scenarios::{breathing_drop, ground, sphere_drop};
use weft_collide::{ColliderDesc, CollisionWorld, ContactStats, Friction, ShapeDesc, TriangleMesh};
use weft_solver::glam::{DQuat, DVec3};
use weft_solver::{Method, Motion, Particles, Solver, SubstepContext, SubstepHook};

/// `CollisionWorld` without its per-particle contacts: forces the general loop; the flag is
/// what it answers to `uses_velocities` (the world answers false).
struct General<'a>(&'a mut CollisionWorld, bool);

impl SubstepHook for General<'_> {
    fn uses_velocities(&self) -> bool {
        self.1
    }

    fn begin_substep(&mut self, ctx: &SubstepContext, particles: &Particles) {
        self.0.begin_substep(ctx, particles);
    }

    fn project(&mut self, ctx: &SubstepContext, particles: &mut Particles) -> usize {
        self.0.project(ctx, particles)
    }

    fn end_substep(&mut self, ctx: &SubstepContext, particles: &mut Particles) {
        self.0.end_substep(ctx, particles);
    }
}

/// The breathing ball's centre.
const BREATHING: DVec3 = DVec3::new(-0.5, 0.45, -0.4);

/// Which triangle meshes a scene holds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Meshes {
    /// None.
    No,
    /// A still, turned ball and one moving as a rigid body.
    Still,
    /// Those and a breathing ball (a deforming mesh).
    Deforming,
}

/// The sphere drop at 40², plus a moving, tilted capsule and an oscillating box in the
/// cloth's way (friction against moving surfaces, several closed-form shapes in order), with
/// `substeps` × `iterations`, and `meshes`.
fn scene(substeps: u32, iterations: u32, meshes: Meshes) -> (Solver, CollisionWorld) {
    let (mut solver, mut world) = sphere_drop(Method::Xpbd, 40).expect("scenario");
    let mut settings = *solver.settings();
    settings.iterations = iterations;
    settings.substeps = substeps;
    solver.set_settings(settings).expect("valid settings");
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Capsule {
                half_height: 0.4,
                radius: 0.08,
            })
            .at(DVec3::new(-0.5, 0.55, 0.0))
            .rotated(DQuat::from_rotation_z(1.2))
            .moving(Motion::Linear {
                velocity: DVec3::new(0.3, 0.0, 0.1),
            })
            .with_friction(Friction::new(0.5, 0.4)),
        )
        .expect("capsule");
    world
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Cuboid {
                half_extents: DVec3::new(0.15, 0.1, 0.15),
            })
            .at(DVec3::new(0.45, 0.5, 0.3))
            .moving(Motion::Oscillate {
                amplitude: DVec3::new(0.0, 0.1, 0.05),
                frequency: 1.5,
            }),
        )
        .expect("box");
    if meshes != Meshes::No {
        let ball = || ShapeDesc::TriMesh(TriangleMesh::icosphere(0.2, 3));
        world
            .add_collider(
                &ColliderDesc::new(ball())
                    .at(DVec3::new(0.3, 0.45, -0.35))
                    .rotated(DQuat::from_rotation_y(0.7))
                    .with_friction(Friction::new(0.6, 0.5)),
            )
            .expect("still mesh");
        world
            .add_collider(
                &ColliderDesc::new(ball())
                    .at(DVec3::new(-0.3, 0.35, 0.35))
                    .moving(Motion::Linear {
                        velocity: DVec3::new(0.1, 0.3, 0.0),
                    }),
            )
            .expect("moving mesh");
    }
    if meshes == Meshes::Deforming {
        // Breathing by 20 % at 2 Hz, under a corner of the cloth.
        let breathe = |t: f64, rest: &[DVec3], out: &mut [DVec3]| {
            let s = 1.0 + 0.2 * (std::f64::consts::TAU * 2.0 * t).sin();
            for (o, v) in out.iter_mut().zip(rest) {
                *o = BREATHING + (*v - BREATHING) * s;
            }
        };
        let mut m = TriangleMesh::icosphere(0.15, 3);
        for v in &mut m.vertices {
            *v += BREATHING;
        }
        world
            .add_deforming_mesh(
                &ColliderDesc::new(ShapeDesc::TriMesh(m)).with_friction(Friction::new(0.5, 0.4)),
                std::sync::Arc::new(breathe),
            )
            .expect("deforming mesh");
    }
    world.add_collider(&ground(-0.6)).expect("ground");
    (solver, world)
}

/// Bits of every position and velocity, then the contacts and statistics of each frame.
type Run = (Vec<[u64; 6]>, Vec<usize>, Vec<ContactStats>);

/// How a run steps its world.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Loop {
    /// The world as it is: the fused frame.
    Fused,
    /// The general loop, each substep's velocities updated in a pass of their own.
    General,
    /// The general loop, each substep's velocities updated in the next integration pass.
    Deferred,
}

fn run(threads: usize, (substeps, iterations): (u32, u32), how: Loop, meshes: Meshes) -> Run {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(|| {
            let (mut solver, mut world) = scene(substeps, iterations, meshes);
            // Global damping too: the deferred velocity update applies it.
            let mut forces = *solver.forces();
            forces.damping = 0.4;
            solver.set_forces(forces).expect("valid forces");
            assert!(world.particle_contacts().is_some(), "per-particle contacts");
            let (mut contacts, mut stats) = (Vec::new(), Vec::new());
            for _ in 0..45 {
                let step = match how {
                    Loop::Fused => solver.step_with(&mut world),
                    Loop::General => solver.step_with(&mut General(&mut world, true)),
                    Loop::Deferred => solver.step_with(&mut General(&mut world, false)),
                };
                contacts.push(step.expect("stable").contacts);
                stats.push(world.stats());
                assert!(world.particle_contacts().is_some(), "per-particle contacts");
            }
            let p = solver.particles();
            let bits = p
                .positions
                .iter()
                .zip(&p.velocities)
                .map(|(x, v)| {
                    let [a, b, c] = x.to_array().map(f64::to_bits);
                    let [d, e, f] = v.to_array().map(f64::to_bits);
                    [a, b, c, d, e, f]
                })
                .collect();
            (bits, contacts, stats)
        })
}

/// Fused runs on 1 and 2 threads and a deferred general run against the general loop, for
/// several substep and iteration counts.
fn fused_matches_general(meshes: Meshes) {
    // One substep per frame shows every substep's statistics (they are kept per substep).
    let mut swept = 0;
    for steps in [(10, 1), (4, 2), (1, 2)] {
        let general = run(1, steps, Loop::General, meshes);
        if meshes == Meshes::Deforming {
            // The cloth came down on the breathing ball (0.18 m at most, 1 cm thick).
            let nearest = (general.0.iter())
                .map(|b| {
                    (DVec3::new(
                        f64::from_bits(b[0]),
                        f64::from_bits(b[1]),
                        f64::from_bits(b[2]),
                    ) - BREATHING)
                        .length()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest < 0.2,
                "nearest particle {nearest} m from the breathing ball"
            );
        }
        let touched: usize = general.1.iter().sum();
        assert!(touched > 2000, "the cloth reached the colliders: {touched}");
        assert!(general.2.iter().any(|s| s.max_depth > 0.0));
        swept += general.2.iter().map(|s| s.swept).sum::<usize>();
        for (threads, how) in [(1, Loop::Fused), (2, Loop::Fused), (2, Loop::Deferred)] {
            let other = run(threads, steps, how, meshes);
            assert!(
                other.0 == general.0,
                "positions or velocities differ: {how:?}, {steps:?}, {threads} thread(s)"
            );
            assert_eq!(other.1, general.1, "contacts per frame, {how:?}, {steps:?}");
            assert_eq!(
                other.2, general.2,
                "statistics of each frame, {how:?}, {steps:?}"
            );
        }
    }
    assert!(swept > 0, "some particle was swept");
}

#[test]
fn closed_form_colliders_in_the_fused_frame_match_the_general_loop() {
    fused_matches_general(Meshes::No);
}

#[test]
fn still_meshes_in_the_fused_frame_match_the_general_loop() {
    fused_matches_general(Meshes::Still);
}

#[test]
fn deforming_meshes_in_the_fused_frame_match_the_general_loop() {
    fused_matches_general(Meshes::Deforming);
}

#[test]
fn self_collision_keeps_the_general_loop_and_deforming_meshes_join() {
    let (solver, mut world) = sphere_drop(Method::Xpbd, 8).expect("scenario");
    assert!(world.particle_contacts().is_some());
    world
        .enable_self_collision(&solver, &[0], Default::default())
        .expect("self-collision");
    assert!(
        world.particle_contacts().is_none(),
        "self-collision pairs particles"
    );
    let (mut solver, mut world) = breathing_drop(Method::Xpbd, 8).expect("scenario");
    solver.step_with(&mut world).expect("stable");
    assert!(
        world.particle_contacts().is_some(),
        "a deforming mesh's lists are kept per run"
    );
}
