//! glTF node animation channels: key times and translation, rotation or scale values,
//! interpolated linearly (slerp for rotations) or stepwise.

use glam::{DQuat, DVec3};

/// How a channel interpolates between keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// Linear (slerp for rotations).
    Linear,
    /// Hold each key until the next.
    Step,
}

/// Key values of one channel.
#[derive(Clone, Debug, PartialEq)]
pub enum ChannelValues {
    /// Translations.
    Translation(Vec<DVec3>),
    /// Rotations (unit quaternions).
    Rotation(Vec<DQuat>),
    /// Scales.
    Scale(Vec<DVec3>),
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Target node.
    pub node: usize,
    /// Key times (s), increasing.
    pub times: Vec<f64>,
    /// Key values, one per time.
    pub values: ChannelValues,
    /// Interpolation.
    pub interpolation: Interpolation,
}

impl Channel {
    /// The keys around `t` (clamped) and the fraction between them.
    fn bracket(&self, t: f64) -> (usize, usize, f64) {
        let n = self.times.len();
        if n == 0 || t <= self.times[0] || t.is_nan() {
            return (0, 0, 0.0);
        }
        if t >= self.times[n - 1] {
            return (n - 1, n - 1, 0.0);
        }
        let j = self.times.partition_point(|&k| k <= t);
        let i = j - 1;
        let span = self.times[j] - self.times[i];
        let f = if span > 0.0 {
            (t - self.times[i]) / span
        } else {
            0.0
        };
        match self.interpolation {
            Interpolation::Linear => (i, j, f),
            Interpolation::Step => (i, i, 0.0),
        }
    }

    /// Overwrites the animated part of a node's (translation, rotation, scale) at time `t`.
    pub fn apply(&self, t: f64, trs: &mut (DVec3, DQuat, DVec3)) {
        if self.times.is_empty() {
            return;
        }
        let (i, j, f) = self.bracket(t);
        match &self.values {
            ChannelValues::Translation(v) => trs.0 = v[i].lerp(v[j], f),
            ChannelValues::Rotation(v) => trs.1 = v[i].slerp(v[j], f).normalize(),
            ChannelValues::Scale(v) => trs.2 = v[i].lerp(v[j], f),
        }
    }
}
