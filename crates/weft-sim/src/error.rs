//! What a grab or a live control refuses, in words that name the key, the cloth or the value.

use thiserror::Error;
use weft_solver::{ParamError, SolverError};

/// A refused grab, drag or live change; nothing was changed.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SimError {
    /// No cloth of the scene has this name.
    #[error("no cloth named `{name}`: the scene's cloths are {known}")]
    NoSuchCloth {
        /// The name given.
        name: String,
        /// The scene's cloth names, quoted and joined.
        known: String,
    },
    /// A particle index beyond the cloth's particles.
    #[error("cloth `{cloth}` has {count} particles: there is no particle {index}")]
    NoSuchParticle {
        /// The cloth's name.
        cloth: String,
        /// The index given.
        index: usize,
        /// The cloth's particle count.
        count: usize,
    },
    /// A key that names no live control.
    #[error("`{key}` is not a live setting: {hint}")]
    UnknownKey {
        /// The key given.
        key: String,
        /// What the key may be instead.
        hint: String,
    },
    /// A value of the wrong kind or outside its range for its key.
    #[error("`{key}`: expected {expected}, got {got}")]
    BadValue {
        /// The key (or argument) given.
        key: String,
        /// What was expected.
        expected: String,
        /// The value given, in words.
        got: String,
    },
    /// The solver refused the value (out of its range).
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The solver refused the grab.
    #[error(transparent)]
    Solver(#[from] SolverError),
}
