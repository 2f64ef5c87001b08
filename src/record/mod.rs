//! Logging runs to MCAP: Foxglove messages and the writer.

pub mod messages;
mod writer;

pub use writer::{RecordOptions, Recorder, Status};
