//! The built-in walk cycle: its bones, its loop, its gait and its size.

use glam::DVec3;
use weft_character::walk::walk_pose;
use weft_character::{WALK_FRAMES, WALK_PERIOD, Wrap, walk_cycle};

#[test]
fn the_walker_has_the_bones_a_garment_needs() {
    let anim = walk_cycle();
    for name in [
        "Hips",
        "Spine",
        "Chest",
        "Neck",
        "Head",
        "LeftShoulder",
        "RightShoulder",
        "LeftArm",
        "RightArm",
        "LeftForeArm",
        "RightForeArm",
        "LeftHand",
        "RightHand",
        "LeftUpLeg",
        "RightUpLeg",
        "LeftLeg",
        "RightLeg",
        "LeftFoot",
        "RightFoot",
    ] {
        assert!(anim.skeleton().find(name).is_some(), "no bone {name}");
    }
    assert_eq!(anim.wrap(), Wrap::Loop);
    assert_eq!(anim.clip().frame_count(), WALK_FRAMES);
    assert!((anim.duration() - WALK_PERIOD).abs() < 1e-12);
}

/// The sampled, looping clip follows the analytic cycle everywhere, including across the
/// wrap from the last frame back to the first: it loops without a jump or a stall.
#[test]
fn the_clip_follows_the_analytic_cycle_across_the_loop() {
    let anim = walk_cycle();
    let skel = anim.skeleton();
    let mut worst: f64 = 0.0;
    let steps = 997;
    for k in 0..=2 * steps {
        let t = k as f64 * 2.0 * WALK_PERIOD / steps as f64;
        let sampled = skel.world_positions(&anim.pose(t));
        let exact = skel.world_positions(&walk_pose(skel, t));
        for (a, b) in sampled.iter().zip(&exact) {
            worst = worst.max((*a - *b).length());
        }
    }
    // Interpolating 44 frames of a 1.1 s cycle: chord error well under a centimetre.
    assert!(worst < 5e-3, "sampled vs analytic: {worst} m");
    let start = skel.world_positions(&walk_pose(skel, 0.0));
    let period = skel.world_positions(&walk_pose(skel, WALK_PERIOD));
    for (a, b) in start.iter().zip(&period) {
        assert!(
            (*a - *b).length() < 1e-12,
            "the analytic cycle is not periodic"
        );
    }
}

#[test]
fn legs_alternate_and_arms_swing_against_them() {
    let anim = walk_cycle();
    let skel = anim.skeleton();
    let at =
        |name: &str, t: f64| skel.world_positions(&anim.pose(t))[skel.find(name).expect("bone")];
    let quarter = WALK_PERIOD / 4.0;
    for (t, sign) in [(quarter, 1.0), (3.0 * quarter, -1.0)] {
        let feet = at("LeftFoot", t).z - at("RightFoot", t).z;
        let hands = at("LeftHand", t).z - at("RightHand", t).z;
        assert!(sign * feet > 0.3, "feet at {t}: left − right = {feet}");
        assert!(sign * hands < -0.2, "hands at {t}: left − right = {hands}");
    }
}

#[test]
fn the_walker_stays_human_sized_and_on_the_ground() {
    let anim = walk_cycle();
    let skel = anim.skeleton();
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for k in 0..200 {
        for p in skel.world_positions(&anim.pose(k as f64 * WALK_PERIOD / 200.0)) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    assert!(hi.y > 1.6 && hi.y < 1.8, "head top at {}", hi.y);
    assert!(lo.y > -0.01 && lo.y < 0.1, "lowest joint at {}", lo.y);
    assert!(hi.x - lo.x < 0.7 && hi.z - lo.z < 1.0, "box {lo} .. {hi}");
}
