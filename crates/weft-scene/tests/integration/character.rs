//! The shipped character scenes (assets/scenes/character.toml, skirt.toml, cape.toml): the
//! walker in a T-shirt, a skirt and a cape.

use crate::common;

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
    common::assert_errors(&cases);
}

#[test]
fn a_bvh_character_loads_and_a_broken_one_names_its_file_and_line() {
    let text = format!(
        "[character]\nskeleton = \"../characters/cmu_01_01_4s.bvh\"\nscale = {}\nbody = \"cmu\"\n\
         wrap = \"clamp\"\n\n[cloth.cape]\ngarment = \"../garments/cape.toml\"\n\
         attach = [{{ bone = \"Spine1\", panel = \"cape\", edges = [2, 2] }}]\n",
        weft_character::CMU_SCALE
    );
    let files = weft_scene::DirFiles(scenes_dir());
    let scene = weft_scene::from_text("cmu.toml", &text, &[], &files).expect("loads");
    let ch = scene.character.expect("a character");
    assert_eq!(ch.character.animation().skeleton().len(), 38);
    assert_eq!(scene.cloths[0].attachments[0].bone_name, "Spine1");
    // A BVH cut short: the error names the scene key, the file and the BVH's own line.
    let mut map = std::collections::BTreeMap::new();
    map.insert(
        "short.bvh".to_owned(),
        b"HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n".to_vec(),
    );
    let text = "[character]\nskeleton = \"short.bvh\"\n\n[cloth.c]\nresolution = [4, 4]\n";
    let errs = match weft_scene::from_text("s.toml", text, &[], &weft_scene::MapFiles(map)) {
        Ok(_) => panic!("accepted a truncated BVH"),
        Err(e) => e.0,
    };
    let e = &errs[0];
    assert_eq!(e.key, "character.skeleton");
    assert!(
        e.message
            .contains("bad BVH file `short.bvh`: line 2: `Hips` opened here has no closing"),
        "{}",
        e.message
    );
    assert!(matches!(
        e.origin,
        weft_scene::Origin::File { line: Some(2), .. }
    ));
}
