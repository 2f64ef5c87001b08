//! The self-collision profile counters: each part is timed when it runs, and the parts add
//! up to no more than the time spent inside self-collision.

use std::time::Duration;

use weft_collide::SelfCollisionTimes;
use weft_collide::scenarios::self_fold;
use weft_solver::Method;

use crate::common;
use common::split::Split;

#[test]
fn each_part_is_timed_when_it_runs_and_the_parts_fit_in_the_time_inside() {
    let (mut solver, colliders) = self_fold(Method::Xpbd, 10, 30).expect("scenario");
    let mut hook = Split::new(&solver, colliders, Default::default()).expect("self-collision");
    assert_eq!(
        hook.own.self_collision_times(),
        Some(SelfCollisionTimes::default()),
        "nothing is timed before the first step"
    );
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
    // The total covers every part, each once.
    assert_eq!(
        t.total(),
        t.check + t.rebuild + t.reanchor + t.find + t.apply
    );
    // A part counted twice (a rebuild inside a check, say) would exceed the time inside.
    assert!(
        t.total() <= hook.spent,
        "the parts ({:?}: {t:?}) exceed the time inside self-collision ({:?})",
        t.total(),
        hook.spent
    );
}

#[test]
fn a_world_without_self_collision_has_no_times() {
    let (_, mut world) = self_fold(Method::Xpbd, 4, 4).expect("scenario");
    world.disable_self_collision();
    assert_eq!(world.self_collision_times(), None);
}
