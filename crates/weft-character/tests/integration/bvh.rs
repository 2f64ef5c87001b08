//! The BVH reader: a hand-computed three-joint pose, and malformed files with their lines.

use crate::common;

use common::TINY_BVH as TINY;
use glam::DVec3;
use weft_character::files::{LoadError, read_bvh};
use weft_character::{BvhError, BvhOptions, parse_bvh};

fn cm() -> BvhOptions {
    BvhOptions { scale: 0.01 }
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

#[test]
fn tiny_hierarchy_reads_names_parents_offsets_and_channels() {
    let bvh = parse_bvh(TINY, &cm()).expect("valid BVH");
    let names: Vec<_> = bvh
        .skeleton
        .joints()
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    assert_eq!(names, ["Root", "Mid", "Tip", "Tip_End"]);
    let parents: Vec<_> = bvh.skeleton.joints().iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(1), Some(2)]);
    assert!(bvh.skeleton.joints()[3].end_site);
    assert!(close(
        bvh.skeleton.joints()[1].offset,
        DVec3::new(0.0, 0.1, 0.0)
    ));
    assert_eq!(
        bvh.channels.iter().map(Vec::len).collect::<Vec<_>>(),
        [6, 3, 2, 0]
    );
    assert_eq!(bvh.clip.frame_count(), 2);
    assert_eq!(bvh.clip.frame_time(), 0.5);
}

#[test]
fn joint_world_positions_match_the_hand_computed_pose() {
    let bvh = parse_bvh(TINY, &cm()).expect("valid BVH");
    let rest = bvh.skeleton.world_positions(&bvh.clip.frames()[0]);
    let expected_rest = [
        DVec3::ZERO,
        DVec3::new(0.0, 0.1, 0.0),
        DVec3::new(0.05, 0.1, 0.0),
        DVec3::new(0.05, 0.1, 0.03),
    ];
    for (got, want) in rest.iter().zip(expected_rest) {
        assert!(close(*got, want), "rest: {got} vs {want}");
    }
    // Frame 1 by hand, with the active rotations
    //   Rx(90°): (x, y, z) → (x, −z, y),  Ry(90°): (x, y, z) → (z, y, −x),
    //   Rz(90°): (x, y, z) → (−y, x, z).
    // Root: t = (1, 2, 3) m, R_root = Rz Rx (channel order Z, X, Y; Y = 0).
    // Mid:  R_mid = Ry (Y = 90).  Tip: R_tip = Rx (X = 90).
    // Mid = t + Rz Rx (0, 0.1, 0) = t + Rz (0, 0, 0.1) = (1, 2, 3.1).
    // Tip = Mid + Rz Rx Ry (0.05, 0, 0) = Mid + Rz Rx (0, 0, −0.05) = Mid + Rz (0, 0.05, 0)
    //     = Mid + (−0.05, 0, 0) = (0.95, 2, 3.1).
    // End = Tip + Rz Rx Ry Rx (0, 0, 0.03) = Tip + Rz Rx Ry (0, −0.03, 0)
    //     = Tip + Rz Rx (0, −0.03, 0) = Tip + Rz (0, 0, −0.03) = (0.95, 2, 3.07).
    let posed = bvh.skeleton.world_positions(&bvh.clip.frames()[1]);
    let expected = [
        DVec3::new(1.0, 2.0, 3.0),
        DVec3::new(1.0, 2.0, 3.1),
        DVec3::new(0.95, 2.0, 3.1),
        DVec3::new(0.95, 2.0, 3.07),
    ];
    for (k, (got, want)) in posed.iter().zip(expected).enumerate() {
        assert!(close(*got, want), "joint {k}: {got} vs {want}");
    }
}

#[test]
fn scale_multiplies_offsets_and_positions() {
    let metres = parse_bvh(TINY, &BvhOptions { scale: 1.0 }).expect("valid BVH");
    let posed = metres.skeleton.world_positions(&metres.clip.frames()[1]);
    assert!(
        close(posed[3], DVec3::new(95.0, 200.0, 307.0)),
        "{}",
        posed[3]
    );
    for scale in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            parse_bvh(TINY, &BvhOptions { scale }),
            Err(BvhError::Scale(_))
        ));
    }
}

