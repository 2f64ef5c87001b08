//! Logging runs to MCAP: Foxglove messages and the writer.

pub mod messages;
pub mod verify;
mod writer;

pub use writer::{RecordOptions, Recorder, Status};
