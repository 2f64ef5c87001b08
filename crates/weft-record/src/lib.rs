//! Weft's MCAP logs: Foxglove messages for cloth particles, surfaces, colliders and a
//! character's body ([`messages`], [`collider_state`]), the recorder that writes a run on its
//! own thread ([`Recorder`]), what a log carries ([`RecordOptions`]), and the check that a log
//! is whole ([`verify`]).
//!
//! The crate's modules:
//!
//! - `body`: the character's body on `/colliders`, each part drawn as Foxglove primitives.
//! - `collider_state`: the `/colliders/state` channel: every collider's pose at a frame, as JSON.
//! - `error`: what can go wrong while writing a log.
//! - `layout`: a log's opening: schemas, channels, and the scene and settings it carries.
//! - `messages`: Foxglove well-known messages for cloth particles, cloth surfaces and colliders.
//! - `options`: what a log carries: which cloth channels, which frames, at what precision.
//! - `sink`: the log's file, counting the bytes written so far for a progress line.
//! - `stats`: `/stats`: one JSON message per logged frame, and its JSON Schema.
//! - `status`: how a run ended.
//! - `surface`: a cloth's surface message, with what every frame repeats encoded once.
//! - `verify`: the check that a log is whole and every CRC intact.
//! - `worker`: the log's own thread, encoding, compressing and writing frames in order.
//! - `writer`: the recorder, handing each frame to the log's thread through a bounded queue.

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