/// `TINY` with `from` replaced by `to` (which must occur exactly once).
fn edit(from: &str, to: &str) -> String {
    assert_eq!(TINY.matches(from).count(), 1, "`{from}` must occur once");
    TINY.replacen(from, to, 1)
}

fn error_of(text: &str) -> BvhError {
    match parse_bvh(text, &cm()) {
        Ok(_) => panic!("malformed BVH accepted:\n{text}"),
        Err(e) => e,
    }
}

#[test]
fn truncated_files_name_where_they_end() {
    let cut = &TINY[..TINY.find("OFFSET 0 10").expect("fixture") + "OFFSET 0 10".len()];
    assert_eq!(
        error_of(cut),
        BvhError::Truncated {
            line: 8,
            expected: "a number"
        }
    );
    let no_close = &TINY[..TINY.find("MOTION").expect("fixture")];
    let e = error_of(no_close.trim_end().trim_end_matches('}'));
    assert_eq!(
        e,
        BvhError::MissingBrace {
            line: 2,
            joint: "Root".into()
        }
    );
    let one_frame = TINY.lines().take(24).collect::<Vec<_>>().join("\n");
    assert_eq!(
        error_of(&one_frame),
        BvhError::MissingFrames {
            line: 24,
            found: 1,
            expected: 2
        }
    );
}

#[test]
fn a_frame_with_the_wrong_number_of_values_is_rejected() {
    let e = error_of(&edit("300 90 90 0 90 0 0 90 0", "300 90 90 0 90 0 0 90"));
    assert_eq!(
        e,
        BvhError::FrameValues {
            line: 25,
            frame: 1,
            found: 10,
            expected: 11
        }
    );
    assert!(e.to_string().starts_with("line 25:"), "{e}");
    let e = error_of(&format!("{TINY}0 0 0 0 0 0 0 0 0 0 0\n"));
    assert_eq!(
        e,
        BvhError::ExtraData {
            line: 26,
            frames: 2
        }
    );
}

#[test]
fn unknown_repeated_and_miscounted_channels_are_rejected() {
    assert_eq!(
        error_of(&edit("2 Xrotation Zrotation", "2 Xrotation Wrotation")),
        BvhError::UnknownChannel {
            line: 13,
            name: "Wrotation".into()
        }
    );
    assert_eq!(
        error_of(&edit("2 Xrotation Zrotation", "2 Xrotation Xrotation")),
        BvhError::RepeatedChannel {
            line: 13,
            name: "Xrotation".into()
        }
    );
    assert!(matches!(
        error_of(&edit("2 Xrotation Zrotation", "3 Xrotation Zrotation")),
        BvhError::Expected { line: 13, .. }
    ));
    assert_eq!(
        error_of(&edit("CHANNELS 2 X", "CHANNELS two X")),
        BvhError::NotACount {
            line: 13,
            token: "two".into()
        }
    );
}

#[test]
fn non_numeric_values_are_rejected_with_their_line() {
    assert_eq!(
        error_of(&edit("OFFSET 5 0 0", "OFFSET 5 zero 0")),
        BvhError::NotANumber {
            line: 12,
            token: "zero".into()
        }
    );
    assert_eq!(
        error_of(&edit("100 200", "100 x200")),
        BvhError::NotANumber {
            line: 25,
            token: "x200".into()
        }
    );
    assert_eq!(
        error_of(&edit("100 200", "100 nan")),
        BvhError::NotANumber {
            line: 25,
            token: "nan".into()
        }
    );
}

#[test]
fn missing_braces_are_rejected() {
    let no_open = edit("JOINT Mid\n  {\n", "JOINT Mid\n");
    assert_eq!(
        error_of(&no_open),
        BvhError::Expected {
            line: 7,
            expected: "`{`",
            found: "OFFSET".into()
        }
    );
    // Drop Tip's closing brace: Root's block then swallows MOTION.
    let no_close = edit("    }\n  }\n}\nMOTION", "  }\n}\nMOTION");
    assert_eq!(
        error_of(&no_close),
        BvhError::MissingBrace {
            line: 2,
            joint: "Root".into()
        }
    );
    let end_site_open = edit("      }\n    }\n  }\n}", "    }\n  }\n}");
    assert!(
        matches!(error_of(&end_site_open), BvhError::MissingBrace { .. }),
        "{:?}",
        error_of(&end_site_open)
    );
}

