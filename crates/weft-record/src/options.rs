//! What a log carries: which cloth channels, which frames, at what precision.

use std::fmt;
use std::str::FromStr;

/// The per-frame cloth channels a log carries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Channels {
    /// `/cloth/<name>/particles` only: the positions, the smallest log and the fastest.
    #[default]
    Particles,
    /// `/cloth/<name>/mesh` only: the surface as a triangle list, what Foxglove draws.
    Surface,
    /// Both (the surface every `mesh_every` frames).
    All,
}

/// How the log's chunks are compressed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compression {
    /// Not at all: the log keeps pace with the solver (docs/performance-notes.md, "Logging").
    #[default]
    None,
    /// zstd at level [`crate::ZSTD_LEVEL`], on one worker per core (the bytes do not depend on
    /// the number of workers): about half the bytes of float data, at about 0.4 GB/s a core.
    Zstd,
}

/// How particle positions are stored on `/cloth/<name>/particles`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// IEEE float32 `x`, `y`, `z` (Foxglove's FLOAT32): within 2⁻²⁴ of each coordinate.
    #[default]
    F32,
    /// IEEE binary16 `x_f16`, `y_f16`, `z_f16` (declared UINT16, Foxglove has no 16-bit float):
    /// half the bytes, within 2⁻¹¹ of each coordinate (0.49 mm at 1 m from the origin).
    F16,
}

/// What a run logs besides particles, and how.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RecordOptions {
    /// The cloth channels.
    pub channels: Channels,
    /// Log every this many frames (1: every frame; frame 0 always).
    pub every: u64,
    /// With [`Channels::All`], log the surface every this many frames (0: never).
    pub mesh_every: u64,
    /// Particle precision.
    pub precision: Precision,
    /// Chunk compression.
    pub compression: Compression,
    /// Add wall-clock step time and the wait for the log to `/stats` (makes files differ
    /// between runs).
    pub timing: bool,
}

impl Default for RecordOptions {
    fn default() -> Self {
        Self {
            channels: Channels::Particles,
            every: 1,
            mesh_every: 1,
            precision: Precision::F32,
            compression: Compression::None,
            timing: false,
        }
    }
}

impl RecordOptions {
    /// Whether frame `frame` is logged.
    pub fn logs_frame(&self, frame: u64) -> bool {
        self.every <= 1 || frame % self.every == 0
    }

    /// Whether the particle channels exist.
    pub fn logs_particles(&self) -> bool {
        self.channels != Channels::Surface
    }

    /// Whether the surface channels exist.
    pub fn has_surface(&self) -> bool {
        match self.channels {
            Channels::Particles => false,
            Channels::Surface => true,
            Channels::All => self.mesh_every > 0,
        }
    }

    /// Whether a logged frame `frame` carries the surface.
    pub fn logs_surface(&self, frame: u64) -> bool {
        match self.channels {
            Channels::Particles => false,
            Channels::Surface => true,
            Channels::All => self.mesh_every > 0 && frame % self.mesh_every == 0,
        }
    }
}

/// A name that is not one of a choice's values.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{given}` is not one of {expected}")]
pub struct UnknownChoice {
    given: String,
    expected: &'static str,
}

macro_rules! named {
    ($ty:ty, $expected:literal, $($variant:path => $name:literal),+) => {
        impl $ty {
            /// The name the command line and the log's `weft.run` metadata use.
            pub fn name(self) -> &'static str {
                match self { $($variant => $name),+ }
            }
        }
        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
        impl FromStr for $ty {
            type Err = UnknownChoice;
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                match s {
                    $($name => Ok($variant),)+
                    _ => Err(UnknownChoice { given: s.to_owned(), expected: $expected }),
                }
            }
        }
    };
}

named!(Channels, "particles, surface, all",
    Channels::Particles => "particles", Channels::Surface => "surface", Channels::All => "all");
named!(Precision, "f32, f16", Precision::F32 => "f32", Precision::F16 => "f16");
named!(Compression, "none, zstd", Compression::None => "none", Compression::Zstd => "zstd");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_ones_are_refused() {
        for c in [Channels::Particles, Channels::Surface, Channels::All] {
            assert_eq!(c.name().parse::<Channels>(), Ok(c));
        }
        for p in [Precision::F32, Precision::F16] {
            assert_eq!(p.name().parse::<Precision>(), Ok(p));
        }
        for c in [Compression::None, Compression::Zstd] {
            assert_eq!(c.name().parse::<Compression>(), Ok(c));
        }
        let e = "mesh".parse::<Channels>().expect_err("not a choice");
        assert_eq!(
            e.to_string(),
            "`mesh` is not one of particles, surface, all"
        );
    }

    #[test]
    fn frames_and_surfaces_follow_every_and_mesh_every() {
        let o = RecordOptions {
            channels: Channels::All,
            every: 3,
            mesh_every: 2,
            ..RecordOptions::default()
        };
        let logged: Vec<u64> = (0..10).filter(|&f| o.logs_frame(f)).collect();
        assert_eq!(logged, [0, 3, 6, 9]);
        assert!(o.logs_surface(6) && !o.logs_surface(3));
        let surface = RecordOptions {
            channels: Channels::Surface,
            mesh_every: 0,
            ..o
        };
        assert!(surface.logs_surface(3) && surface.has_surface() && !surface.logs_particles());
        let particles = RecordOptions {
            channels: Channels::Particles,
            ..o
        };
        assert!(!particles.has_surface() && !particles.logs_surface(0));
    }
}
