//! A scene's solvers stepped in lockstep, one frame at a time.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use weft_scene::{Scene, SceneError, SolverGroup};
use weft_solver::SolverError;
use weft_solver::glam::DVec3;

use crate::SimError;
use crate::crossings::{self, CrossingStats, SolverMesh, StartCrossing};

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
    /// Conjugate-gradient iterations of the frame: implicit mass-spring's, and XPBD's bending or
    /// joint solves (0 where neither runs).
    pub cg_iterations: u64,
    /// The largest XPBD bending residual of the last substep over the solvers
    /// (`Solver::bending_residual`: 0 converged, 1 a hinge about twice too soft); `None`
    /// without XPBD bending.
    pub bending_residual: Option<f64>,
    /// Wall-clock time of the step (ms); not deterministic.
    pub step_ms: f64,
    /// Cloth crossings and the closest approach, when measured (see
    /// [`Simulation::set_measure_crossings`]).
    pub crossings: Option<CrossingStats>,
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
    /// The frame time step in use (s): the scene's until a live change.
    dt: f64,
    /// Where the current time step took over: (frame, simulated time then).
    epoch: (u64, f64),
    /// Each solver's mesh as crossings are measured on it, when they are.
    crossing_meshes: Option<Vec<SolverMesh>>,
    /// Cloth crossing itself or another cloth at the start.
    start_crossings: Vec<StartCrossing>,
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
        let dt = scene.settings.dt;
        let start_crossings = crossings::start_crossings(&scene, &groups);
        let mut sim = Self {
            scene,
            groups,
            places,
            frame: 0,
            dt,
            epoch: (0, 0.0),
            crossing_meshes: None,
            start_crossings,
        };
        sim.set_measure_crossings(crossings::cloth_meets_cloth(&sim.scene, &sim.groups));
        Ok(sim)
    }

    /// Measures cloth crossings in every frame's statistics ([`FrameStats::crossings`]), or
    /// stops. On by default where cloth can meet cloth (self-collision on, or two cloths in one
    /// solver), off elsewhere: the measure costs about what a frame of contact does.
    pub fn set_measure_crossings(&mut self, on: bool) {
        self.crossing_meshes = on.then(|| {
            self.groups
                .iter()
                .map(|g| SolverMesh::new(&self.scene, g))
                .collect()
        });
    }

    /// Whether crossings are measured.
    pub fn measures_crossings(&self) -> bool {
        self.crossing_meshes.is_some()
    }

    /// Cloth that crossed itself or another cloth of its solver when the scene was built: the
    /// run goes on (contact cannot undo a crossing it did not cause), a warning is due.
    pub fn start_crossings(&self) -> &[StartCrossing] {
        &self.start_crossings
    }

    /// The crossings of the present state, measured whether or not frames measure them.
    pub fn crossings_now(&self) -> CrossingStats {
        let measure = |meshes: &[SolverMesh]| {
            crossings::combine(self.groups.iter().zip(meshes).map(|(g, m)| m.measure(g)))
        };
        match &self.crossing_meshes {
            Some(m) => measure(m),
            None => measure(
                &self
                    .groups
                    .iter()
                    .map(|g| SolverMesh::new(&self.scene, g))
                    .collect::<Vec<_>>(),
            ),
        }
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

    /// Simulated time (s): frames × the scene's time step, until a live change of the time
    /// step (see [`Simulation::set_settings`]) starts a new epoch.
    pub fn time(&self) -> f64 {
        let (frame, time) = self.epoch;
        if frame == 0 {
            self.frame as f64 * self.dt
        } else {
            time + (self.frame - frame) as f64 * self.dt
        }
    }

    /// The frame time step in use (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Takes `dt` as the time step from the current frame on.
    pub(crate) fn new_epoch(&mut self, dt: f64) {
        self.epoch = (self.frame, self.time());
        self.dt = dt;
    }

    /// Positions of scene cloth `i`, in particle order.
    pub fn cloth_positions(&self, i: usize) -> &[DVec3] {
        let (g, range) = &self.places[i];
        &self.groups[*g].solver.particles().positions[range.clone()]
    }

    /// Velocities of scene cloth `i`, in particle order.
    pub fn cloth_velocities(&self, i: usize) -> &[DVec3] {
        let (g, range) = &self.places[i];
        &self.groups[*g].solver.particles().velocities[range.clone()]
    }

    /// Places scene cloth `i`'s particles at `positions` (one per particle, finite), as the
    /// start of the next frame; velocities are kept. A pin that follows a motion goes back
    /// to its prescribed place in the next substep.
    pub fn set_cloth_positions(&mut self, i: usize, positions: &[DVec3]) -> Result<(), SimError> {
        let (g, range) = self
            .places
            .get(i)
            .cloned()
            .ok_or_else(|| SimError::BadValue {
                key: "cloth".into(),
                expected: format!("a cloth index below {}", self.places.len()),
                got: i.to_string(),
            })?;
        let name = &self.scene.cloths[i].name;
        if positions.len() != range.len() {
            return Err(SimError::BadValue {
                key: format!("positions of `{name}`"),
                expected: format!("{} positions (one per particle)", range.len()),
                got: format!("{}", positions.len()),
            });
        }
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(SimError::BadValue {
                key: format!("positions of `{name}`"),
                expected: "finite numbers".into(),
                got: format!("{} at particle {k}", positions[k]),
            });
        }
        let p = self.groups[g].solver.particles_mut();
        p.positions[range.clone()].copy_from_slice(positions);
        p.prev_positions[range].copy_from_slice(positions);
        Ok(())
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
            if let Some(b) = g.solver.bending_residual() {
                s.bending_residual = Some(s.bending_residual.map_or(b, |a| a.max(b)));
            }
        }
        if self.crossing_meshes.is_some() {
            s.crossings = Some(self.crossings_now());
        }
        s
    }

    /// Steps every solver one frame; on divergence the state is left as the solver left it.
    pub fn step(&mut self) -> Result<FrameStats, SolverError> {
        let start = Instant::now();
        let (mut contacts, mut cg) = (0, 0);
        for g in &mut self.groups {
            let st = g.step()?;
            contacts += st.contacts;
            cg += u64::from(st.cg_iterations);
        }
        self.frame += 1;
        let mut s = self.stats(start.elapsed().as_secs_f64() * 1e3, contacts);
        s.cg_iterations = cg;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::sim;

    #[test]
    fn positions_set_are_the_next_frames_start_and_bad_ones_are_refused() {
        let mut s = sim("xpbd", "[0.0, 0.0, 0.0]");
        let moved: Vec<DVec3> = s.cloth_positions(0).iter().map(|p| *p + DVec3::Z).collect();
        s.set_cloth_positions(0, &moved)
            .expect("25 finite positions");
        assert_eq!(s.cloth_positions(0), &moved[..]);
        assert!(s.cloth_velocities(0).iter().all(|v| *v == DVec3::ZERO));
        let e = s.set_cloth_positions(0, &moved[1..]).expect_err("24");
        assert!(e.to_string().contains("25 positions"), "{e}");
        let mut nan = moved.clone();
        nan[7].y = f64::NAN;
        let e = s.set_cloth_positions(0, &nan).expect_err("NaN");
        assert!(e.to_string().contains("particle 7"), "{e}");
        assert!(s.set_cloth_positions(1, &moved).is_err(), "no cloth 1");
        assert_eq!(s.cloth_positions(0), &moved[..], "refusals change nothing");
        s.step().expect("steps");
        assert!(
            s.cloth_positions(0).iter().all(|p| p.z == 1.0),
            "no gravity, no motion"
        );
    }
}
