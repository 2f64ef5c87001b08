//! `[character] model = "file.glb"`: a skinned glTF/GLB character read (with its external
//! buffers, relative to the model file), its animation chosen, and placed by `scale`,
//! `rotation_deg` and `position` into a [`ModelSpec`] whose deforming mesh is the body.

use std::path::Path;
use std::sync::Arc;

use weft_character::skin::{
    AnimationChoice, BufferSource, SkinCollider, SkinnedMesh, parse_gltf_slice,
};
use weft_solver::glam::{DMat4, DVec3};

use super::Checker;
use super::checker::show;
use crate::ranges;
use crate::scene::ModelSpec;
use crate::schema::{AnimationKey, CharacterSection};

/// Checks the model keys of `s` (which has a `model`) and reads the model.
pub(super) fn model(c: &mut Checker<'_>, s: &CharacterSection) -> Option<ModelSpec> {
    let path = s.model.as_deref()?;
    let before = c.errors.len();
    if s.skeleton != "walker" {
        c.bad(
            "character.skeleton",
            "not used with `model` (the model's skin is the skeleton)",
        );
    }
    if s.body != "walker" {
        c.bad(
            "character.body",
            "not used with `model` (the model's mesh is the body)",
        );
    }
    c.friction("character", s.static_friction, s.dynamic_friction);
    let scale = s.scale.unwrap_or(1.0);
    c.positive("character.scale", scale);
    let rotation = c.rotation("character.rotation_deg", s.rotation_deg.unwrap_or_default());
    let position = c.vector("character.position", s.position.unwrap_or_default());
    let choice = match &s.animation {
        None => AnimationChoice::First,
        Some(AnimationKey::Name(n)) => AnimationChoice::Name(n.clone()),
        Some(AnimationKey::Index(i)) => match usize::try_from(*i) {
            Ok(i) => AnimationChoice::Index(i),
            Err(_) => {
                c.bad("character.animation", format!("must be >= 0, got {i}"));
                return None;
            }
        },
    };
    let bytes = c.read_bytes("character.model", path, "glTF model")?;
    let mesh = read_model(c, path, &bytes, &choice)?;
    if c.errors.len() > before {
        return None;
    }
    let placement = DMat4::from_scale_rotation_translation(DVec3::splat(scale), rotation, position);
    let skin = SkinCollider::placed(mesh, placement, s.wrap.into());
    // The placed body at the first and a few later instants must lie in the world's range
    // (a wrong `scale` would put it kilometres away).
    let duration = skin.mesh().duration();
    for k in 0..=4 {
        let t = duration * f64::from(k) / 4.0;
        let far = skin
            .vertices(t)
            .into_iter()
            .find(|v| !v.is_finite() || v.abs().max_element() > ranges::COORDINATE.hi);
        if let Some(v) = far {
            c.bad(
                "character.model",
                format!(
                    "`{path}` placed by scale {} has a vertex at {v} at t = {} s: out of range, \
                     every coordinate must be {}",
                    show(scale),
                    show(t),
                    ranges::COORDINATE.expected()
                ),
            );
            return None;
        }
    }
    Some(ModelSpec {
        path: path.to_owned(),
        skin: Arc::new(skin),
        static_friction: s.static_friction,
        dynamic_friction: s.dynamic_friction,
    })
}

/// Parses the model's bytes, reads its external buffers (relative to the model file) and
/// builds the skinned mesh; every failure is an error on `character.model` naming the file.
fn read_model(
    c: &mut Checker<'_>,
    path: &str,
    bytes: &[u8],
    choice: &AnimationChoice,
) -> Option<SkinnedMesh> {
    let bad = |c: &mut Checker<'_>, e: &dyn std::fmt::Display| {
        c.bad(
            "character.model",
            format!("`{path}` is not a usable skinned glTF: {e}"),
        );
    };
    let (doc, sources) = match parse_gltf_slice(bytes) {
        Ok(p) => p,
        Err(e) => {
            bad(c, &e);
            return None;
        }
    };
    if let Err(e) = choice.pick(&doc) {
        c.bad("character.animation", format!("`{path}` has {e}"));
        return None;
    }
    let dir = Path::new(path).parent().unwrap_or(Path::new(""));
    let mut buffers = Vec::new();
    for source in sources {
        match source {
            BufferSource::Data(d) => buffers.push(d),
            BufferSource::External(uri) => {
                let file = dir.join(&uri).to_string_lossy().into_owned();
                buffers.push(c.read_bytes("character.model", &file, "glTF buffer")?);
            }
        }
    }
    match SkinnedMesh::from_document_with(&doc, &buffers, choice) {
        Ok(m) if m.triangles.is_empty() => {
            bad(c, &"its skinned meshes have no triangles");
            None
        }
        Ok(m) => Some(m),
        Err(e) => {
            bad(c, &e);
            None
        }
    }
}
