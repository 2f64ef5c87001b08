//! The `[character]` table: a skeleton and clip (the built-in walker or a BVH file), a body
//! table (built-in or a file), checked and built into a [`CharacterSpec`].

use weft_character::{
    Animation, BodyTable, BvhOptions, Character, parse_bvh, walk::walk_clip, walker_skeleton,
};

use super::Checker;
use crate::scene::CharacterSpec;
use crate::schema::CharacterSection;

pub(super) fn character(c: &mut Checker<'_>, s: &CharacterSection) -> Option<CharacterSpec> {
    let before = c.errors.len();
    let model_only = "without `model` (it places a glTF model)";
    c.unused("character.animation", &s.animation, model_only);
    c.unused("character.position", &s.position, model_only);
    c.unused("character.rotation_deg", &s.rotation_deg, model_only);
    let wrap = s.wrap.into();
    c.friction("character", s.static_friction, s.dynamic_friction);
    let animation = if s.skeleton == "walker" {
        c.unused("character.scale", &s.scale, "by the built-in walker");
        let skeleton = walker_skeleton();
        let clip = walk_clip(&skeleton);
        match Animation::new(skeleton, clip, wrap) {
            Ok(a) => Some(a),
            Err(e) => {
                c.bad("character.skeleton", e.to_string());
                None
            }
        }
    } else {
        let scale = s.scale.unwrap_or(1.0);
        let scale_ok = c.positive("character.scale", scale);
        let text = c.read_text("character.skeleton", &s.skeleton, "BVH");
        match text {
            Some(text) if scale_ok => match parse_bvh(&text, &BvhOptions { scale }) {
                Ok(bvh) => Some(Animation::from_bvh(bvh, wrap)),
                Err(e) => {
                    c.bad(
                        "character.skeleton",
                        format!("bad BVH file `{}`: {e}", s.skeleton),
                    );
                    None
                }
            },
            _ => None,
        }
    };
    let table = match s.body.as_str() {
        "walker" => Some(BodyTable::walker()),
        "cmu" => Some(BodyTable::cmu()),
        path => c
            .read_text("character.body", path, "body table")
            .and_then(|text| match BodyTable::from_toml(&text) {
                Ok(t) => Some(t),
                Err(e) => {
                    c.bad("character.body", format!("bad body table `{path}`: {e}"));
                    None
                }
            }),
    };
    let (animation, table) = (animation?, table?);
    let character = match Character::new(animation, &table) {
        Ok(ch) => ch,
        Err(e) => {
            c.bad(
                "character.body",
                format!("the body `{}` does not fit the skeleton: {e}", s.body),
            );
            return None;
        }
    };
    (c.errors.len() == before).then_some(CharacterSpec {
        character: std::sync::Arc::new(character),
        static_friction: s.static_friction,
        dynamic_friction: s.dynamic_friction,
    })
}
