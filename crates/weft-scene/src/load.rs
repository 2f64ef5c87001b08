//! Loading: file → TOML document → `--set` overrides → serde → validation.

use std::collections::BTreeSet;
use std::path::Path;

use toml_edit::DocumentMut;

use crate::duplicate::{Duplicate, duplicate};
use crate::error::{Origin, SceneError, SceneErrors};
use crate::limits::{
    BYTES_PER_PAIR, Limits, Member, built_bytes, contact_pairs, estimate_bytes, grid_members, human,
};
use crate::overrides::{self, Override};
use crate::resolve::{Checker, resolve};
use crate::scene::{CappedDirFiles, Files, Scene, read_regular};
use crate::schema::{ContactKind, SceneFile};
use crate::source::{Source, key_at, line_at};
use crate::suggest::closest;

/// Loads and validates the scene file at `path` with `overrides` applied; mesh files are
/// read relative to the scene's directory. Files larger than
/// [`DEFAULT_MAX_FILE_BYTES`](crate::DEFAULT_MAX_FILE_BYTES) are refused.
pub fn load(path: &Path, overrides: &[Override]) -> Result<Scene, SceneErrors> {
    load_with(path, overrides, &Limits::default())
}

/// [`load`] within `limits`: files larger than `limits.max_file_bytes` are refused, and so is a
/// scene whose estimated memory exceeds `limits.max_memory`, before its cloths are built.
pub fn load_with(
    path: &Path,
    overrides: &[Override],
    limits: &Limits,
) -> Result<Scene, SceneErrors> {
    let max_file_bytes = limits.max_file_bytes;
    let name = path.display().to_string();
    let bytes = read_regular(path, max_file_bytes).map_err(|e| SceneError {
        origin: Origin::File {
            path: name.clone(),
            line: None,
        },
        key: String::new(),
        message: format!("cannot read the scene file: {e}"),
    })?;
    let text = String::from_utf8(bytes).map_err(|e| SceneError {
        origin: Origin::File {
            path: name.clone(),
            line: Some(line_at_byte(e.as_bytes(), e.utf8_error().valid_up_to())),
        },
        key: String::new(),
        message: "not UTF-8 text".into(),
    })?;
    let files = CappedDirFiles {
        dir: Scene::dir_of(path),
        max_bytes: max_file_bytes,
    };
    from_text_with(&name, &text, overrides, &files, limits)
}

