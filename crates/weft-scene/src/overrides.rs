//! `--set KEY=VALUE` overrides, applied to the TOML document before it is deserialised.

use std::str::FromStr;

use toml_edit::{DocumentMut, Item, Table, Value};

use crate::error::{Origin, SceneError};
use crate::source::split_key;

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
        let bad = |message: &str| SceneError {
            origin: Origin::CommandLine,
            key: s.to_owned(),
            message: message.to_owned(),
        };
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| bad("expected KEY=VALUE, e.g. sim.substeps=20"))?;
        let key = key.trim();
        let valid = !key.is_empty()
            && split_key(key).iter().all(|(name, _)| {
                !name.is_empty()
                    && name
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            });
        if !valid {
            return Err(bad(
                "the key must be dotted names such as cloth.flag.mass or collider[0].radius",
            ));
        }
        Ok(Self {
            key: key.to_owned(),
            value: value.trim().to_owned(),
        })
    }
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

/// Applies `ov` to `doc`, creating tables on the way.
pub fn apply(doc: &mut DocumentMut, ov: &Override) -> Result<(), SceneError> {
    let err = |message: String| SceneError {
        origin: Origin::CommandLine,
        key: ov.key.clone(),
        message,
    };
    let segs = split_key(&ov.key);
    let Some(((last, last_index), path)) = segs.split_last() else {
        return Err(err("empty key".into()));
    };
    let mut table: &mut Table = doc.as_table_mut();
    for &(name, index) in path {
        if !table.contains_key(name) {
            let mut t = Table::new();
            t.set_implicit(true);
            table.insert(name, Item::Table(t));
        }
        let item = table
            .get_mut(name)
            .ok_or_else(|| err(format!("cannot create `{name}`")))?;
        if let Item::Value(Value::InlineTable(_)) = item {
            // Turn an inline table into a normal one so it can be edited like the rest.
            let inline = std::mem::take(item);
            if let Item::Value(Value::InlineTable(t)) = inline {
                *item = Item::Table(t.into_table());
            }
        }
        table = match (item, index) {
            (Item::Table(t), None) => t,
            (Item::ArrayOfTables(a), Some(i)) => {
                let len = a.len();
                a.get_mut(i).ok_or_else(|| {
                    err(format!(
                        "`{name}` has {len} entries, so [{i}] does not exist"
                    ))
                })?
            }
            (Item::ArrayOfTables(_), None) => {
                return Err(err(format!(
                    "`{name}` is a list: name an entry, e.g. {name}[0]"
                )));
            }
            _ => return Err(err(format!("`{name}` is a value, not a table"))),
        };
    }
    if last_index.is_some() {
        return Err(err("the last part of the key cannot be indexed".into()));
    }
    table.insert(last, Item::Value(parse_value(&ov.value)));
    Ok(())
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

    #[test]
    fn overrides_edit_and_create_keys() {
        let mut doc: DocumentMut = "[sim]\ndt = 0.01\n\n[[collider]]\nshape = \"sphere\"\n"
            .parse()
            .expect("valid");
        for s in [
            "sim.substeps=20",
            "cloth.flag.mass=2",
            "collider[0].radius=0.5",
        ] {
            apply(&mut doc, &s.parse().expect("valid override")).expect("applies");
        }
        let text = doc.to_string();
        assert!(text.contains("substeps = 20"), "{text}");
        assert!(text.contains("[cloth.flag]\nmass = 2"), "{text}");
        assert!(text.contains("radius = 0.5"), "{text}");
        let bad = apply(&mut doc, &"collider[3].radius=1".parse().expect("valid"));
        assert!(bad.is_err());
        assert!("nokey".parse::<Override>().is_err());
    }
}
