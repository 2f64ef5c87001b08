//! Naming a duplicate key: toml_edit reports only "duplicate key" and the span of the second
//! definition's key, so the dotted key and the line of its first definition are found here.
//!
//! The second definition's key is renamed to a placeholder and the text parsed again: the
//! placeholder's place in the document is the dotted key, and the original key, still
//! there, gives the first line. Later duplicates are renamed too, and a later error of
//! another kind cuts the text before its line, so the part that holds both definitions parses.

use std::collections::BTreeSet;
use std::ops::Range;

use toml_edit::{Document, Item, Key, Table, Value};

use crate::source::{Source, line_at};

/// What a duplicate key is.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Duplicate {
    /// The key as written at the second definition (unquoted).
    pub name: String,
    /// Its dotted key, e.g. `cloth.flag.mass` or `collider[1].radius`, when found.
    pub key: Option<String>,
    /// 1-based line of the first definition, when found.
    pub first: Option<usize>,
    /// 1-based line of the second definition.
    pub second: usize,
}

/// How many further errors are stepped over before giving up.
const TRIES: usize = 16;

/// Describes the duplicate key whose second definition's key lies at `at` in `text`.
pub(crate) fn duplicate(text: &str, at: Range<usize>) -> Option<Duplicate> {
    let token = text.get(at.clone())?;
    let name = token
        .parse::<Key>()
        .map(|k| k.get().to_owned())
        .unwrap_or_else(|_| token.trim().to_owned());
    let second = line_at(text, at.start);
    let placeholder = |n: usize| format!("weft_duplicate_{n}_{}", text.len());
    let mut work = format!("{}{}{}", &text[..at.start], placeholder(0), &text[at.end..]);
    let ours = at.start..at.start + placeholder(0).len();
    let mut found = None;
    for n in 1..=TRIES {
        let e = match Document::parse(work.clone()) {
            Ok(doc) => {
                found = path_to(doc.as_table(), &placeholder(0));
                break;
            }
            Err(e) => e,
        };
        // An error at or before the placeholder means the renaming went wrong.
        let Some(span) = e.span().filter(|s| s.start >= ours.end) else {
            break;
        };
        if e.message().starts_with("duplicate key") && work.get(span.clone()).is_some() {
            work.replace_range(span, &placeholder(n));
        } else {
            let Some(before) = work.get(..span.start) else {
                break;
            };
            let line_start = before.rfind('\n').map_or(0, |i| i + 1);
            if line_start <= ours.end {
                break;
            }
            work.truncate(line_start);
        }
    }
    let path = found.map(|p| join(&p, &name));
    let first = path
        .as_deref()
        .and_then(|key| Source::new("", &work, BTreeSet::new()).exact_line_of(key));
    Some(Duplicate {
        name,
        key: path,
        first,
        second,
    })
}

/// The dotted key for `path`, its last segment (the placeholder) named `name`.
fn join(path: &[String], name: &str) -> String {
    let mut key = path[..path.len().saturating_sub(1)].join(".");
    if !key.is_empty() {
        key.push('.');
    }
    key.push_str(name);
    key
}

/// The segments (`name` or `name[i]`) down to the key called `wanted`.
fn path_to(table: &Table, wanted: &str) -> Option<Vec<String>> {
    table.iter().find_map(|(k, item)| in_item(k, item, wanted))
}

fn in_item(key: &str, item: &Item, wanted: &str) -> Option<Vec<String>> {
    if key == wanted {
        return Some(vec![key.to_owned()]);
    }
    let below = match item {
        Item::Table(t) => path_to(t, wanted).map(|p| (None, p)),
        Item::ArrayOfTables(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, t)| path_to(t, wanted).map(|p| (Some(i), p))),
        Item::Value(v) => in_value(v, wanted),
        Item::None => None,
    };
    prefixed(key, below)
}

/// The path below an inline value, and the index taken into it if it is an array.
fn in_value(v: &Value, wanted: &str) -> Option<(Option<usize>, Vec<String>)> {
    match v {
        Value::InlineTable(t) => t
            .iter()
            .find_map(|(k, v)| {
                if k == wanted {
                    Some(vec![k.to_owned()])
                } else {
                    prefixed(k, in_value(v, wanted))
                }
            })
            .map(|p| (None, p)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, v)| in_value(v, wanted).map(|(_, p)| (Some(i), p))),
        _ => None,
    }
}

/// `below` with `key` (indexed if an index was taken) put in front.
fn prefixed(key: &str, below: Option<(Option<usize>, Vec<String>)>) -> Option<Vec<String>> {
    below.map(|(index, mut path)| {
        let seg = match index {
            Some(i) => format!("{key}[{i}]"),
            None => key.to_owned(),
        };
        path.insert(0, seg);
        path
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The duplicate in `text` as toml_edit reports it.
    fn describe(text: &str) -> Duplicate {
        let e = text
            .parse::<toml_edit::DocumentMut>()
            .expect_err("duplicate");
        assert_eq!(e.message(), "duplicate key", "{text}");
        duplicate(text, e.span().expect("span")).expect("described")
    }

    fn found(key: &str, first: usize, second: usize) -> (Option<String>, Option<usize>, usize) {
        (Some(key.to_owned()), Some(first), second)
    }

    #[test]
    fn a_duplicate_is_named_with_its_dotted_key_and_both_lines() {
        for (text, want) in [
            ("[sim]\ndt = 0.01\ndt = 0.02\n", found("sim.dt", 2, 3)),
            (
                "[sim]\ndt = 0.01\n\n[sim]\nsubsteps = 2\n",
                found("sim", 1, 4),
            ),
            (
                "[cloth.a]\nmass = 1\n[cloth.b]\nmass = 2\n[cloth.a]\nmass = 3\n",
                found("cloth.a", 1, 5),
            ),
            (
                "[cloth.a]\nmotion = { kind = \"static\", kind = \"linear\" }\n",
                found("cloth.a.motion.kind", 2, 2),
            ),
            (
                "[cloth.a]\nmass = 1\n[cloth]\na = 5\n",
                found("cloth.a", 1, 4),
            ),
            ("sim.dt = 1\n[sim]\ndt = 2\n", found("sim", 1, 2)),
            (
                "[[collider]]\nradius = 1\n[[collider]]\nshape = \"sphere\"\nradius = 1\n\"radius\" = 2\n",
                found("collider[1].radius", 5, 6),
            ),
            (
                "[[collider]]\nparts = [{ shape = \"sphere\" }, { radius = 1, radius = 2 }]\n",
                found("collider[0].parts[1].radius", 2, 2),
            ),
            // Later errors of both kinds do not hide the first duplicate's place.
            (
                "[sim]\ndt = 1\ndt = 2\nsubsteps = 1\nsubsteps = 2\n[wind]\ndrag = 1\ndrag.x = 2\n",
                found("sim.dt", 2, 3),
            ),
        ] {
            let d = describe(text);
            assert_eq!((d.key, d.first, d.second), want, "{text}");
        }
    }
}
