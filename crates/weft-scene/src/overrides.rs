//! `--set KEY=VALUE` overrides, applied to the TOML document before it is deserialised.

use std::str::FromStr;

use toml_edit::{DocumentMut, InlineTable, Item, Table, TableLike, Value};

use crate::error::{Origin, SceneError};
use crate::suggest::closest;

/// One `KEY=VALUE` override; the value is parsed as TOML, falling back to a string.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Override {
    /// Dotted key, e.g. `cloth.flag.stretch_compliance` or `collider[0].radius`.
    pub key: String,
    /// The value as typed.
    pub value: String,
}

impl FromStr for Override {
    type Err = SceneError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = |key: &str, message: String| SceneError {
            origin: Origin::CommandLine,
            key: key.to_owned(),
            message,
        };
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| bad(s, "expected KEY=VALUE, e.g. sim.substeps=20".into()))?;
        let key = key.trim();
        segments(key).map_err(|m| bad(key, m))?;
        Ok(Self {
            key: key.to_owned(),
            value: value.trim().to_owned(),
        })
    }
}

/// One part of a dotted key: a name, and the index of an entry when it names a list's.
type Segment<'a> = (&'a str, Option<usize>);

/// The parts of `key` (`collider[0].radius` → `collider`, 0; `radius`), or why it is not a key.
fn segments(key: &str) -> Result<Vec<Segment<'_>>, String> {
    key.split('.')
        .map(|seg| {
            let (name, index) = match seg.split_once('[') {
                None => (seg, None),
                Some((name, rest)) => {
                    let Some(inside) = rest.strip_suffix(']') else {
                        return Err(format!(
                            "`{seg}` has no closing `]`: an index is a whole number in \
                             brackets, e.g. {name}[0]"
                        ));
                    };
                    (name, Some(index(name, inside)?))
                }
            };
            let bare = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
            if name.is_empty() || !name.chars().all(bare) {
                return Err(
                    "the key must be dotted names such as cloth.flag.mass or collider[0].radius"
                        .into(),
                );
            }
            Ok((name, index))
        })
        .collect()
}

/// The index written `[inside]` after `name`.
fn index(name: &str, inside: &str) -> Result<usize, String> {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if inside.strip_prefix('-').is_some_and(digits) {
        return Err(format!(
            "[{inside}] is a negative index, which is not valid: entries are numbered from 0, \
             e.g. {name}[0]"
        ));
    }
    if !digits(inside) {
        return Err(format!(
            "[{inside}] is not an index: an index is a whole number, e.g. {name}[0]"
        ));
    }
    inside
        .parse()
        .map_err(|_| format!("[{inside}] is too large an index"))
}

impl std::fmt::Display for Override {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.key, self.value)
    }
}

/// The value of an override: TOML if it parses as a value (`20`, `1e-6`, `[0, 1, 0]`,
/// `"pbd"`, `{ kind = "static" }`), otherwise the text as a string (`pbd`).
pub fn parse_value(text: &str) -> Value {
    let doc = format!("v = {text}");
    DocumentMut::from_str(&doc)
        .ok()
        .and_then(|d| d.get("v").and_then(Item::as_value).cloned())
        .map(|mut v| {
            v.decor_mut().clear();
            v
        })
        .unwrap_or_else(|| Value::from(text))
}

/// Keys whose value is a list of tables (`[[collider]]`, a cloth's `attach`, a compound's
/// `parts`): a key below one names an entry, e.g. `collider[0].radius`.
const LISTS: &[&str] = &["collider", "attach", "parts"];

/// How many cloth names an error lists before saying how many more there are.
const LISTED: usize = 12;

