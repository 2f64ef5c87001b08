//! Weft's MCAP logs: Foxglove messages for cloth particles, surfaces, colliders and a
//! character's body ([`messages`], [`collider_state`]), the recorder that writes a run
//! ([`Recorder`]), and the check that a log is whole ([`verify`]).

mod body;
pub mod collider_state;
mod error;
pub mod messages;
pub mod verify;
mod writer;

pub use error::{RecordError, Result};
pub use writer::{CHANNELS, RecordOptions, Recorder, Status, foxglove_schema};