/// 1-based line of byte `at` in `bytes`.
fn line_at_byte(bytes: &[u8], at: usize) -> usize {
    bytes[..at.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Validates scene `text` (called `name` in messages) with `overrides`, reading meshes from `files`.
pub fn from_text(
    name: &str,
    text: &str,
    overrides: &[Override],
    files: &dyn Files,
) -> Result<Scene, SceneErrors> {
    from_text_with(name, text, overrides, files, &Limits::default())
}

/// [`from_text`] within `limits` (see [`load_with`]).
pub fn from_text_with(
    name: &str,
    text: &str,
    overrides: &[Override],
    files: &dyn Files,
    limits: &Limits,
) -> Result<Scene, SceneErrors> {
    let file_error = |line: Option<usize>, message: String| SceneError {
        origin: Origin::File {
            path: name.to_owned(),
            line,
        },
        key: String::new(),
        message,
    };
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| {
        let found = e
            .span()
            .filter(|_| e.message() == "duplicate key")
            .and_then(|at| duplicate(text, at));
        if let Some(d) = found {
            return duplicate_error(name, d);
        }
        let line = e.span().map(|s| line_at(text, s.start));
        file_error(line, format!("not valid TOML: {}", first_line(e.message())))
    })?;
    for ov in overrides {
        overrides::apply(&mut doc, ov)?;
    }
    let effective = doc.to_string();
    let overridden: BTreeSet<String> = overrides.iter().map(|o| o.key.clone()).collect();
    let src = Source::new(name, text, overridden);
    let file: SceneFile = toml_edit::de::from_str(&effective).map_err(|e| {
        let message = tidy(e.message());
        match e.span().and_then(|s| key_at(&effective, s.start)) {
            Some(key) => src.error(&key, message),
            // Lines of the effective text are the file's only while no override moved them.
            None if effective == text => {
                file_error(e.span().map(|s| line_at(text, s.start)), message)
            }
            None => file_error(
                None,
                format!("{message} (with the --set overrides applied)"),
            ),
        }
    })?;
    if let Some((cap, origin)) = &limits.max_memory {
        let grids = grid_members(&file);
        let total: u64 = grids.iter().map(|(_, m, _)| m.particles).sum();
        let members: Vec<Member> = (grids.iter()).filter(|g| g.2).map(|g| g.1).collect();
        let (kind, margin, adaptive) = (file.self_collision.as_ref())
            .map_or((ContactKind::Particles, 0.0, false), |s| {
                (s.contact, s.search_margin, s.adaptive_search_margin)
            });
        let pairs = contact_pairs(&members, kind, margin, adaptive);
        let count = members.iter().map(|m| m.particles).sum();
        let method = |name: &str| {
            (file.cloth.get(name).and_then(|c| c.method))
                .unwrap_or(file.sim.method)
                .into()
        };
        let cloths: Vec<_> = (grids.iter())
            .map(|(n, m, _)| (method(n), m.particles))
            .collect();
        let need = estimate_bytes(&cloths, count, pairs);
        let thickest =
            (grids.iter().filter(|g| g.2)).max_by(|a, b| a.1.thickness.total_cmp(&b.1.thickness));
        let by_pairs = pairs.saturating_mul(BYTES_PER_PAIR) > need / 2;
        if need > *cap
            && by_pairs
            && let Some((name, m, _)) = thickest
        {
            let what = match kind {
                ContactKind::Particles => "particles",
                ContactKind::Mesh => "elements (vertex–triangle and edge–edge)",
            };
            return Err(src
                .error(
                    &format!("cloth.{name}.thickness"),
                    format!(
                        "self-collision at this thickness ({} m) may list {pairs} pairs of \
                         {what}, and the scene needs about {} once built, more than the {} \
                         allowed ({origin}); lower the thickness, or raise the limit with \
                         --max-memory",
                        m.thickness,
                        human(need),
                        human(*cap)
                    ),
                )
                .into());
        }
        if need > *cap
            && let Some((largest, _, _)) = grids.iter().max_by_key(|(_, m, _)| m.particles)
        {
            return Err(src
                .error(
                    &format!("cloth.{largest}.resolution"),
                    format!(
                        "the scene's cloths hold {total} particles, about {} once built, more \
                         than the {} allowed ({origin}); lower the resolution, or raise the \
                         limit with --max-memory",
                        human(need),
                        human(*cap)
                    ),
                )
                .into());
        }
    }
    let mut checker = Checker::new(&src, files);
    let parts = resolve(&file, &mut checker);
    let Some(parts) = parts else {
        return Err(SceneErrors(checker.errors));
    };
    if let Some((cap, origin)) = &limits.max_memory {
        // Exact now, mesh cloths included.
        let total: u64 = parts.cloths.iter().map(|c| c.mesh.len() as u64).sum();
        let need = built_bytes(&parts.cloths, parts.self_collision.as_ref());
        if need > *cap {
            return Err(src
                .error(
                    "cloth",
                    format!(
                        "the scene's cloths hold {total} particles, about {} once built, more \
                         than the {} allowed ({origin}); raise the limit with --max-memory",
                        human(need),
                        human(*cap)
                    ),
                )
                .into());
        }
    }
    Ok(Scene {
        name: name.to_owned(),
        source: text.to_owned(),
        effective,
        overrides: overrides.to_vec(),
        file,
        settings: parts.settings,
        forces: parts.forces,
        cloths: parts.cloths,
        colliders: parts.colliders,
        self_collision: parts.self_collision,
        character: parts.character,
        model: parts.model,
        files: checker.read,
    })
}

/// The error for a key defined twice in the file `name`.
fn duplicate_error(name: &str, d: Duplicate) -> SceneError {
    let first = match d.first {
        Some(l) if l == d.second => format!("defined twice on line {l}"),
        Some(l) => format!("first defined on line {l}, again on line {}", d.second),
        None => format!("defined again on line {}", d.second),
    };
    let (key, message) = match d.key {
        Some(key) => (key, format!("duplicate key: {first}")),
        None => (
            String::new(),
            format!("duplicate key `{}`: {first}", d.name),
        ),
    };
    SceneError {
        origin: Origin::File {
            path: name.to_owned(),
            line: Some(d.second),
        },
        key,
        message,
    }
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or(s).trim()
}

/// Shortens serde's messages: long lists of expected keys become a "did you mean".
fn tidy(message: &str) -> String {
    let message = plain_types(first_line(message));
    let message = message.as_str();
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_owned();
    };
    let Some((field, tail)) = rest.split_once('`') else {
        return message.to_owned();
    };
    let expected: Vec<&str> = tail.split('`').skip(1).step_by(2).collect();
    match closest(field, &expected) {
        Some(b) => format!("unknown key `{field}` (did you mean `{b}`?)"),
        None if expected.len() <= 8 && !expected.is_empty() => {
            format!(
                "unknown key `{field}`, expected one of: {}",
                expected.join(", ")
            )
        }
        None => format!("unknown key `{field}` (see the scene key reference in docs/scenes.md)"),
    }
}

