//! Linear blend skinning of the glTF simple_skin fixture against positions worked out by hand.

use std::path::PathBuf;

use glam::{DQuat, DVec3};
use weft_character::files::{LoadError, read_skinned_gltf};
use weft_character::skin::{SkinError, SkinnedMesh, parse_gltf_slice};

fn fixture() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters/simple_skin.gltf")
}

fn mesh() -> SkinnedMesh {
    read_skinned_gltf(&fixture()).expect("simple_skin.gltf")
}

/// The fixture by hand: 10 vertices at x ∈ {0, 1}, y ∈ {0, 0.5, 1, 1.5, 2}; joint 0 is node 1
/// (translation (0, 1, 0)), joint 1 is its child node 2, rotated about z by the animation;
/// both inverse bind matrices translate by (−0.5, −1, 0); the weight of joint 1 is y / 2.
/// So M₀ v = v − (0.5, 0, 0) and M₁ v = (0, 1, 0) + R_z(θ) (v − (0.5, 1, 0)), and the
/// skinned vertex is (1 − w) M₀ v + w M₁ v.
fn by_hand(theta: f64) -> Vec<DVec3> {
    let r = DQuat::from_rotation_z(theta);
    let mut out = Vec::new();
    for row in 0..5 {
        for col in 0..2 {
            let v = DVec3::new(col as f64, 0.5 * row as f64, 0.0);
            let w = v.y / 2.0;
            let m0 = v - DVec3::new(0.5, 0.0, 0.0);
            let m1 = DVec3::Y + r * (v - DVec3::new(0.5, 1.0, 0.0));
            out.push(m0 * (1.0 - w) + m1 * w);
        }
    }
    out
}

fn assert_close(got: &[DVec3], want: &[DVec3], what: &str) {
    assert_eq!(got.len(), want.len());
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((*g - *w).length() < 1e-9, "{what}, vertex {k}: {g} vs {w}");
    }
}

#[test]
fn the_fixture_reads_with_its_skin_and_animation() {
    let m = mesh();
    assert_eq!(m.positions.len(), 10);
    assert_eq!(m.triangles.len(), 8);
    assert_eq!(m.joints, vec![1, 2]);
    assert_eq!(m.channels.len(), 1);
    assert!((m.duration() - 5.5).abs() < 1e-12);
}

#[test]
fn skinned_vertices_at_key_frames_match_the_hand_computation() {
    let m = mesh();
    use std::f64::consts::FRAC_PI_2;
    assert_close(&m.skin(0.0), &by_hand(0.0), "t = 0 (rest)");
    assert_close(&m.skin(1.0), &by_hand(FRAC_PI_2), "t = 1 (90°)");
    assert_close(&m.skin(4.0), &by_hand(-FRAC_PI_2), "t = 4 (−90°)");
    // Halfway from the identity to the key at 0.5 s, (0, 0, 0.383, 0.924): slerp halves
    // its angle 2·atan2(0.383, 0.924), the key stored as f32.
    let half = f64::from(0.383_f32).atan2(f64::from(0.924_f32));
    assert_close(&m.skin(0.25), &by_hand(half), "t = 0.25");
    // A quarter of the way: a quarter of the angle (normalised lerp would miss this).
    assert_close(&m.skin(0.125), &by_hand(half / 2.0), "t = 0.125");
    // The tip of the bent column moved: vertex 9 from (0.5, 2) to (−1, 1.5) at 90°.
    assert!((m.skin(1.0)[9] - DVec3::new(-1.0, 1.5, 0.0)).length() < 1e-9);
}

/// A glTF text whose buffers are all embedded data URIs, parsed: its document and buffers.
fn embedded(text: &str) -> (gltf::Document, Vec<Vec<u8>>) {
    let (doc, buffers) = parse_gltf_slice(text.as_bytes()).expect("still glTF");
    let data = buffers
        .into_iter()
        .map(|b| match b {
            weft_character::skin::BufferSource::Data(d) => d,
            other => panic!("{other:?}"),
        })
        .collect();
    (doc, data)
}

