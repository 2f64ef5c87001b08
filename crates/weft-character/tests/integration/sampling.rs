//! Sampling a clip between frames, and bone velocities against finite differences.

use crate::common;

use common::TINY_BVH as TINY;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{DQuat, DVec3};
use weft_character::{Animation, BvhOptions, Clip, Pose, VELOCITY_STEP, Wrap, parse_bvh};

fn tiny(wrap: Wrap) -> Animation {
    let bvh = parse_bvh(TINY, &BvhOptions { scale: 0.01 }).expect("valid BVH");
    Animation::from_bvh(bvh, wrap)
}

fn same_rotation(a: DQuat, b: DQuat) -> bool {
    a.dot(b).abs() > 1.0 - 1e-12
}

fn same_pose(a: &Pose, b: &Pose) -> bool {
    a.translations
        .iter()
        .zip(&b.translations)
        .all(|(x, y)| (*x - *y).length() < 1e-12)
        && a.rotations
            .iter()
            .zip(&b.rotations)
            .all(|(x, y)| same_rotation(*x, *y))
}

/// A clip of `n` frames at 120 fps whose joint 1 turns 7° about a tilted axis per frame and
/// whose root moves on a parabola.
fn turning_clip(n: usize) -> Clip {
    let axis = DVec3::new(0.3, 1.0, -0.5).normalize();
    let frames = (0..n)
        .map(|k| {
            let k = k as f64;
            let mut p = Pose::identity(3);
            p.translations[0] = DVec3::new(0.01 * k, 0.002 * k * k, -0.005 * k);
            p.rotations[0] = DQuat::from_rotation_y(0.03 * k);
            p.rotations[1] = DQuat::from_axis_angle(axis, (7.0 * k).to_radians());
            p.rotations[2] = DQuat::from_rotation_x(0.002 * k * k);
            p
        })
        .collect();
    Clip::new(1.0 / 120.0, frames, 3).expect("valid clip")
}

#[test]
fn sampling_at_a_frame_time_gives_that_frame() {
    let clip = turning_clip(40);
    for wrap in [Wrap::Clamp, Wrap::Loop] {
        for (k, frame) in clip.frames().iter().enumerate() {
            let t = k as f64 / 120.0;
            assert!(
                same_pose(&clip.sample(t, wrap), frame),
                "frame {k}, {wrap:?}"
            );
        }
    }
}

#[test]
fn halfway_between_a_90_degree_turn_is_45_degrees() {
    let anim = tiny(Wrap::Clamp);
    let half = anim.pose(0.25);
    assert!(same_rotation(
        half.rotations[1],
        DQuat::from_rotation_y(FRAC_PI_4)
    ));
    assert!((half.root_translation() - DVec3::new(0.5, 1.0, 1.5)).length() < 1e-12);
    // The root turns 120° about (1, 1, 1)/√3 (R_z(90°) R_x(90°)); halfway is 60°.
    let axis = DVec3::ONE.normalize();
    assert!(same_rotation(
        half.rotations[0],
        DQuat::from_axis_angle(axis, PI / 3.0)
    ));
    let quarter = anim.pose(0.125);
    assert!(same_rotation(
        quarter.rotations[1],
        DQuat::from_rotation_y(FRAC_PI_2 / 4.0)
    ));
}

#[test]
fn clamp_holds_the_ends_and_loop_wraps_through_the_first_frame() {
    let clamp = tiny(Wrap::Clamp);
    let frames = clamp.clip().frames();
    assert_eq!(clamp.duration(), 0.5);
    assert!(same_pose(&clamp.pose(-3.0), &frames[0]));
    assert!(same_pose(&clamp.pose(7.0), &frames[1]));
    let looped = tiny(Wrap::Loop);
    assert_eq!(looped.duration(), 1.0);
    // Period 1 s: 0.75 s lies halfway from the last frame back to the first.
    let back = looped.pose(0.75);
    assert!(same_rotation(
        back.rotations[1],
        DQuat::from_rotation_y(FRAC_PI_4)
    ));
    assert!(same_pose(&looped.pose(3.25), &looped.pose(0.25)));
    assert!(same_pose(&looped.pose(-0.75), &looped.pose(0.25)));
}

#[test]
fn root_velocities_match_the_analytic_rates_of_the_tiny_clip() {
    let anim = tiny(Wrap::Clamp);
    let bones = anim.bones(0.2);
    // Root: (1, 2, 3) m in 0.5 s; 120° about (1, 1, 1)/√3 in 0.5 s.
    assert!((bones[0].linear - DVec3::new(2.0, 4.0, 6.0)).length() < 1e-8);
    let omega = DVec3::ONE.normalize() * (2.0 * PI / 3.0 / 0.5);
    assert!(
        (bones[0].angular - omega).length() < 1e-8,
        "{} vs {omega}",
        bones[0].angular
    );
    // At the clamped ends the pose is held: velocities vanish past the end.
    for t in [2.0, 0.5 + 0.5 * VELOCITY_STEP, -0.5 * VELOCITY_STEP] {
        let held = anim.bones(t);
        assert!(
            held.iter()
                .all(|b| b.linear == DVec3::ZERO && b.angular == DVec3::ZERO),
            "moving at {t}"
        );
    }
}

#[test]
fn bone_velocities_match_finite_differences_of_positions() {
    let skeleton = weft_character::Skeleton::new(vec![
        weft_character::Joint {
            name: "a".into(),
            parent: None,
            offset: DVec3::ZERO,
            end_site: false,
        },
        weft_character::Joint {
            name: "b".into(),
            parent: Some(0),
            offset: DVec3::new(0.0, 0.4, 0.1),
            end_site: false,
        },
        weft_character::Joint {
            name: "c".into(),
            parent: Some(1),
            offset: DVec3::new(0.3, 0.0, 0.0),
            end_site: false,
        },
    ])
    .expect("skeleton");
    let anim = Animation::new(skeleton, turning_clip(40), Wrap::Clamp).expect("animation");
    // A point fixed in each bone's frame, off the joint, so ω × r matters.
    let local = DVec3::new(0.2, -0.15, 0.35);
    let delta = 2e-5;
    for t in [0.0123, 0.1041, 0.2222] {
        let bones = anim.bones(t);
        let before = anim.world(t - delta);
        let after = anim.world(t + delta);
        for (i, bone) in bones.iter().enumerate() {
            let fd = (after[i].translation - before[i].translation) / (2.0 * delta);
            assert!(
                (bone.linear - fd).length() < 1e-6 * (1.0 + fd.length()),
                "bone {i} at {t}: {} vs {fd}",
                bone.linear
            );
            let p = bone.transform.transform_point(local);
            let fd_point = (after[i].transform_point(local) - before[i].transform_point(local))
                / (2.0 * delta);
            let v = bone.point_velocity(p);
            assert!(
                (v - fd_point).length() < 1e-6 * (1.0 + fd_point.length()),
                "point on bone {i} at {t}: {v} vs {fd_point}"
            );
        }
        // The child's rotation adds to its parent's: ω grows down the chain.
        assert!(bones[2].angular.length() > bones[0].angular.length());
    }
}
