//! What drives a deforming mesh collider: the vertex positions at any time, evaluated by the
//! collision world at the end of every frame (a skinned body, keyframes, a procedure); the
//! vertices move linearly between those over the frame's substeps.

use glam::DVec3;

use crate::error::ShapeError;

/// A source of a deforming mesh's vertices: positions at time `t`, in the collider's frame.
///
/// Called once per frame, at the frame's end time, from the collision world, with the rest
/// vertices (those of the collider's `TriangleMesh`) and an output of the same length; the
/// mesh moves linearly there over the frame's substeps. Non-finite output keeps the previous
/// positions for that frame.
pub trait MeshAnimation: Send + Sync {
    /// Writes the vertex positions at time `t` (s) into `out` (one per rest vertex).
    fn vertices_at(&self, t: f64, rest: &[DVec3], out: &mut [DVec3]);
}

impl<F: Fn(f64, &[DVec3], &mut [DVec3]) + Send + Sync> MeshAnimation for F {
    fn vertices_at(&self, t: f64, rest: &[DVec3], out: &mut [DVec3]) {
        self(t, rest, out);
    }
}

/// Vertex keyframes, linearly interpolated in time and held before the first and after the
/// last (a baked animation, or a blade swept across a scene).
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframes {
    times: Vec<f64>,
    frames: Vec<Vec<DVec3>>,
}

impl Keyframes {
    /// Keyframes at increasing finite `times` (s), each frame one position per vertex.
    pub fn new(times: Vec<f64>, frames: Vec<Vec<DVec3>>) -> Result<Self, ShapeError> {
        let bad = |expected| ShapeError::InvalidParameter {
            name: "keyframes",
            value: times.len() as f64,
            expected,
        };
        if times.is_empty() || times.len() != frames.len() {
            return Err(bad("as many key times as frames, at least one"));
        }
        if !times.iter().all(|t| t.is_finite()) || times.windows(2).any(|w| w[1] <= w[0]) {
            return Err(bad("finite, increasing key times"));
        }
        let n = frames[0].len();
        if frames
            .iter()
            .any(|f| f.len() != n || !f.iter().all(|v| v.is_finite()))
        {
            return Err(bad("frames of equal length with finite positions"));
        }
        Ok(Self { times, frames })
    }

    /// Vertices per frame.
    pub fn vertex_count(&self) -> usize {
        self.frames[0].len()
    }
}

impl MeshAnimation for Keyframes {
    fn vertices_at(&self, t: f64, _rest: &[DVec3], out: &mut [DVec3]) {
        let k = self.times.partition_point(|&s| s <= t);
        let n = self.frames.len();
        let (a, b, w) = if k == 0 {
            (0, 0, 0.0)
        } else if k >= n {
            (n - 1, n - 1, 0.0)
        } else {
            let (t0, t1) = (self.times[k - 1], self.times[k]);
            (k - 1, k, (t - t0) / (t1 - t0))
        };
        for ((o, p), q) in out.iter_mut().zip(&self.frames[a]).zip(&self.frames[b]) {
            *o = *p + (*q - *p) * w;
        }
    }
}
