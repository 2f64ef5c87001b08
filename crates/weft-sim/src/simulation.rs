//! A scene's solvers stepped in lockstep, one frame at a time.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use weft_scene::{Scene, SceneError, SolverGroup};
use weft_solver::SolverError;
use weft_solver::glam::DVec3;

/// What one frame did, summed over the scene's solvers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Frame number (0 is the initial state).
    pub frame: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Kinetic energy of every particle (J).
    pub kinetic_energy: f64,
    /// Largest |C| over distance-like constraints (m).
    pub residual_max: f64,
    /// Largest per-solver RMS |C| (m).
    pub residual_rms: f64,
    /// Contacts in the last substep.
    pub contacts: usize,
    /// Wall-clock time of the step (ms); not deterministic.
    pub step_ms: f64,
}

/// A scene and its solvers.
pub struct Simulation {
    /// The validated scene.
    pub scene: Scene,
    /// One solver per method.
    pub groups: Vec<SolverGroup>,
    /// For each scene cloth: its solver and particle range.
    places: Vec<(usize, Range<usize>)>,
    frame: u64,
}

impl Simulation {
    /// Builds the scene's solvers.
    pub fn new(scene: Scene) -> Result<Self, SceneError> {
        let groups = scene.build()?;
        let mut places = vec![(0, 0..0); scene.cloths.len()];
        for (g, group) in groups.iter().enumerate() {
            for (j, &i) in group.cloths.iter().enumerate() {
                places[i] = (g, group.solver.cloths()[j].particles.clone());
            }
        }
        Ok(Self {
            scene,
            groups,
            places,
            frame: 0,
        })
    }

    /// Lets every solver poll `stop` once per substep (see `Solver::set_stop`), and its
    /// collision world inside its longest work.
    pub fn set_stop(&mut self, stop: Arc<AtomicBool>) {
        for g in &mut self.groups {
            g.solver.set_stop(Arc::clone(&stop));
            if let Some(w) = &mut g.world {
                w.set_stop(Arc::clone(&stop));
            }
        }
    }

    /// Whether `e` is a stop (the frame in progress abandoned), not a failure.
    pub fn interrupted(&self, e: &SolverError) -> bool {
        matches!(e, SolverError::Interrupted { .. })
    }

    /// Frames stepped so far.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.frame as f64 * self.scene.settings.dt
    }

    /// Positions of scene cloth `i`, in particle order.
    pub fn cloth_positions(&self, i: usize) -> &[DVec3] {
        let (g, range) = &self.places[i];
        &self.groups[*g].solver.particles().positions[range.clone()]
    }

    /// Statistics of the current state.
    pub fn stats(&self, step_ms: f64, contacts: usize) -> FrameStats {
        let mut s = FrameStats {
            frame: self.frame,
            time: self.time(),
            step_ms,
            contacts,
            ..FrameStats::default()
        };
        for g in &self.groups {
            let r = g.solver.residual();
            s.kinetic_energy += g.solver.particles().kinetic_energy();
            s.residual_max = s.residual_max.max(r.max);
            s.residual_rms = s.residual_rms.max(r.rms);
        }
        s
    }

    /// Steps every solver one frame; on divergence the state is left as the solver left it.
    pub fn step(&mut self) -> Result<FrameStats, SolverError> {
        let start = Instant::now();
        let mut contacts = 0;
        for g in &mut self.groups {
            contacts += g.step()?.contacts;
        }
        self.frame += 1;
        Ok(self.stats(start.elapsed().as_secs_f64() * 1e3, contacts))
    }
}
