//! What can go wrong while writing a log.

/// A log could not be written.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The MCAP writer failed (often an I/O error underneath).
    #[error("writing the MCAP log: {0}")]
    Mcap(#[from] mcap::McapError),
    /// The file could not be flushed or synced.
    #[error("writing the log file: {0}")]
    Io(#[from] std::io::Error),
    /// A JSON message could not be encoded.
    #[error("encoding a JSON message: {0}")]
    Json(#[from] serde_json::Error),
    /// A Foxglove message could not be encoded.
    #[error("encoding a Foxglove message: {0}")]
    Encode(Box<dyn std::error::Error + Send + Sync>),
    /// The log's own thread stopped without saying why.
    #[error("{0}")]
    Worker(String),
    /// The foxglove crate has no schema for a message type it should describe.
    #[error("the foxglove schema of {0} is missing")]
    SchemaMissing(&'static str),
}

/// The result of a recorder operation.
pub type Result<T> = std::result::Result<T, RecordError>;
