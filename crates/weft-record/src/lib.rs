//! Weft's MCAP logs: Foxglove messages for cloth particles, surfaces, colliders and a
//! character's body ([`messages`], [`collider_state`]), the recorder that writes a run on its
//! own thread ([`Recorder`]), what a log carries ([`RecordOptions`]), and the check that a log
//! is whole ([`verify`]).

mod body;
pub mod collider_state;
mod error;
mod layout;
pub mod messages;
mod options;
mod sink;
mod stats;
mod status;
mod surface;
pub mod verify;
mod worker;
mod writer;

pub use error::{RecordError, Result};
pub use layout::{CHANNELS, ZSTD_LEVEL, foxglove_schema};
pub use options::{Channels, Compression, Precision, RecordOptions, UnknownChoice};
pub use stats::STATS_SCHEMA;
pub use status::Status;
pub use writer::{LogProgress, QUEUE_BYTES, Recorder};
