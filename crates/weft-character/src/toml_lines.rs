//! Lines of keys in TOML text, for errors that name where a bad value sits.

/// For each table of the array of tables `name` (`[[name]]`), the 1-based line of each of its
/// keys, plus the line of its header under the empty key.
pub(crate) fn array_key_lines(text: &str, name: &str) -> Vec<Vec<(String, usize)>> {
    let Ok(doc) = toml_edit::Document::parse(text.to_owned()) else {
        return Vec::new();
    };
    let Some(toml_edit::Item::ArrayOfTables(tables)) = doc.as_table().get(name) else {
        return Vec::new();
    };
    tables
        .iter()
        .map(|t| {
            let mut keys: Vec<(String, usize)> = t
                .iter()
                .filter_map(|(k, _)| {
                    let span = t.key(k).and_then(|key| key.span())?;
                    Some((k.to_owned(), line_at(text, span.start)))
                })
                .collect();
            if let Some(span) = t.span() {
                keys.push((String::new(), line_at(text, span.start)));
            }
            keys
        })
        .collect()
}

/// The line of `key` in entry `index` of `lines` (or of the entry's header).
pub(crate) fn line_in(lines: &[Vec<(String, usize)>], index: usize, key: &str) -> Option<usize> {
    let keys = lines.get(index)?;
    let find = |k: &str| keys.iter().find(|(name, _)| name == k).map(|(_, l)| *l);
    find(key).or_else(|| find(""))
}

/// 1-based line holding byte `offset` of `text`.
pub(crate) fn line_at(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}
