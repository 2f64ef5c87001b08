//! The `weft` binary's integration tests: one test binary (one link of wgpu, winit and egui) holding every module.
//!
//! One binary instead of one per file keeps the test build small on disk and quick to link.

mod common;

mod bad_input;
mod collider_state;
mod crossing_report;
mod e2e_drag;
mod e2e_keys;
mod e2e_view;
mod experiments;
mod export;
mod export_body;
mod fabric;
mod fuzz_inputs;
mod hostile_names;
mod limits;
mod mcap_log;
mod output_safety;
mod recorder;
mod recover;
mod render_video;
mod replay;
mod seam_warning;
mod small_things;
mod stability_warning;
mod stops;
mod viewer;