/// `message` in the scene's terms: serde's Rust types (`i64`, `struct SimSection`, `map`,
/// `sequence`) named as TOML ones.
fn plain_types(message: &str) -> String {
    let mut out = message
        .replace("expected i64", "expected an integer")
        .replace("expected f64", "expected a number")
        .replace("invalid type: map", "invalid type: table")
        .replace("invalid type: sequence", "invalid type: array")
        .replace("expected a map", "expected a table")
        .replace("expected a sequence", "expected an array")
        .replace("wanted string or table", "expected a name (a string)");
    for (rust, toml) in [
        (
            "expected internally tagged enum ",
            "expected a table with a `kind`",
        ),
        ("expected struct ", "expected a table"),
    ] {
        while let Some(at) = out.find(rust) {
            let name = &out[at + rust.len()..];
            let end = name
                .find(|c: char| !c.is_ascii_alphanumeric() && c != '_')
                .unwrap_or(name.len());
            out.replace_range(at..at + rust.len() + end, toml);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::DirFiles;

    const CLOTH: &str = "[cloth.c]\nresolution = [4, 4]\nsize = [1.0, 1.0]\n\n";

    fn self_collision(section: &str) -> Result<Scene, SceneErrors> {
        let text = format!("{CLOTH}[self_collision]\n{section}");
        from_text("s.toml", &text, &[], &DirFiles(".".into()))
    }

    #[test]
    fn a_duplicate_key_names_the_file_the_key_and_both_lines() {
        let err = |text: &str| {
            from_text("d.toml", text, &[], &DirFiles(".".into()))
                .expect_err("duplicate")
                .to_string()
        };
        assert_eq!(
            err("[sim]\ndt = 0.01\ndt = 0.02\n"),
            "d.toml:3: sim.dt: duplicate key: first defined on line 2, again on line 3"
        );
        assert_eq!(
            err(&format!("{CLOTH}[sim]\ndt = 0.01\n\n[sim]\nsubsteps = 2\n")),
            "d.toml:8: sim: duplicate key: first defined on line 5, again on line 8"
        );
        assert_eq!(
            err("[cloth.c]\nmotion = { kind = \"static\", kind = \"linear\" }\n"),
            "d.toml:2: cloth.c.motion.kind: duplicate key: defined twice on line 2"
        );
    }

    #[test]
    fn the_search_margin_adapts_unless_the_scene_fixes_it() {
        let spec = |scene: Scene| scene.self_collision.expect("self-collision on");
        let default = spec(self_collision("").expect("valid"));
        assert_eq!(
            (default.search_margin, default.adaptive_search_margin),
            (0.5, true)
        );
        let fixed = spec(
            self_collision("search_margin = 0.3\nadaptive_search_margin = false\n").expect("valid"),
        );
        assert_eq!(
            (fixed.search_margin, fixed.adaptive_search_margin),
            (0.3, false)
        );
        let err = self_collision("adaptive_search_margin = 2\n")
            .expect_err("not a boolean")
            .to_string();
        assert!(
            err.contains("s.toml") && err.contains("adaptive_search_margin"),
            "{err}"
        );
    }

    #[test]
    fn contact_is_the_mesh_unless_the_scene_asks_for_particles() {
        let spec = |scene: Scene| scene.self_collision.expect("self-collision on");
        let mesh = self_collision("").expect("valid");
        assert_eq!(spec(mesh.clone()).contact, ContactKind::Mesh);
        let groups = mesh.build().expect("builds");
        let world = groups[0].world.as_ref().expect("a collision world");
        assert!(world.cloth_contact_stats().is_some(), "mesh contact is on");
        let particles = self_collision("contact = \"particles\"\n").expect("valid");
        assert_eq!(spec(particles.clone()).contact, ContactKind::Particles);
        let groups = particles.build().expect("builds");
        let world = groups[0].world.as_ref().expect("a collision world");
        assert!(world.cloth_contact_stats().is_none(), "mesh contact is off");
        assert!(
            world.self_collision_lists().is_some(),
            "particle contact is on"
        );
        let err = self_collision("contact = \"edges\"\n")
            .expect_err("no such contact")
            .to_string();
        assert!(err.contains("s.toml:6: self_collision.contact"), "{err}");
    }
}
