//! Fuzzing the loader and `check` (load, then build the solvers): shipped scenes mutated at
//! random (lines deleted, duplicated or given extreme values, keys misspelt or invented)
//! never panic, and every error names the file with a line or a key. Bounded (a few hundred
//! cases) so it runs in seconds; `PROPTEST_CASES` raises the count.

use std::path::Path;

use proptest::prelude::*;
use weft_scene::{DirFiles, Origin, SceneErrors};

/// Values that break things: overflow, underflow, NaN, wrong types, empty containers.
const VALUES: &[&str] = &[
    "1e308",
    "-1e308",
    "1.797e308",
    "1e-320",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "-0.0",
    "0",
    "-1",
    "99999999999999999999",
    "9223372036854775807",
    "\"x\"",
    "\"\"",
    "\"1/0\"",
    "\"0/0\"",
    "[]",
    "[1e308, 1e308]",
    "[1e-300, 1e-300]",
    "[0, 0, 0]",
    "[nan, 1, 2]",
    "[[1]]",
    "{}",
    "true",
    "2000-01-01",
];

fn shipped() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes");
    let mut v: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("assets/scenes")
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "toml").then(|| {
                (
                    p.display().to_string(),
                    std::fs::read_to_string(&p).expect("scene text"),
                )
            })
        })
        .collect();
    v.sort();
    v
}

/// One mutation: what to do, where (a line), and with which value.
#[derive(Clone, Debug)]
enum Mutation {
    Delete(usize),
    Duplicate(usize),
    Value(usize, usize),
    Misspell(usize, usize),
    Invent(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::Delete),
        any::<usize>().prop_map(Mutation::Duplicate),
        (any::<usize>(), 0..VALUES.len()).prop_map(|(l, v)| Mutation::Value(l, v)),
        (any::<usize>(), any::<usize>()).prop_map(|(l, c)| Mutation::Misspell(l, c)),
        (any::<usize>(), 0..VALUES.len()).prop_map(|(l, v)| Mutation::Invent(l, v)),
    ]
}

fn mutate(text: &str, muts: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    for m in muts {
        if lines.is_empty() {
            break;
        }
        let at = |l: usize| l % lines.len();
        // Value and key mutations pick among the lines that set a key.
        let keyed: Vec<usize> = (0..lines.len())
            .filter(|&i| lines[i].contains('=') && !lines[i].trim_start().starts_with('#'))
            .collect();
        let key_at = |l: usize| keyed.get(l % keyed.len().max(1)).copied();
        match *m {
            Mutation::Delete(l) => {
                lines.remove(at(l));
            }
            Mutation::Duplicate(l) => {
                let i = at(l);
                lines.insert(i, lines[i].clone());
            }
            Mutation::Value(l, v) => {
                let Some(i) = key_at(l) else { continue };
                if let Some((key, _)) = lines[i].split_once('=') {
                    lines[i] = format!("{key}= {}", VALUES[v]);
                }
            }
            Mutation::Misspell(l, c) => {
                let Some(i) = key_at(l) else { continue };
                if let Some((key, value)) = lines[i].split_once('=') {
                    let mut k: Vec<char> = key.trim().chars().collect();
                    if !k.is_empty() {
                        let j = c % k.len();
                        k[j] = if k[j] == 'z' { 'q' } else { 'z' };
                    }
                    lines[i] = format!("{} ={value}", k.into_iter().collect::<String>());
                }
            }
            Mutation::Invent(l, v) => {
                lines.insert(at(l), format!("fuzzed_key = {}", VALUES[v]));
            }
        }
    }
    lines.join("\n") + "\n"
}

/// Every error names the file and a line or a key (or comes from the command line); a
/// duplicate key names its key.
fn well_named(errors: &SceneErrors, name: &str) -> Result<(), String> {
    for e in &errors.0 {
        let ok = match &e.origin {
            Origin::File { path, line } => path == name && (line.is_some() || !e.key.is_empty()),
            Origin::CommandLine => !e.key.is_empty(),
        };
        // A duplicate key names the key, not only the line of its second definition.
        let duplicate = e.message.contains("duplicate key");
        if !ok || e.message.is_empty() || duplicate && e.key.is_empty() {
            return Err(format!("badly named error: {e:?}"));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 300,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mutated_scenes_never_panic_and_every_error_is_placed(
        pick in any::<usize>(),
        muts in proptest::collection::vec(mutation(), 1..6),
    ) {
        let scenes = shipped();
        let (path, text) = &scenes[pick % scenes.len()];
        let mutated = mutate(text, &muts);
        let dir = DirFiles(Path::new(path).parent().expect("dir").to_path_buf());
        match weft_scene::from_text(path, &mutated, &[], &dir) {
            Ok(scene) => {
                if let Err(e) = scene.build() {
                    let errors: SceneErrors = e.into();
                    prop_assert!(well_named(&errors, path).is_ok(), "{}\n{mutated}", errors);
                }
            }
            Err(errors) => {
                let named = well_named(&errors, path);
                prop_assert!(named.is_ok(), "{named:?}\n{errors}\n---\n{mutated}");
            }
        }
    }
}