/// Applies `ov` to `doc`, creating the tables of absent sections on the way (`[sim]`,
/// `[self_collision]`, a cloth's `motion`) but never a cloth or a list entry: a key under a
/// cloth the scene does not have, or an entry past the end of a list, is an error.
pub fn apply(doc: &mut DocumentMut, ov: &Override) -> Result<(), SceneError> {
    let err = |message: String| SceneError {
        origin: Origin::CommandLine,
        key: ov.key.clone(),
        message,
    };
    let segs = segments(&ov.key).map_err(err)?;
    let Some(((last, last_index), path)) = segs.split_last() else {
        return Err(err("empty key".into()));
    };
    if let [("cloth", None), (name, _), ..] = segs[..] {
        known_cloth(doc, name).map_err(err)?;
    }
    let mut table: &mut dyn TableLike = doc.as_table_mut();
    let mut inline = false;
    for &(name, index) in path {
        if !table.contains_key(name) {
            if let Some(i) = index {
                return Err(err(format!(
                    "the scene has no `{name}` entries, so [{i}] does not exist"
                )));
            }
            if LISTS.contains(&name) {
                return Err(err(format!(
                    "`{name}` is a list: name an entry, e.g. {name}[0]"
                )));
            }
            let fresh = if inline {
                Item::Value(Value::InlineTable(InlineTable::new()))
            } else {
                let mut t = Table::new();
                t.set_implicit(true);
                Item::Table(t)
            };
            table.insert(name, fresh);
        }
        let item = table
            .get_mut(name)
            .ok_or_else(|| err(format!("cannot create `{name}`")))?;
        if !inline && let Item::Value(Value::InlineTable(_)) = item {
            // Turn an inline table into a normal one so it can be edited like the rest.
            let inline = std::mem::take(item);
            if let Item::Value(Value::InlineTable(t)) = inline {
                *item = Item::Table(t.into_table());
            }
        }
        (table, inline) = match (item, index) {
            (Item::Table(t), None) => (t as &mut dyn TableLike, false),
            (Item::Value(Value::InlineTable(t)), None) => (t as &mut dyn TableLike, true),
            (Item::ArrayOfTables(a), Some(i)) => {
                let len = a.len();
                let entry = a
                    .get_mut(i)
                    .ok_or_else(|| err(past_the_end(name, len, i)))?;
                (entry as &mut dyn TableLike, false)
            }
            (Item::Value(Value::Array(a)), Some(i)) => {
                let len = a.len();
                match a.get_mut(i) {
                    Some(Value::InlineTable(t)) => (t as &mut dyn TableLike, true),
                    Some(_) => {
                        return Err(err(format!("`{name}[{i}]` is a value, not a table")));
                    }
                    None => return Err(err(past_the_end(name, len, i))),
                }
            }
            (Item::ArrayOfTables(_) | Item::Value(Value::Array(_)), None) => {
                return Err(err(format!(
                    "`{name}` is a list: name an entry, e.g. {name}[0]"
                )));
            }
            (Item::Table(_) | Item::Value(Value::InlineTable(_)), Some(i)) => {
                return Err(err(format!(
                    "`{name}` is a table, not a list, so [{i}] does not exist"
                )));
            }
            (Item::Value(_) | Item::None, _) => {
                return Err(err(format!("`{name}` is a value, not a table")));
            }
        };
    }
    if last_index.is_some() {
        return Err(err(format!(
            "the last part of the key cannot be indexed: set the whole of `{last}`"
        )));
    }
    table.insert(last, Item::Value(parse_value(&ov.value)));
    Ok(())
}

fn past_the_end(name: &str, len: usize, i: usize) -> String {
    format!("`{name}` has {len} entries, so [{i}] does not exist")
}

