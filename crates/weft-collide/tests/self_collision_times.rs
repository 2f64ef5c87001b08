//! The self-collision profile counters: each part is timed when it runs, and the parts add
//! up to no more than the time spent inside self-collision.

use std::time::{Duration, Instant};

use weft_collide::scenarios::self_fold;
use weft_collide::{CollisionWorld, SelfCollisionParams, SelfCollisionTimes};
use weft_solver::{Method, Particles, SubstepContext, SubstepHook};

/// A world holding only self-collision, timed from outside, then the scene's colliders.
struct Timed {
    own: CollisionWorld,
    colliders: CollisionWorld,
    inside: Duration,
}

impl SubstepHook for Timed {
    fn begin_substep(&mut self, ctx: &SubstepContext, p: &Particles) {
        let start = Instant::now();
        self.own.begin_substep(ctx, p);
        self.inside += start.elapsed();
        self.colliders.begin_substep(ctx, p);
    }

    fn project(&mut self, ctx: &SubstepContext, p: &mut Particles) -> usize {
        let start = Instant::now();
        let own = self.own.project(ctx, p);
        self.inside += start.elapsed();
        own + self.colliders.project(ctx, p)
    }

    fn end_substep(&mut self, ctx: &SubstepContext, p: &mut Particles) {
        let start = Instant::now();
        self.own.end_substep(ctx, p);
        self.inside += start.elapsed();
        self.colliders.end_substep(ctx, p);
    }
}

#[test]
fn each_part_is_timed_when_it_runs_and_the_parts_fit_in_the_time_inside() {
    let (mut solver, mut colliders) = self_fold(Method::Xpbd, 10, 30).expect("scenario");
    colliders.disable_self_collision();
    let mut own = CollisionWorld::new(&solver);
    own.enable_self_collision(&solver, &[0], SelfCollisionParams::default())
        .expect("self-collision");
    assert_eq!(
        own.self_collision_times(),
        Some(SelfCollisionTimes::default()),
        "nothing is timed before the first step"
    );
    let mut hook = Timed {
        own,
        colliders,
        inside: Duration::ZERO,
    };
    // Step until the fold has rebuilt its list, re-anchored movers and found contacts.
    for _ in 0..600 {
        solver.step_with(&mut hook).expect("step");
        let (rebuilds, updates, _) = hook.own.self_collision_lists().expect("on");
        if rebuilds > 1 && updates > 0 && hook.own.stats().self_contacts > 0 {
            break;
        }
    }
    let (rebuilds, updates, _) = hook.own.self_collision_lists().expect("on");
    assert!(
        rebuilds > 1 && updates > 0,
        "the fold never rebuilt and re-anchored ({rebuilds}, {updates})"
    );
    let t = hook.own.self_collision_times().expect("on");
    for (part, time) in [
        ("check", t.check),
        ("rebuild", t.rebuild),
        ("reanchor", t.reanchor),
        ("find", t.find),
        ("apply", t.apply),
    ] {
        assert!(time > Duration::ZERO, "{part} ran but was not timed: {t:?}");
    }
    assert_eq!(t.total(), t.upkeep() + t.sweep());
    // A part counted twice (a rebuild inside a check, say) would exceed the time inside.
    assert!(
        t.total() <= hook.inside,
        "the parts ({:?}: {t:?}) exceed the time inside self-collision ({:?})",
        t.total(),
        hook.inside
    );
}

#[test]
fn a_world_without_self_collision_has_no_times() {
    let (_, mut world) = self_fold(Method::Xpbd, 4, 4).expect("scenario");
    world.disable_self_collision();
    assert_eq!(world.self_collision_times(), None);
}
