//! A converged reference run, for the metrics that measure how far a run's cloth is from the
//! answer (`shape_error`, `trajectory_error`): the `[reference]` table of an experiments file
//! names its overrides (typically many substeps), the reference is run once before the queue,
//! and every run is compared with it particle by particle.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::bail;
use weft_sim::Simulation;
use weft_solver::glam::DVec3;

/// Every particle of every cloth, in scene order.
fn positions(sim: &Simulation) -> Vec<DVec3> {
    (0..sim.scene.cloths.len())
        .flat_map(|i| sim.cloth_positions(i).iter().copied())
        .collect()
}

/// Root mean square of the distances between the particles of `sim` (in scene order) and
/// `there`.
fn rms_distance(sim: &Simulation, there: &[DVec3]) -> f64 {
    let here = (0..sim.scene.cloths.len()).flat_map(|i| sim.cloth_positions(i).iter());
    let sum: f64 = here.zip(there).map(|(p, q)| p.distance_squared(*q)).sum();
    (sum / there.len().max(1) as f64).sqrt()
}

/// The reference run's particles at every `every`-th frame and at its last.
#[derive(Clone, Debug)]
pub struct Reference {
    every: u64,
    dt: f64,
    /// Positions at frames 0, every, 2·every, …
    samples: Vec<Vec<DVec3>>,
    /// Positions at the last frame.
    last: Vec<DVec3>,
}

impl Reference {
    /// Runs `sim` for `frames` frames, sampling every `every`-th (at least 1, as
    /// `Spec::load` checks); `None` when stopped.
    pub fn run(
        mut sim: Simulation,
        every: u64,
        frames: u64,
        stop: &Arc<AtomicBool>,
    ) -> anyhow::Result<Option<Self>> {
        debug_assert!(every > 0, "Spec::load refuses reference.every = 0");
        sim.set_stop(Arc::clone(stop));
        let mut samples = vec![positions(&sim)];
        for f in 1..=frames {
            if stop.load(Ordering::SeqCst) {
                return Ok(None);
            }
            match sim.step() {
                Ok(_) => {}
                Err(e) if sim.interrupted(&e) => return Ok(None),
                Err(e) => bail!("the reference run diverged at frame {f}: {e}"),
            }
            if f % every == 0 {
                samples.push(positions(&sim));
            }
        }
        Ok(Some(Self {
            every,
            dt: sim.dt(),
            samples,
            last: positions(&sim),
        }))
    }

    /// A comparison of a run, starting at its initial state, with this reference; refuses a
    /// run of another particle count or frame time step.
    pub fn track(self: &Arc<Self>, sim: &Simulation) -> anyhow::Result<Tracker> {
        let n = self.last.len();
        let here: usize = (0..sim.scene.cloths.len())
            .map(|i| sim.cloth_positions(i).len())
            .sum();
        if here != n {
            bail!(
                "the run has {here} particles and the reference {n}: a reference must keep \
                 the runs' meshes"
            );
        }
        if (sim.dt() - self.dt).abs() > 1e-12 * self.dt {
            bail!(
                "the run steps {} s a frame and the reference {} s: a reference must keep \
                 the runs' frame time step (refine it with sim.substeps)",
                sim.dt(),
                self.dt
            );
        }
        let mut t = Tracker {
            reference: Arc::clone(self),
            sum_sq: 0.0,
            samples: 0,
        };
        t.frame(0, sim);
        Ok(t)
    }
}

/// A run's distance from the [`Reference`], accumulated frame by frame.
#[derive(Clone, Debug)]
pub struct Tracker {
    reference: Arc<Reference>,
    /// Σ over sampled frames of the mean squared distance.
    sum_sq: f64,
    samples: usize,
}

impl Tracker {
    /// Records the run's state after frame `frame` (a sampled frame only).
    pub fn frame(&mut self, frame: u64, sim: &Simulation) {
        let r = &self.reference;
        if frame % r.every != 0 {
            return;
        }
        if let Some(there) = usize::try_from(frame / r.every)
            .ok()
            .and_then(|k| r.samples.get(k))
        {
            self.sum_sq += rms_distance(sim, there).powi(2);
            self.samples += 1;
        }
    }

    /// RMS distance from the reference's last frame (m): the error of the rest shape when
    /// both have settled.
    pub fn shape_error(&self, sim: &Simulation) -> f64 {
        rms_distance(sim, &self.reference.last)
    }

    /// RMS distance from the reference over the sampled frames (m): the trajectory's error.
    pub fn trajectory_error(&self) -> f64 {
        (self.sum_sq / self.samples.max(1) as f64).sqrt()
    }
}
