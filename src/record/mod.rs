//! Logging runs to MCAP: Foxglove messages and the writer.

mod body;
pub mod collider_state;
pub mod messages;
pub mod verify;
mod writer;

pub use writer::{CHANNELS, RecordOptions, Recorder, Status, foxglove_schema};
