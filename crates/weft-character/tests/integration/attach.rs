//! Cloth vertices attached to a bone follow it exactly.

use glam::DVec3;
use weft_character::{AttachError, Attachment, Character};

#[test]
fn attached_vertices_follow_their_bone_to_a_nanometre() {
    let walker = Character::walker();
    let skel = walker.animation().skeleton();
    let hand = skel.find("LeftHand").expect("bone");
    let tip = skel.find("LeftHand_End").expect("end site");
    let hips = skel.find("Hips").expect("bone");
    let t0 = 0.0;
    let bind = walker.animation().world(t0);
    // A cuff vertex at the finger tip, a waistband around the hips.
    let mut cloth = vec![bind[tip].translation];
    for k in 0..12 {
        let a = std::f64::consts::TAU * k as f64 / 12.0;
        cloth.push(bind[hips].translation + DVec3::new(0.17 * a.cos(), -0.05, 0.13 * a.sin()));
    }
    let cuff = Attachment::bind(hand, vec![0], &cloth, &bind[hand]).expect("bind");
    let band_vertices: Vec<u32> = (1..13).collect();
    let band = Attachment::bind(hips, band_vertices, &cloth, &bind[hips]).expect("bind");
    let rest: Vec<f64> = (1..13)
        .map(|i| (cloth[i] - bind[hips].translation).length())
        .collect();
    for k in 1..60 {
        let t = k as f64 * 0.037;
        let world = walker.animation().world(t);
        // The cuff sits where forward kinematics puts the finger tip, a child of the hand.
        let cuff_at = cuff.positions(&world[hand])[0];
        assert!(
            (cuff_at - world[tip].translation).length() < 1e-9,
            "cuff at {t}"
        );
        let band_at = band.positions(&world[hips]);
        for (p, r) in band_at.iter().zip(&rest) {
            assert!(((*p - world[hips].translation).length() - r).abs() < 1e-9);
        }
        // The hand moved: the test is not comparing a still pose with itself.
        if k == 10 {
            assert!((cuff_at - cloth[0]).length() > 0.05);
        }
    }
}

#[test]
fn attached_velocities_match_finite_differences() {
    let walker = Character::walker();
    let skel = walker.animation().skeleton();
    let shin = skel.find("RightLeg").expect("bone");
    let bind = walker.animation().world(0.0);
    let cloth = vec![
        bind[shin].translation + DVec3::new(0.06, -0.1, 0.0),
        bind[shin].translation + DVec3::new(-0.05, -0.2, 0.03),
    ];
    let att = Attachment::bind(shin, vec![0, 1], &cloth, &bind[shin]).expect("bind");
    let t = 0.33;
    let delta = 1e-5;
    let bones = walker.animation().bones(t);
    let v = att.velocities(&bones[shin]);
    let before = att.positions(&walker.animation().world(t - delta)[shin]);
    let after = att.positions(&walker.animation().world(t + delta)[shin]);
    for i in 0..2 {
        let fd = (after[i] - before[i]) / (2.0 * delta);
        assert!(
            (v[i] - fd).length() < 1e-6 * (1.0 + fd.length()),
            "{} vs {fd}",
            v[i]
        );
        assert!(fd.length() > 0.05, "the shin should move");
    }
}

#[test]
fn bad_attachments_are_rejected() {
    let walker = Character::walker();
    let bind = walker.animation().world(0.0);
    let cloth = vec![DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)];
    assert_eq!(
        Attachment::bind(0, vec![2], &cloth, &bind[0]),
        Err(AttachError::VertexOutOfRange { vertex: 2, len: 2 })
    );
    assert_eq!(
        Attachment::bind(0, vec![1], &cloth, &bind[0]),
        Err(AttachError::NonFinite { vertex: 1 })
    );
    let ok = Attachment::bind(99, vec![0], &cloth, &bind[0]).expect("bind");
    assert!(ok.check_bone(walker.animation().skeleton().len()).is_err());
}