#[test]
fn broken_gltf_files_are_errors_not_panics() {
    let text = std::fs::read_to_string(fixture()).expect("fixture");
    let no_skin = text.replacen("\"skin\" : 0,", "", 1);
    let (doc, data) = embedded(&no_skin);
    assert_eq!(
        SkinnedMesh::from_document(&doc, &data).err(),
        Some(SkinError::NoSkinnedMesh)
    );
    // Channel targets the gltf crate leaves unchecked (it panicked reading them).
    for (from, to, says) in [
        (
            "\"path\" : \"rotation\"",
            "\"path\" : \"rotatio\"",
            "target property",
        ),
        ("\"node\" : 2,", "\"node\" : 9,", "target node 9"),
        // An accessor count that overflowed the gltf crate's reader.
        (
            "\"count\" : 2,",
            "\"count\" : 18446744073709551615,",
            "past its buffer view",
        ),
    ] {
        let (doc, data) = embedded(&text.replacen(from, to, 1));
        match SkinnedMesh::from_document(&doc, &data) {
            Err(SkinError::Invalid(m)) => assert!(m.contains(says), "{m}"),
            other => panic!("{to}: {other:?}"),
        }
    }
    let bad_base64 = text.replacen("base64,AAAB", "base64,!AAB", 1);
    assert!(matches!(
        parse_gltf_slice(bad_base64.as_bytes()),
        Err(SkinError::Buffer { index: 0, .. })
    ));
    assert!(matches!(
        parse_gltf_slice(b"{ not json"),
        Err(SkinError::Gltf(_))
    ));
    let dir = std::env::temp_dir().join(format!("weft-character-skin-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let start = text.find("\"data:").expect("data uri");
    let end = start + 1 + text[start + 1..].find('"').expect("end of uri");
    let external = format!("{}\"missing.bin{}", &text[..start], &text[end..]);
    let path = dir.join("external.gltf");
    std::fs::write(&path, external).expect("write");
    let e = read_skinned_gltf(&path).expect_err("missing buffer file");
    assert!(
        matches!(e, LoadError::Io { .. }) && e.to_string().contains("missing.bin"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The fixture with the f32 at byte `at` of buffer `buffer` set to NaN, read.
fn with_nan(buffer: usize, at: usize) -> Result<SkinnedMesh, SkinError> {
    use base64::Engine;
    let text = std::fs::read_to_string(fixture()).expect("fixture");
    let engine = base64::engine::general_purpose::STANDARD;
    let mut start = 0;
    for _ in 0..=buffer {
        start += text[start..].find("base64,").expect("a data uri") + "base64,".len();
    }
    let end = start + text[start..].find('"').expect("end of uri");
    let mut bytes = engine.decode(&text[start..end]).expect("base64");
    bytes[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let broken = format!(
        "{}{}{}",
        &text[..start],
        engine.encode(&bytes),
        &text[end..]
    );
    let (doc, data) = embedded(&broken);
    SkinnedMesh::from_document(&doc, &data)
}

/// A NaN among the bind positions or an animation's key values is an error naming where it
/// is, not a body that turns into NaN.
#[test]
fn non_finite_positions_and_animation_keys_are_errors() {
    let text = std::fs::read_to_string(fixture()).expect("fixture");
    let (doc, _) = parse_gltf_slice(text.as_bytes()).expect("glTF");
    let place = |a: gltf::Accessor| {
        let view = a.view().expect("a buffer view");
        (view.buffer().index(), view.offset() + a.offset())
    };
    let prim = doc.meshes().next().and_then(|m| m.primitives().next());
    let position = prim
        .and_then(|p| p.get(&gltf::Semantic::Positions))
        .expect("positions");
    let (b, at) = place(position);
    assert_eq!(
        with_nan(b, at + 12).expect_err("a NaN position"),
        SkinError::Invalid("mesh 0, primitive 0: vertex 1 is not finite".into())
    );
    let output = doc
        .animations()
        .next()
        .and_then(|a| a.channels().next())
        .expect("a channel")
        .sampler()
        .output();
    let (b, at) = place(output);
    assert_eq!(
        with_nan(b, at).expect_err("a NaN key"),
        SkinError::Invalid("channel 0: a key value is not finite".into())
    );
}
