//! The shipped character scenes (assets/scenes/character.toml, skirt.toml, cape.toml): the
//! walker in a T-shirt, a skirt and a cape.

mod common;

use common::{load, scenes_dir};

#[test]
fn the_character_scenes_load() {
    for name in ["character", "skirt", "cape"] {
        let scene = load(&scenes_dir().join(format!("{name}.toml")), &[]);
        let c = &scene.cloths[0];
        eprintln!(
            "{name}: {} particles, {} seams, attachments {:?}",
            c.mesh.len(),
            c.seams.len(),
            c.attachments
                .iter()
                .map(|a| (a.bone_name.clone(), a.vertices.len()))
                .collect::<Vec<_>>()
        );
        let groups = scene.build().expect("builds");
        assert_eq!(groups.len(), 1);
    }
}

/// The errors (as `line: key: message` lines, sorted) of a character scene `text` whose
/// files are read from assets/scenes.
fn errors(text: &str) -> Vec<(Option<usize>, String, String)> {
    let files = weft_scene::DirFiles(scenes_dir());
    match weft_scene::from_text("bad.toml", text, &[], &files) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => {
            e.0.iter()
                .map(|e| {
                    let line = match &e.origin {
                        weft_scene::Origin::File { line, .. } => *line,
                        weft_scene::Origin::CommandLine => None,
                    };
                    (line, e.key.clone(), e.message.clone())
                })
                .collect()
        }
    }
}

const GOOD: &str = r#"[character]
skeleton = "walker"

[cloth.skirt]
garment = "../garments/skirt.toml"
material = "cotton"
attach = [{ bone = "Hips", panel = "front", edges = [2, 2] }]
"#;

/// `GOOD` with `from` replaced by `to`.
fn bad(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "{from}");
    GOOD.replacen(from, to, 1)
}

#[test]
fn bad_character_and_garment_keys_are_errors_with_file_line_and_key() {
    let files = weft_scene::DirFiles(scenes_dir());
    assert!(weft_scene::from_text("good.toml", GOOD, &[], &files).is_ok());
    let cases: [(String, usize, &str, &str); 9] = [
        (
            bad("\"Hips\"", "\"Pelvis\""),
            7,
            "cloth.skirt.attach[0].bone",
            "no bone named `Pelvis`",
        ),
        (
            bad("skirt.toml", "nowhere.toml"),
            5,
            "cloth.skirt.garment",
            "cannot read garment file `../garments/nowhere.toml`",
        ),
        (
            bad("\"walker\"", "\"missing.bvh\""),
            2,
            "character.skeleton",
            "cannot read BVH file `missing.bvh`",
        ),
        (
            bad(
                "skeleton = \"walker\"",
                "skeleton = \"walker\"\nbody = \"no_body.toml\"",
            ),
            3,
            "character.body",
            "cannot read body table file `no_body.toml`",
        ),
        (
            bad(
                "skeleton = \"walker\"",
                "skeleton = \"walker\"\nwrap = \"bounce\"",
            ),
            3,
            "character.wrap",
            "unknown variant `bounce`",
        ),
        (
            bad(
                "skeleton = \"walker\"",
                "skeleton = \"walker\"\nskelton = 1",
            ),
            3,
            "character.skelton",
            "did you mean `skeleton`",
        ),
        (
            bad("edges = [2, 2]", "edges = [2, 9]"),
            7,
            "cloth.skirt.attach[0].edges",
            "panel `front` has edges 0..=3",
        ),
        (
            bad("panel = \"front\"", "panel = \"side\""),
            7,
            "cloth.skirt.attach[0].panel",
            "no panel named `side`",
        ),
        (
            bad("[character]\nskeleton = \"walker\"\n", ""),
            5,
            "cloth.skirt.attach",
            "attachments need a [character] table",
        ),
    ];
    for (text, line, key, message) in cases {
        let errs = errors(&text);
        assert!(
            errs.iter()
                .any(|(l, k, m)| *l == Some(line) && k == key && m.contains(message)),
            "expected line {line}, key {key}: {message}\ngot {errs:?}\nfor\n{text}"
        );
    }
}
