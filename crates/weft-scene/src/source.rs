//! The scene text with spans: maps dotted keys to lines and byte offsets back to keys.

use std::collections::BTreeSet;

use toml_edit::{Document, Item, Value};

use crate::error::{Origin, SceneError};

/// A parsed scene file that remembers where every key is, plus the keys set on the command line.
#[derive(Debug)]
pub(crate) struct Source {
    path: String,
    doc: Option<Document<String>>,
    overridden: BTreeSet<String>,
}

impl Source {
    /// Parses `text` (errors are reported later, when the mutable copy is parsed).
    pub fn new(path: &str, text: &str, overridden: BTreeSet<String>) -> Self {
        Self {
            path: path.to_owned(),
            doc: Document::parse(text.to_owned()).ok(),
            overridden,
        }
    }

    /// Whether `key` (or a table holding it) was set with `--set`.
    pub fn is_overridden(&self, key: &str) -> bool {
        self.overridden.iter().any(|o| {
            key == o
                || key
                    .strip_prefix(o.as_str())
                    .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
        })
    }

    /// An error about `key`, located at the key's line or on the command line. A key the
    /// file does not have, made by a `--set` of a key below it (a table the override
    /// created), is placed at that `--set`.
    pub fn error(&self, key: &str, message: impl Into<String>) -> SceneError {
        let message = message.into();
        if self.is_overridden(key) {
            return SceneError {
                origin: Origin::CommandLine,
                key: key.to_owned(),
                message,
            };
        }
        if let Some(o) = self.made_by_override(key) {
            return SceneError {
                origin: Origin::CommandLine,
                key: o.to_owned(),
                message,
            };
        }
        SceneError {
            origin: Origin::File {
                path: self.path.clone(),
                line: self.line_of(key),
            },
            key: key.to_owned(),
            message,
        }
    }

    /// The `--set` key below `key` that made it, if the file does not have `key`.
    fn made_by_override(&self, key: &str) -> Option<&str> {
        if self.doc.is_some() && self.exact_line_of(key).is_some() {
            return None;
        }
        self.overridden
            .iter()
            .find(|o| {
                o.strip_prefix(key)
                    .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
            })
            .map(String::as_str)
    }

    /// 1-based line of `key` (or of its nearest enclosing key that exists).
    pub fn line_of(&self, key: &str) -> Option<usize> {
        self.find_line(key).map(|(line, _)| line)
    }

    /// 1-based line of `key` itself, if the file has it.
    pub fn exact_line_of(&self, key: &str) -> Option<usize> {
        self.find_line(key)
            .and_then(|(line, exact)| exact.then_some(line))
    }

    /// The line of `key` or of its nearest enclosing key that exists, and whether it is
    /// `key`'s own.
    fn find_line(&self, key: &str) -> Option<(usize, bool)> {
        let doc = self.doc.as_ref()?;
        let raw = doc.raw();
        let mut node = Node::Table(doc.as_table());
        let mut best = None;
        let mut exact = false;
        for (name, index) in split_key(key) {
            let Some((span, child)) = node.get(name) else {
                return best.map(|l| (l, false));
            };
            exact = span.is_some();
            best = span.map(|s| line_at(raw, s.start)).or(best);
            node = child;
            if let Some(i) = index {
                let Some((span, child)) = node.index(i) else {
                    return best.map(|l| (l, false));
                };
                exact = span.is_some();
                best = span.map(|s| line_at(raw, s.start)).or(best);
                node = child;
            }
        }
        best.map(|l| (l, exact))
    }
}

