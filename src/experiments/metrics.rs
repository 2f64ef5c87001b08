//! Metrics of one run, measured while it steps.

use serde::{Deserialize, Serialize};

use crate::experiments::cantilever::Strip;
use crate::experiments::reference::Tracker;
use weft_sim::{FrameStats, Simulation};
use weft_solver::Drape;

/// A quantity reported per run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// Drop of the lowest particle from its rest height at the end (m).
    Sag,
    /// Largest |C| over all frames (m).
    StretchErrorMax,
    /// Largest per-frame RMS |C| over all frames (m).
    StretchErrorRms,
    /// Largest |C| at the last frame (m).
    FinalStretchError,
    /// Kinetic energy at the last frame (J).
    KineticEnergy,
    /// Wall-clock milliseconds per frame (not deterministic).
    MsPerFrame,
    /// Constraint sweeps per frame: substeps × iterations.
    Cost,
    /// Frames simulated.
    Frames,
    /// Cantilever: the chord from clamp to tip, degrees below the horizontal.
    ChordAngle,
    /// Cantilever: the heavy elastica's chord angle for the strip (degrees).
    ElasticaAngle,
    /// Cantilever: chord angle minus the elastica's (degrees).
    AngleError,
    /// Cusick drape test: the share of the free annulus the disc's shadow covers (1 flat).
    DrapeCoefficient,
    /// RMS distance of the particles from the reference's at the last frame (m).
    ShapeError,
    /// RMS distance of the particles from the reference's over its sampled frames (m).
    TrajectoryError,
}

