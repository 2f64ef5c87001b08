//! Scene errors: each names where the bad value came from (file and line, or the command line)
//! and its dotted key.

use std::fmt;

use thiserror::Error;

/// Where a value came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A scene file, at a line when known.
    File {
        /// The file as given.
        path: String,
        /// 1-based line.
        line: Option<usize>,
    },
    /// A `--set KEY=VALUE` on the command line.
    CommandLine,
}

/// One problem with a scene: origin, dotted key and message.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub struct SceneError {
    /// Where the value came from.
    pub origin: Origin,
    /// Dotted key, e.g. `cloth.flag.stretch_compliance` (empty when the file as a whole is bad).
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.origin {
            Origin::File {
                path,
                line: Some(l),
            } => write!(f, "{path}:{l}: ")?,
            Origin::File { path, line: None } => write!(f, "{path}: ")?,
            Origin::CommandLine => write!(f, "command line (--set {}): ", elide(&self.key))?,
        }
        if !self.key.is_empty() {
            write!(f, "{}: ", elide(&self.key))?;
        }
        f.write_str(&elide(&self.message))
    }
}

/// The longest run of non-blank characters a message shows whole.
pub const LONGEST_WORD: usize = 64;

/// `s` with every run of non-blank characters longer than [`LONGEST_WORD`] cut to that many
/// and `…`, so an error never echoes a huge bad value in full.
pub fn elide(s: &str) -> String {
    let mut out = String::with_capacity(s.len().min(4096));
    let mut run = 0;
    for ch in s.chars() {
        if ch.is_whitespace() {
            run = 0;
            out.push(ch);
            continue;
        }
        run += 1;
        if run <= LONGEST_WORD {
            out.push(ch);
        } else if run == LONGEST_WORD + 1 {
            out.push('…');
        }
    }
    out
}

/// Every problem found in a scene (at least one).
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub struct SceneErrors(pub Vec<SceneError>);

impl fmt::Display for SceneErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl From<SceneError> for SceneErrors {
    fn from(e: SceneError) -> Self {
        Self(vec![e])
    }
}