/// A place in the document while walking a dotted key.
#[derive(Clone, Copy)]
enum Node<'a> {
    Table(&'a toml_edit::Table),
    Item(&'a Item),
    Value(&'a Value),
}

type Span = Option<std::ops::Range<usize>>;

impl<'a> Node<'a> {
    fn get(self, name: &str) -> Option<(Span, Node<'a>)> {
        let table = match self {
            Node::Table(t) | Node::Item(Item::Table(t)) => Some(t),
            _ => None,
        };
        if let Some(t) = table {
            let item = t.get(name)?;
            let span = t.key(name).and_then(|k| k.span()).or_else(|| item.span());
            return Some((span, Node::Item(item)));
        }
        let inline = match self {
            Node::Item(Item::Value(Value::InlineTable(t))) | Node::Value(Value::InlineTable(t)) => {
                t
            }
            _ => return None,
        };
        let v = inline.get(name)?;
        let span = inline.key(name).and_then(|k| k.span()).or_else(|| v.span());
        Some((span, Node::Value(v)))
    }

    fn index(self, i: usize) -> Option<(Span, Node<'a>)> {
        match self {
            Node::Item(Item::ArrayOfTables(a)) => a.get(i).map(|t| (t.span(), Node::Table(t))),
            Node::Item(Item::Value(Value::Array(a))) | Node::Value(Value::Array(a)) => {
                a.get(i).map(|v| (v.span(), Node::Value(v)))
            }
            _ => None,
        }
    }
}

/// Splits `a.b[2].c` into `[("a", None), ("b", Some(2)), ("c", None)]`.
pub(crate) fn split_key(key: &str) -> Vec<(&str, Option<usize>)> {
    key.split('.')
        .map(|seg| match seg.split_once('[') {
            Some((name, rest)) => (name, rest.trim_end_matches(']').parse().ok()),
            None => (seg, None),
        })
        .collect()
}

/// 1-based line holding byte `offset` of `text`.
pub(crate) fn line_at(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The dotted key whose key or value span holds byte `offset` of `text`, deepest first.
pub(crate) fn key_at(text: &str, offset: usize) -> Option<String> {
    let doc = Document::parse(text.to_owned()).ok()?;
    let mut path = String::new();
    find_in_table(doc.as_table().iter_spans(), offset, &mut path).then_some(path)
}

type Entry<'a> = (&'a toml_edit::Key, &'a Item);

trait IterSpans {
    fn iter_spans(&self) -> Vec<Entry<'_>>;
}

impl IterSpans for toml_edit::Table {
    fn iter_spans(&self) -> Vec<Entry<'_>> {
        self.iter()
            .filter_map(|(k, _)| self.get_key_value(k))
            .collect()
    }
}

fn contains(span: Option<std::ops::Range<usize>>, offset: usize) -> bool {
    span.is_some_and(|s| s.start <= offset && offset < s.end.max(s.start + 1))
}

fn join(path: &mut String, seg: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(seg);
}

fn find_in_table(entries: Vec<Entry<'_>>, offset: usize, path: &mut String) -> bool {
    for (k, item) in entries {
        let base = path.len();
        join(path, k.get());
        if find_in_item(item, offset, path) || contains(k.span(), offset) {
            return true;
        }
        path.truncate(base);
    }
    false
}

fn find_in_item(item: &Item, offset: usize, path: &mut String) -> bool {
    match item {
        // A table's span is its header: an error about the table as a whole (a missing
        // key, a table where a list belongs) points there.
        Item::Table(t) => find_in_table(t.iter_spans(), offset, path) || contains(t.span(), offset),
        Item::ArrayOfTables(a) => {
            for (i, t) in a.iter().enumerate() {
                let base = path.len();
                path.push_str(&format!("[{i}]"));
                if find_in_table(t.iter_spans(), offset, path) || contains(t.span(), offset) {
                    return true;
                }
                path.truncate(base);
            }
            false
        }
        Item::Value(Value::InlineTable(t)) => {
            for (k, v) in t.iter() {
                let base = path.len();
                join(path, k);
                let key_span = t.key(k).and_then(|k| k.span());
                if find_in_value(v, offset, path) || contains(key_span, offset) {
                    return true;
                }
                path.truncate(base);
            }
            contains(item.span(), offset)
        }
        Item::Value(v) => find_in_value(v, offset, path),
        Item::None => false,
    }
}

fn find_in_value(v: &Value, offset: usize, path: &mut String) -> bool {
    match v {
        Value::InlineTable(t) => {
            for (k, v2) in t.iter() {
                let base = path.len();
                join(path, k);
                let key_span = t.key(k).and_then(|k| k.span());
                if find_in_value(v2, offset, path) || contains(key_span, offset) {
                    return true;
                }
                path.truncate(base);
            }
            contains(v.span(), offset)
        }
        _ => contains(v.span(), offset),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_map_to_lines_and_back() {
        let text = "[sim]\ndt = 0.01\n\n[cloth.flag]\nmass = 1\nmotion = { kind = \"linear\", velocity = [1, 2, 3] }\n\n[[collider]]\nshape = \"sphere\"\n\n[[collider]]\nradius = 2\n";
        let s = Source::new("x.toml", text, BTreeSet::new());
        assert_eq!(s.line_of("sim.dt"), Some(2));
        assert_eq!(s.line_of("cloth.flag.mass"), Some(5));
        assert_eq!(s.line_of("cloth.flag.motion.velocity"), Some(6));
        assert_eq!(s.line_of("collider[1].radius"), Some(12));
        let at = |needle: &str| key_at(text, text.find(needle).expect("present"));
        assert_eq!(at("0.01").as_deref(), Some("sim.dt"));
        assert_eq!(at("[1, 2").as_deref(), Some("cloth.flag.motion.velocity"));
        assert_eq!(at("2\n").as_deref(), Some("collider[1].radius"));
        // An error about a table as a whole points at its header.
        assert_eq!(at("[cloth.flag]").as_deref(), Some("cloth.flag"));
        assert_eq!(at("[[collider]]\nradius").as_deref(), Some("collider[1]"));
        assert_eq!(s.exact_line_of("collider[1]"), Some(11));
        assert_eq!(s.exact_line_of("collider[1].shape"), None);
        assert_eq!(s.line_of("collider[1].shape"), Some(11));
    }
}
