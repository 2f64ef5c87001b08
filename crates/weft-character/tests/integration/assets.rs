//! The shipped motion-capture clip: it parses, stays human-sized, and the CMU body fits it.

use std::path::PathBuf;

use glam::DVec3;
use weft_character::files::read_bvh;
use weft_character::{Animation, BodyTable, BvhOptions, CMU_SCALE, Character, Wrap};

fn shipped() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters/cmu_01_01_4s.bvh")
}

fn cmu_animation() -> Animation {
    let bvh = read_bvh(&shipped(), &BvhOptions { scale: CMU_SCALE }).expect("shipped clip");
    Animation::from_bvh(bvh, Wrap::Clamp)
}

#[test]
fn the_shipped_clip_parses_with_its_expected_shape() {
    let anim = cmu_animation();
    assert_eq!(anim.clip().frame_count(), 240);
    assert!((anim.clip().frame_time() - 1.0 / 60.0).abs() < 1e-6);
    assert!((anim.duration() - 239.0 / 60.0).abs() < 1e-4);
    // 31 joints with channels and 7 end sites (toes, head, fingers, thumbs).
    assert_eq!(anim.skeleton().len(), 38);
    assert_eq!(
        anim.skeleton()
            .joints()
            .iter()
            .filter(|j| j.end_site)
            .count(),
        7
    );
}

#[test]
fn joints_stay_within_a_human_sized_box_over_the_clip() {
    let anim = cmu_animation();
    let skel = anim.skeleton();
    let head = skel.find("Head_End").expect("head");
    let (lf, rf) = (
        skel.find("LeftToeBase").expect("toe"),
        skel.find("RightToeBase").expect("toe"),
    );
    let mut travel_lo = DVec3::splat(f64::INFINITY);
    let mut travel_hi = DVec3::splat(f64::NEG_INFINITY);
    let steps = 4 * 240;
    for k in 0..=steps {
        let t = anim.duration() * k as f64 / steps as f64;
        let p = skel.world_positions(&anim.pose(t));
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for q in &p {
            lo = lo.min(*q);
            hi = hi.max(*q);
        }
        // One person: never taller than 2.2 m, never wider than an arm span, never below
        // the floor by more than a few centimetres, the head above the toes.
        let size = hi - lo;
        assert!(
            size.y < 2.2 && size.x < 2.0 && size.z < 2.0,
            "at {t}: extent {size}"
        );
        assert!(lo.y > -0.05, "at {t}: lowest joint {}", lo.y);
        assert!(
            p[head].y - p[lf].y.min(p[rf].y) > 1.0,
            "at {t}: head over toes"
        );
        travel_lo = travel_lo.min(p[0]);
        travel_hi = travel_hi.max(p[0]);
    }
    // A standing subject 1.5–1.9 m tall in the first frame.
    let first = skel.world_positions(&anim.pose(0.0));
    let height = first[head].y - first.iter().map(|q| q.y).fold(f64::INFINITY, f64::min);
    assert!(height > 1.4 && height < 1.9, "standing height {height} m");
    // The clip jumps forward: the hips travel more than a metre along z.
    assert!(
        travel_hi.z - travel_lo.z > 1.0,
        "hips travel {travel_lo} .. {travel_hi}"
    );
}

#[test]
fn the_cmu_body_fits_the_shipped_skeleton_and_holds_its_spine() {
    let character = Character::new(cmu_animation(), &BodyTable::cmu()).expect("CMU body");
    assert_eq!(character.body().shapes().len(), 25);
    let skel = character.animation().skeleton();
    let inner = [
        "Hips", "Spine", "Spine1", "Neck1", "Head", "LeftArm", "RightLeg", "LeftHand",
    ];
    for k in 0..20 {
        let state = character.state(k as f64 * 0.2);
        for name in inner {
            let p = state.bones[skel.find(name).expect("joint")]
                .transform
                .translation;
            assert!(
                state.signed_distance(p) < 0.0,
                "{name} outside the body at frame {k}"
            );
        }
    }
}
