//! A procedural walk cycle of our own: a 1.7 m mannequin skeleton walking in place with
//! sinusoidal joint angles, sampled into a looping [`Clip`] so that tests and scenes need no
//! asset.
//!
//! Axes as in BVH: y up, the walker faces +z, its left is +x. A rotation about +x by a
//! positive angle swings a hanging limb backwards (−z).

use std::f64::consts::{PI, TAU};

use glam::{DQuat, DVec3};

use crate::animation::Animation;
use crate::clip::{Clip, Wrap};
use crate::pose::Pose;
use crate::skeleton::{Joint, Skeleton};

/// Duration of one stride (two steps), s.
pub const WALK_PERIOD: f64 = 1.1;

/// How far the arms hang away from the body (rad, about the walker's forward axis): enough
/// for a sleeve and a shirt's side seam to pass between arm and torso.
pub const ABDUCT: f64 = 0.20;

/// Frames in one stride of the built-in clip (40 frames per second).
pub const WALK_FRAMES: usize = 44;

/// (name, parent, offset in m). End sites are named `<parent>_End`, as the BVH reader does.
const JOINTS: [(&str, Option<usize>, [f64; 3]); 24] = [
    ("Hips", None, [0.0, 0.95, 0.0]),
    ("Spine", Some(0), [0.0, 0.10, 0.0]),
    ("Chest", Some(1), [0.0, 0.15, 0.0]),
    ("Neck", Some(2), [0.0, 0.20, 0.0]),
    ("Head", Some(3), [0.0, 0.08, 0.0]),
    ("Head_End", Some(4), [0.0, 0.20, 0.0]),
    ("LeftShoulder", Some(2), [0.03, 0.16, 0.0]),
    ("LeftArm", Some(6), [0.15, 0.0, 0.0]),
    ("LeftForeArm", Some(7), [0.0, -0.28, 0.0]),
    ("LeftHand", Some(8), [0.0, -0.25, 0.0]),
    ("LeftHand_End", Some(9), [0.0, -0.17, 0.0]),
    ("RightShoulder", Some(2), [-0.03, 0.16, 0.0]),
    ("RightArm", Some(11), [-0.15, 0.0, 0.0]),
    ("RightForeArm", Some(12), [0.0, -0.28, 0.0]),
    ("RightHand", Some(13), [0.0, -0.25, 0.0]),
    ("RightHand_End", Some(14), [0.0, -0.17, 0.0]),
    ("LeftUpLeg", Some(0), [0.09, -0.06, 0.0]),
    ("LeftLeg", Some(16), [0.0, -0.42, 0.0]),
    ("LeftFoot", Some(17), [0.0, -0.40, 0.0]),
    ("LeftFoot_End", Some(18), [0.0, -0.03, 0.15]),
    ("RightUpLeg", Some(0), [-0.09, -0.06, 0.0]),
    ("RightLeg", Some(20), [0.0, -0.42, 0.0]),
    ("RightFoot", Some(21), [0.0, -0.40, 0.0]),
    ("RightFoot_End", Some(22), [0.0, -0.03, 0.15]),
];

/// The walker's skeleton: hips, spine, chest, neck, head, shoulders, upper arms, forearms,
/// hands, thighs, shins and feet (plus end sites at the head top, finger tips and toes).
pub fn walker_skeleton() -> Skeleton {
    let joints = JOINTS
        .iter()
        .map(|&(name, parent, offset)| Joint {
            name: name.to_owned(),
            parent,
            offset: DVec3::from_array(offset),
            end_site: name.ends_with("_End"),
        })
        .collect();
    Skeleton::new(joints).expect("the built-in walker skeleton is valid")
}

fn rx(a: f64) -> DQuat {
    DQuat::from_rotation_x(a)
}

/// Angles of one leg and the arm on the same side at phase `p` (rad); the leg is forward at
/// p = π/2, the same-side arm back.
struct Limbs {
    thigh: f64,
    knee: f64,
    ankle: f64,
    arm: f64,
    elbow: f64,
}

fn limbs(p: f64) -> Limbs {
    let thigh = -0.40 * p.sin();
    // Knee flexion peaks in mid-swing (p = 0, thigh passing forward); never hyperextends.
    let knee = 0.30 + 0.28 * p.cos();
    Limbs {
        thigh,
        knee,
        ankle: -0.5 * (thigh + knee) + 0.1 * p.sin(),
        arm: 0.35 * p.sin(),
        elbow: -(0.25 + 0.1 * (1.0 - p.sin())),
    }
}

/// The walker's pose at time `t` (s); periodic with [`WALK_PERIOD`].
pub fn walk_pose(skeleton: &Skeleton, t: f64) -> Pose {
    let p = TAU * t / WALK_PERIOD;
    let mut pose = Pose::identity(skeleton.len());
    let mut set = |name: &str, q: DQuat| {
        if let Some(i) = skeleton.find(name) {
            pose.rotations[i] = q.normalize();
        }
    };
    set("Hips", DQuat::from_rotation_y(0.08 * p.sin()));
    set("Spine", rx(0.03));
    set("Chest", DQuat::from_rotation_y(-0.12 * p.sin()));
    set("Neck", DQuat::from_rotation_y(0.03 * p.sin()));
    set("Head", DQuat::from_rotation_y(0.02 * p.sin()) * rx(-0.03));
    for (side, phase, abduct) in [("Left", p, ABDUCT), ("Right", p + PI, -ABDUCT)] {
        let l = limbs(phase);
        set(&format!("{side}UpLeg"), rx(l.thigh));
        set(&format!("{side}Leg"), rx(l.knee));
        set(&format!("{side}Foot"), rx(l.ankle));
        set(
            &format!("{side}Arm"),
            DQuat::from_rotation_z(abduct) * rx(l.arm),
        );
        set(&format!("{side}ForeArm"), rx(l.elbow));
    }
    // The pelvis bobs twice per stride and sways towards the standing leg.
    pose.translations[0] = DVec3::new(0.02 * p.sin(), 0.015 * (2.0 * p).cos(), 0.0);
    pose
}

/// The walk cycle as a clip: [`WALK_FRAMES`] frames over one [`WALK_PERIOD`] (the frame at
/// t = period is frame 0 again, reached by [`Wrap::Loop`]).
pub fn walk_clip(skeleton: &Skeleton) -> Clip {
    let dt = WALK_PERIOD / WALK_FRAMES as f64;
    let frames = (0..WALK_FRAMES)
        .map(|k| walk_pose(skeleton, k as f64 * dt))
        .collect();
    Clip::new(dt, frames, skeleton.len()).expect("the built-in walk clip is valid")
}

/// The walker skeleton playing its looping walk cycle.
pub fn walk_cycle() -> Animation {
    let skeleton = walker_skeleton();
    let clip = walk_clip(&skeleton);
    Animation::new(skeleton, clip, Wrap::Loop).expect("walk clip matches its skeleton")
}