impl Metric {
    /// Name as written in files and table headers.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Sag => "sag",
            Metric::StretchErrorMax => "stretch_error_max",
            Metric::StretchErrorRms => "stretch_error_rms",
            Metric::FinalStretchError => "final_stretch_error",
            Metric::KineticEnergy => "kinetic_energy",
            Metric::MsPerFrame => "ms_per_frame",
            Metric::Cost => "cost",
            Metric::Frames => "frames",
            Metric::ChordAngle => "chord_angle",
            Metric::ElasticaAngle => "elastica_angle",
            Metric::AngleError => "angle_error",
            Metric::DrapeCoefficient => "drape_coefficient",
            Metric::ShapeError => "shape_error",
            Metric::TrajectoryError => "trajectory_error",
        }
    }

    /// Whether the metric measures the cloth's state (a diverged run's value then describes a
    /// blown-up cloth), rather than the run's cost, length or reference.
    pub fn measures_state(self) -> bool {
        !matches!(
            self,
            Metric::MsPerFrame | Metric::Cost | Metric::Frames | Metric::ElasticaAngle
        )
    }

    /// Unit for axis labels.
    pub fn unit(self) -> &'static str {
        match self {
            Metric::Sag | Metric::StretchErrorMax | Metric::StretchErrorRms => "m",
            Metric::FinalStretchError => "m",
            Metric::KineticEnergy => "J",
            Metric::MsPerFrame => "ms",
            Metric::Cost => "sweeps/frame",
            Metric::Frames => "frames",
            Metric::ChordAngle | Metric::ElasticaAngle | Metric::AngleError => "°",
            Metric::DrapeCoefficient => "",
            Metric::ShapeError | Metric::TrajectoryError => "m",
        }
    }

    /// Every metric.
    pub const ALL: [Metric; 14] = [
        Metric::Sag,
        Metric::StretchErrorMax,
        Metric::StretchErrorRms,
        Metric::FinalStretchError,
        Metric::KineticEnergy,
        Metric::MsPerFrame,
        Metric::Cost,
        Metric::Frames,
        Metric::ChordAngle,
        Metric::ElasticaAngle,
        Metric::AngleError,
        Metric::DrapeCoefficient,
        Metric::ShapeError,
        Metric::TrajectoryError,
    ];

    /// Whether the metric is measured against a `[reference]` run.
    pub fn needs_reference(self) -> bool {
        matches!(self, Metric::ShapeError | Metric::TrajectoryError)
    }

    /// The metric called `name`.
    pub fn from_name(name: &str) -> Option<Metric> {
        Metric::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// Accumulates a run's metrics frame by frame.
#[derive(Clone, Debug, Default)]
pub struct Meter {
    rest_lowest: f64,
    worst_max: f64,
    worst_rms: f64,
    last: FrameStats,
    wall_ms: f64,
    strip: Option<Strip>,
    /// The first disc cloth (`disc_radius`) and its flat shadow.
    drape: Option<(usize, Drape)>,
    /// The run against the experiment's reference, when it has one.
    reference: Option<Tracker>,
}

fn lowest(sim: &Simulation) -> f64 {
    (0..sim.scene.cloths.len())
        .flat_map(|i| sim.cloth_positions(i).iter().map(|p| p.y))
        .fold(f64::INFINITY, f64::min)
}

/// The first cloth cut to a disc (`disc_radius`) and its [`Drape`] at rest, its support the
/// clamp (`clamp_radius`).
fn drape(sim: &Simulation) -> Option<(usize, Drape)> {
    sim.scene.cloths.iter().enumerate().find_map(|(i, c)| {
        let section = sim.scene.file.cloth.get(&c.name)?;
        let radius = section.disc_radius?;
        let clamp = section.clamp_radius.unwrap_or(0.0);
        let drape = Drape::new(&c.mesh.positions, &c.mesh.triangles, radius, clamp);
        Some((i, drape))
    })
}

impl Meter {
    /// Starts at the initial state; `strip` is the run's cantilever, `reference` its
    /// comparison with the experiment's reference, if it has them.
    pub fn new(sim: &Simulation, strip: Option<Strip>, reference: Option<Tracker>) -> Self {
        Self {
            rest_lowest: lowest(sim),
            strip,
            drape: drape(sim),
            reference,
            ..Self::default()
        }
    }

    /// Records one stepped frame, `sim` as it left it.
    pub fn frame(&mut self, stats: &FrameStats, sim: &Simulation) {
        self.worst_max = self.worst_max.max(stats.residual_max);
        self.worst_rms = self.worst_rms.max(stats.residual_rms);
        self.wall_ms += stats.step_ms;
        self.last = *stats;
        if let Some(t) = self.reference.as_mut() {
            t.frame(stats.frame, sim);
        }
    }

    /// Every metric of the run so far.
    pub fn values(&self, sim: &Simulation) -> Vec<(Metric, f64)> {
        let s = sim.scene.settings;
        let frames = self.last.frame;
        let chord = self
            .strip
            .map_or(f64::NAN, |t| t.chord_angle(sim.cloth_positions(t.cloth)));
        let elastica = self.strip.map_or(f64::NAN, |t| t.elastica_angle());
        let drape = self.drape.map_or(f64::NAN, |(i, d)| {
            d.coefficient(sim.cloth_positions(i), &sim.scene.cloths[i].mesh.triangles)
        });
        Metric::ALL
            .into_iter()
            .map(|m| {
                let v = match m {
                    Metric::Sag => self.rest_lowest - lowest(sim),
                    Metric::StretchErrorMax => self.worst_max,
                    Metric::StretchErrorRms => self.worst_rms,
                    Metric::FinalStretchError => self.last.residual_max,
                    Metric::KineticEnergy => self.last.kinetic_energy,
                    Metric::MsPerFrame => self.wall_ms / frames.max(1) as f64,
                    Metric::Cost => f64::from(s.substeps * s.iterations),
                    Metric::Frames => frames as f64,
                    Metric::ChordAngle => chord,
                    Metric::ElasticaAngle => elastica,
                    Metric::AngleError => chord - elastica,
                    Metric::DrapeCoefficient => drape,
                    Metric::ShapeError => self
                        .reference
                        .as_ref()
                        .map_or(f64::NAN, |t| t.shape_error(sim)),
                    Metric::TrajectoryError => self
                        .reference
                        .as_ref()
                        .map_or(f64::NAN, Tracker::trajectory_error),
                };
                (m, v)
            })
            .collect()
    }
}
