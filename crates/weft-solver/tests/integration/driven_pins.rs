//! Driven pins ([`PinDriver`]): driven particles sit exactly where the driver puts them at
//! every substep's end time, with the driver's velocity, on the fused path and the general
//! loop alike (the same bits), and bad drivers are refused.

use crate::common;

use std::sync::{Arc, Mutex};

use common::flag::{flag_settings, fusable_flag, in_pool, state_bits, step, windy_flag};
use weft_solver::glam::{DQuat, DVec3};
use weft_solver::{Method, Particles, PinDriver, Solver, SolverError, SubstepContext, SubstepHook};

/// Particles carried round the y axis through (0, 0.5, 0) at ω rad/s, each from its rest
/// position: x(t) = R(ωt) r, v = ω ŷ × (x − pivot).
struct Turntable {
    particles: Vec<u32>,
    rest: Vec<DVec3>,
    omega: f64,
}

const PIVOT: DVec3 = DVec3::new(0.0, 0.5, 0.0);

impl Turntable {
    fn position(&self, k: usize, t: f64) -> DVec3 {
        PIVOT + DQuat::from_rotation_y(self.omega * t) * (self.rest[k] - PIVOT)
    }
}

impl PinDriver for Turntable {
    fn particles(&self) -> &[u32] {
        &self.particles
    }

    fn drive(&self, t: f64, positions: &mut [DVec3], velocities: &mut [DVec3]) {
        for k in 0..self.particles.len() {
            positions[k] = self.position(k, t);
            velocities[k] = DVec3::Y.cross(positions[k] - PIVOT) * self.omega;
        }
    }
}

/// The flag's top-row particles 0..8 on a turntable.
fn turntable(s: &Solver) -> Arc<Turntable> {
    let particles: Vec<u32> = (0..8).collect();
    let rest = particles
        .iter()
        .map(|&i| s.particles().positions[i as usize])
        .collect();
    Arc::new(Turntable {
        particles,
        rest,
        omega: 3.0,
    })
}

/// Records, after every substep, the worst distance of a driven particle from the driver's
/// position at the substep's end time.
struct Check {
    driver: Arc<Turntable>,
    worst: Arc<Mutex<(f64, usize)>>,
}

impl SubstepHook for Check {
    fn end_substep(&mut self, ctx: &SubstepContext, p: &mut Particles) {
        let mut w = self.worst.lock().expect("lock");
        for (k, &i) in self.driver.particles.iter().enumerate() {
            let off = p.positions[i as usize].distance(self.driver.position(k, ctx.time));
            w.0 = w.0.max(off);
            w.1 += 1;
        }
    }
}

#[test]
fn driven_particles_follow_their_driver_every_substep() {
    let (b, _) = windy_flag((24, 24), flag_settings(Method::Xpbd, 128));
    let mut s = b.build();
    let driver = turntable(&s);
    s.add_pin_driver(driver.clone()).expect("valid driver");
    let worst = Arc::new(Mutex::new((0.0, 0)));
    let mut hook = Check {
        driver: driver.clone(),
        worst: worst.clone(),
    };
    for _ in 0..30 {
        s.step_with(&mut hook).expect("stable");
    }
    let (off, seen) = *worst.lock().expect("lock");
    assert_eq!(seen, 30 * 4 * 8, "checked every substep");
    assert!(off <= 1e-12, "a driven particle was {off} m off its driver");
    // Half a second at 3 rad/s: the pins really moved, and so did the cloth below them.
    let t = s.time();
    let p = s.particles();
    assert!(p.positions[0].distance(driver.rest[0]) > 0.1);
    for (k, &i) in driver.particles.iter().enumerate() {
        let expected_v = DVec3::Y.cross(driver.position(k, t) - PIVOT) * driver.omega;
        let dv = p.velocities[i as usize].distance(expected_v);
        assert!(dv <= 1e-12, "particle {i}: velocity off by {dv} m/s");
        assert_eq!(p.inv_masses[i as usize], 0.0);
    }
}

/// The fused frame and the general loop give the same bits with a driver, on 1 and 2 threads.
#[test]
fn driven_pins_run_the_same_fused_and_general() {
    let run = |threads: usize, general: bool| {
        in_pool(threads, || {
            let (b, _) = fusable_flag((40, 40), flag_settings(Method::Xpbd, 200));
            let mut s = b.build();
            assert!(s.runs_fused(), "the fused side really runs fused");
            assert!(s.domain_stats().domains > 1);
            s.add_pin_driver(turntable(&s)).expect("valid driver");
            for _ in 0..20 {
                step(&mut s, general);
            }
            state_bits(&s)
        })
    };
    let fused = run(1, false);
    assert_eq!(fused, run(1, true), "fused vs general");
    assert_eq!(fused, run(2, false), "fused, 2 threads");
    assert_eq!(fused, run(2, true), "general, 2 threads");
}

#[test]
fn bad_drivers_are_refused_and_change_nothing() {
    let (b, _) = windy_flag((8, 8), flag_settings(Method::Xpbd, 128));
    let mut s = b.build();
    let before = state_bits(&s);
    let mut d = Turntable {
        particles: vec![3, 64],
        rest: vec![DVec3::ZERO; 2],
        omega: 1.0,
    };
    assert_eq!(
        s.add_pin_driver(Arc::new(Turntable {
            particles: d.particles.clone(),
            rest: d.rest.clone(),
            omega: 1.0
        }))
        .err(),
        Some(SolverError::NoSuchParticle {
            index: 64,
            count: 64
        })
    );
    d.particles = vec![3, 3];
    assert_eq!(
        s.add_pin_driver(Arc::new(d)).err(),
        Some(SolverError::DrivenTwice { particle: 3 })
    );
    assert_eq!(before, state_bits(&s));
    assert!(s.pin_drivers().is_empty());
}