/// Whether the scene has a cloth `name`; if not, why not, with the names it has. (A
/// `cloth` that is not a table is left to the walk, which says so.)
fn known_cloth(doc: &DocumentMut, name: &str) -> Result<(), String> {
    let names: Vec<&str> = match doc.get("cloth") {
        None => Vec::new(),
        Some(item) => match item.as_table_like() {
            Some(t) => t.iter().map(|(k, _)| k).collect(),
            None => return Ok(()),
        },
    };
    if names.contains(&name) {
        return Ok(());
    }
    if names.is_empty() {
        return Err(format!(
            "no cloth named `{name}` in the scene, which has none (--set changes a cloth; it \
             does not add one)"
        ));
    }
    let guess = closest(name, &names)
        .map(|c| format!(" (did you mean `{c}`?)"))
        .unwrap_or_default();
    let mut listed = names[..names.len().min(LISTED)].join(", ");
    if names.len() > LISTED {
        listed.push_str(&format!(" and {} more", names.len() - LISTED));
    }
    Err(format!(
        "no cloth named `{name}` in the scene{guess}; its cloths: {listed}"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_as_toml_or_fall_back_to_strings() {
        assert_eq!(parse_value("20").as_integer(), Some(20));
        assert_eq!(parse_value("1e-6").as_float(), Some(1e-6));
        assert_eq!(parse_value("pbd").as_str(), Some("pbd"));
        assert_eq!(parse_value("\"1/60\"").as_str(), Some("1/60"));
        assert!(parse_value("[0, 1, 0]").is_array());
    }

    /// A scene with two cloths (one with an attach list) and one collider.
    const SCENE: &str = "[sim]\ndt = 0.01\n\n[cloth.reference]\nmass = 1\n\n[cloth.flag]\nmass = 1\nattach = [{ bone = \"a\", panel = \"p\", edges = [0, 0] }]\n\n[[collider]]\nshape = \"sphere\"\n";

    fn doc() -> DocumentMut {
        SCENE.parse().expect("valid")
    }

    /// The error applying `s` to [`SCENE`], checking that it left the document as it was.
    fn refused(s: &str) -> String {
        let mut d = doc();
        let ov = Override {
            key: s.split_once('=').expect("KEY=VALUE").0.to_owned(),
            value: "1".into(),
        };
        let e = apply(&mut d, &ov).expect_err(s);
        assert_eq!(d.to_string(), SCENE, "{s} changed the scene");
        assert_eq!(e.origin, Origin::CommandLine);
        e.message
    }

    #[test]
    fn overrides_edit_and_create_keys() {
        let mut doc = doc();
        for s in [
            "sim.substeps=20",
            "cloth.flag.mass=2",
            "collider[0].radius=0.5",
            "cloth.flag.attach[0].bone=\"b\"",
            "self_collision.enabled=true",
            "wind.aero.drag_coefficient=1",
            "cloth.reference.motion.kind=linear",
        ] {
            apply(&mut doc, &s.parse().expect("valid override")).expect(s);
        }
        let text = doc.to_string();
        for want in [
            "substeps = 20",
            "[cloth.flag]\nmass = 2",
            "radius = 0.5",
            "bone = \"b\"",
            "[self_collision]\nenabled = true",
            "[wind.aero]\ndrag_coefficient = 1",
            "[cloth.reference.motion]\nkind = \"linear\"",
        ] {
            assert!(text.contains(want), "{want}\n{text}");
        }
        assert!("nokey".parse::<Override>().is_err());
    }

    #[test]
    fn a_key_under_a_cloth_the_scene_lacks_is_an_error_listing_its_cloths() {
        assert_eq!(
            refused("cloth.sheet.mass=5"),
            "no cloth named `sheet` in the scene; its cloths: reference, flag"
        );
        assert_eq!(
            refused("cloth.refrence.mass=5"),
            "no cloth named `refrence` in the scene (did you mean `reference`?); its cloths: \
             reference, flag"
        );
        assert!(refused("cloth.clth=5").starts_with("no cloth named `clth`"));
        assert!(refused("cloth.clth.motion.kind=5").starts_with("no cloth named `clth`"));
        let mut bare: DocumentMut = "[sim]\ndt = 0.01\n".parse().expect("valid");
        let e = apply(&mut bare, &"cloth.c.mass=1".parse().expect("valid")).expect_err("none");
        assert!(e.message.contains("which has none"), "{}", e.message);
    }

    #[test]
    fn list_entries_must_exist_and_indexes_must_be_whole_numbers() {
        for (s, want) in [
            (
                "collider[1].radius=1",
                "`collider` has 1 entries, so [1] does not exist",
            ),
            (
                "collider.radius=1",
                "`collider` is a list: name an entry, e.g. collider[0]",
            ),
            (
                "cloth.flag.attach[3].bone=1",
                "`attach` has 1 entries, so [3] does not exist",
            ),
            (
                "cloth.reference.attach[0].bone=1",
                "the scene has no `attach` entries, so [0] does not exist",
            ),
            (
                "cloth.reference.attach.bone=1",
                "`attach` is a list: name an entry",
            ),
            (
                "cloth.flag[0].mass=1",
                "`flag` is a table, not a list, so [0] does not exist",
            ),
            ("cloth.flag.mass.x=1", "`mass` is a value, not a table"),
            ("sim.dt[0]=1", "the last part of the key cannot be indexed"),
            (
                "collider[-1].radius=1",
                "[-1] is a negative index, which is not valid",
            ),
            ("collider[x].radius=1", "[x] is not an index"),
            ("collider[].radius=1", "[] is not an index"),
            ("collider[0.radius=1", "`collider[0` has no closing `]`"),
            (
                "collider[99999999999999999999999].radius=1",
                "too large an index",
            ),
            ("cloth..mass=1", "the key must be dotted names"),
            (".mass=1", "the key must be dotted names"),
            ("sim.=1", "the key must be dotted names"),
            ("sim.sub steps=1", "the key must be dotted names"),
        ] {
            let message = refused(s);
            assert!(message.contains(want), "{s}: {message}");
        }
        let mut empty: DocumentMut = "[sim]\ndt = 0.01\n".parse().expect("valid");
        let e = apply(&mut empty, &"collider[0].radius=1".parse().expect("valid"));
        assert_eq!(
            e.expect_err("no colliders").message,
            "the scene has no `collider` entries, so [0] does not exist"
        );
        // Parsing refuses a bad index too, naming the key without its value.
        let e = "collider[-1].radius=1"
            .parse::<Override>()
            .expect_err("negative");
        assert_eq!(e.key, "collider[-1].radius");
        assert!(e.message.contains("negative index"), "{}", e.message);
    }

    #[test]
    fn errors_in_what_an_override_made_are_placed_on_the_command_line() {
        let scene = "[cloth.c]\nresolution = [4, 4]\nsize = [1.0, 1.0]\n";
        let err = |set: &str| {
            let ov = [set.parse::<Override>().expect("valid")];
            crate::from_text("s.toml", scene, &ov, &crate::DirFiles(".".into()))
                .expect_err(set)
                .to_string()
        };
        for (set, want) in [
            (
                "cloth.c.motion.kind=linear",
                "command line (--set cloth.c.motion.kind): cloth.c.motion.kind: missing field \
                 `velocity`",
            ),
            (
                "sim2.substeps=3",
                "command line (--set sim2.substeps): sim2.substeps: unknown key `sim2` (did you \
                 mean `sim`?)",
            ),
            (
                "collider.radius=1",
                "command line (--set collider.radius): collider.radius: `collider` is a list: \
                 name an entry, e.g. collider[0]",
            ),
            (
                "cloth.c.resolution=[4, 4, 1]",
                "command line (--set cloth.c.resolution): cloth.c.resolution: takes 2 values, \
                 got 3",
            ),
            (
                "cloth.c=5",
                "command line (--set cloth.c): cloth.c: invalid type: integer `5`, expected a \
                 table",
            ),
            (
                "sim.method=5",
                "command line (--set sim.method): sim.method: expected a name (a string)",
            ),
        ] {
            assert_eq!(err(set), want);
        }
    }
}
