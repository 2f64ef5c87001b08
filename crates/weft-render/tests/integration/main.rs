//! weft-render's integration tests, linked into one test binary.
//!
//! One binary instead of one per file keeps the test build small on disk and quick to link.

mod offscreen;
mod tiles;
