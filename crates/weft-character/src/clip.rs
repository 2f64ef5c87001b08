//! A clip: poses sampled at a fixed frame time.

use crate::error::ClipError;
use crate::pose::Pose;

/// Poses at times 0, Δt, 2Δt, … for one skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    frame_time: f64,
    frames: Vec<Pose>,
}

impl Clip {
    /// A clip from its frame time Δt (s) and its frames, checking: Δt finite and positive, at
    /// least one frame, every frame with `joints` joints and finite, unit rotations.
    pub fn new(frame_time: f64, frames: Vec<Pose>, joints: usize) -> Result<Self, ClipError> {
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(ClipError::FrameTime(frame_time));
        }
        if frames.is_empty() {
            return Err(ClipError::NoFrames);
        }
        for (k, f) in frames.iter().enumerate() {
            if f.len() != joints || f.translations.len() != joints {
                return Err(ClipError::JointCount {
                    frame: k,
                    found: f.len(),
                    expected: joints,
                });
            }
            let finite = f.translations.iter().all(|t| t.is_finite())
                && f.rotations
                    .iter()
                    .all(|q| q.is_finite() && q.is_normalized());
            if !finite {
                return Err(ClipError::NotFinite { frame: k });
            }
        }
        Ok(Self { frame_time, frames })
    }

    /// Time between frames Δt (s).
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// The frames.
    pub fn frames(&self) -> &[Pose] {
        &self.frames
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }
}
