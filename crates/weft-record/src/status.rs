//! How a run ended.

/// How a run ended, written as the `weft.status` metadata record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    /// Every requested frame was simulated.
    Complete,
    /// SIGINT or SIGTERM stopped the run.
    Interrupted,
    /// The simulation diverged; the message says where.
    Diverged(String),
}

impl Status {
    /// The status's name in the log.
    pub(crate) fn name(&self) -> &'static str {
        match self {
            Status::Complete => "complete",
            Status::Interrupted => "interrupted",
            Status::Diverged(_) => "diverged",
        }
    }
}