#[test]
fn zero_frames_and_bad_frame_times_are_rejected() {
    assert_eq!(
        error_of(&edit("Frames: 2", "Frames: 0")),
        BvhError::ZeroFrames { line: 22 }
    );
    assert_eq!(
        error_of(&edit("Frame Time: 0.5", "Frame Time: -0.5")),
        BvhError::FrameTime {
            line: 23,
            value: -0.5
        }
    );
    assert_eq!(
        error_of(&edit("Frame Time: 0.5", "Frame Time: 0")),
        BvhError::FrameTime {
            line: 23,
            value: 0.0
        }
    );
    assert_eq!(
        error_of(&edit("Frames: 2", "Frames: -2")),
        BvhError::NotACount {
            line: 22,
            token: "-2".into()
        }
    );
}

#[test]
fn duplicate_joint_names_are_rejected() {
    assert_eq!(
        error_of(&edit("JOINT Tip", "JOINT Mid")),
        BvhError::DuplicateJoint {
            line: 10,
            name: "Mid".into()
        }
    );
}

#[test]
fn crlf_line_ends_and_leading_dot_numbers_read() {
    let text = edit("Frame Time: 0.5", "Frame Time: .5").replace('\n', "\r\n");
    let bvh = parse_bvh(&text, &cm()).expect("CRLF BVH");
    assert_eq!(bvh.clip.frame_time(), 0.5);
}

#[test]
fn file_errors_name_the_file_and_the_line() {
    let dir = std::env::temp_dir().join(format!("weft-character-bvh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bad = dir.join("bad.bvh");
    std::fs::write(&bad, edit("2 Xrotation Zrotation", "2 Xrotation Wrotation")).expect("write");
    let e = read_bvh(&bad, &cm()).expect_err("bad file accepted");
    assert!(matches!(e, LoadError::Bvh { .. }));
    let msg = e.to_string();
    assert!(msg.contains("bad.bvh") && msg.contains("line 13"), "{msg}");
    let missing = read_bvh(&dir.join("missing.bvh"), &cm()).expect_err("missing file");
    assert!(matches!(missing, LoadError::Io { .. }), "{missing}");
    assert!(missing.to_string().contains("missing.bvh"));
    let good = dir.join("good.bvh");
    std::fs::write(&good, TINY).expect("write");
    assert_eq!(read_bvh(&good, &cm()).expect("good file").skeleton.len(), 4);
    std::fs::remove_dir_all(&dir).ok();
}

/// A chain of `depth` joints below the root, each with one rotation channel, one frame.
fn chain(depth: usize) -> String {
    let mut text = String::from("HIERARCHY\nROOT J0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n");
    for k in 1..=depth {
        text += &format!("JOINT J{k}\n{{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n");
    }
    text += &"}\n".repeat(depth + 1);
    text += &format!(
        "MOTION\nFrames: 1\nFrame Time: 0.1\n{}\n",
        "0 ".repeat(depth + 1)
    );
    text
}

#[test]
fn declared_frame_counts_and_nesting_cannot_exhaust_memory_or_the_stack() {
    // A count the file cannot hold is an error, not an allocation of that many frames.
    for frames in ["4000000000", "18446744073709551615"] {
        assert_eq!(
            error_of(&edit("Frames: 2", &format!("Frames: {frames}"))),
            BvhError::MissingFrames {
                line: 25,
                found: 2,
                expected: frames.parse().expect("a count")
            }
        );
    }
    let deep = parse_bvh(&chain(200), &cm()).expect("200 levels read");
    assert_eq!(deep.skeleton.len(), 201);
    let limit = weft_character::bvh::MAX_JOINT_DEPTH;
    assert_eq!(
        error_of(&chain(20_000)),
        BvhError::TooDeep {
            line: 2 + 4 * (limit + 1),
            limit
        }
    );
}
