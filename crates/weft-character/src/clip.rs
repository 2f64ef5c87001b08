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

/// What sampling does outside the clip's frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Hold the first frame before 0 and the last after (n − 1) Δt.
    #[default]
    Clamp,
    /// Repeat with period n Δt; between the last frame and the first the pose is
    /// interpolated like between any two frames (for clips whose last frame leads into the
    /// first, such as the built-in walk cycle).
    Loop,
}

impl Clip {
    /// Length of the clip (s): (n − 1) Δt when clamped, n Δt (one period) when looping.
    pub fn duration(&self, wrap: Wrap) -> f64 {
        let n = self.frames.len() as f64;
        match wrap {
            Wrap::Clamp => (n - 1.0) * self.frame_time,
            Wrap::Loop => n * self.frame_time,
        }
    }

    /// The two frames around time `t` (s) and the fraction between them.
    pub fn bracket(&self, t: f64, wrap: Wrap) -> (usize, usize, f64) {
        let n = self.frames.len();
        let u = t / self.frame_time;
        match wrap {
            Wrap::Clamp => {
                if n == 1 || u.is_nan() || u <= 0.0 {
                    return (0, 0, 0.0);
                }
                let last = (n - 1) as f64;
                if u >= last {
                    return (n - 1, n - 1, 0.0);
                }
                let i = (u.floor() as usize).min(n - 2);
                (i, i + 1, u - i as f64)
            }
            Wrap::Loop => {
                let u = u.rem_euclid(n as f64);
                if !u.is_finite() {
                    return (0, 0, 0.0);
                }
                let i = (u.floor() as usize).min(n - 1);
                (i, (i + 1) % n, (u - i as f64).clamp(0.0, 1.0))
            }
        }
    }

    /// The pose at time `t` (s): rotations slerped, translations lerped between the frames
    /// around `t`.
    pub fn sample(&self, t: f64, wrap: Wrap) -> Pose {
        let mut out = Pose::identity(0);
        self.sample_into(t, wrap, &mut out);
        out
    }

    /// [`Clip::sample`] into a reused pose.
    pub fn sample_into(&self, t: f64, wrap: Wrap, out: &mut Pose) {
        let (i, j, f) = self.bracket(t, wrap);
        Pose::interpolate_into(&self.frames[i], &self.frames[j], f, out);
    }
}
