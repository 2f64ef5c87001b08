//! The viewer's simulation side, free of any window: the scene's solvers, the fixed-step
//! clock, the grabbed particle, live parameter changes and the optional session log.

use std::path::PathBuf;
use std::time::Instant;

use weft_scene::{Override, Scene, SceneErrors};
use weft_solver::{Method, ParamError};

use crate::app::clock::{FixedClock, WallClock};
use crate::app::grab::Grab;
use crate::app::picking::Ray;
use crate::app::recording::SessionLog;
use crate::default_scene;
use weft_record::Status;
use weft_sim::{SeamWatch, Simulation};

/// Where a scene came from (to reset it, and to list it in the panel).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSource {
    /// The compiled-in default scene.
    Default,
    /// A scene file.
    File(PathBuf),
}

impl SceneSource {
    /// Loads the scene with `overrides`.
    pub fn load(&self, overrides: &[Override]) -> Result<Scene, SceneErrors> {
        match self {
            SceneSource::Default => default_scene::load(overrides),
            SceneSource::File(p) => weft_scene::load(p, overrides),
        }
    }

    /// A short label.
    pub fn label(&self) -> String {
        match self {
            SceneSource::Default => format!("built-in ({})", default_scene::NAME),
            SceneSource::File(p) => p.display().to_string(),
        }
    }
}

/// Figures the panel shows.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Wall-clock time of the last simulated frame (ms).
    pub step_ms: f64,
    /// Wall-clock time between the last two displayed frames (ms).
    pub frame_ms: f64,
    /// Simulation frames stepped in the last displayed frame.
    pub steps_last: u32,
    /// Frames of real time dropped in the last displayed frame (over the per-frame limit).
    pub dropped_last: u32,
    /// Contacts in the last substep.
    pub contacts: usize,
    /// Cloth crossings of the last frame, when measured.
    pub crossings: Option<weft_sim::CrossingStats>,
    /// Largest |C| over the distance-like constraints after the last frame (m).
    pub stretch_error: f64,
    /// Conjugate-gradient iterations of the last frame (implicit mass-spring's, XPBD's
    /// bending or joint solves).
    pub cg_iterations: u64,
    /// XPBD's bending residual of the last frame, where it bends.
    pub bending_residual: Option<f64>,
}

/// The simulation the window shows.
pub struct Session {
    /// The scene's solvers.
    pub sim: Simulation,
    /// Where the scene came from.
    pub source: SceneSource,
    /// The fixed-step clock.
    pub clock: FixedClock<WallClock>,
    /// The particle held with the mouse.
    pub grab: Option<Grab>,
    /// The session log (`--record`).
    pub log: Option<SessionLog>,
    /// Figures for the panel.
    pub stats: Stats,
    /// The solver's message after a divergence (stepping stops until reset).
    pub diverged: Option<String>,
    /// Frames simulated in this session (across resets).
    pub frames: u64,
    /// The garments' seams, looked at once they were due to have closed.
    pub seams: SeamWatch,
}

impl Session {
    /// A session on `sim`, stepping at most `max_steps` frames per displayed frame.
    pub fn new(sim: Simulation, source: SceneSource, max_steps: u32) -> Self {
        Self {
            sim,
            source,
            clock: FixedClock::new(WallClock::default(), max_steps),
            grab: None,
            log: None,
            stats: Stats::default(),
            diverged: None,
            frames: 0,
            seams: SeamWatch::default(),
        }
    }

    /// The frame time step in use (s).
    pub fn dt(&self) -> f64 {
        self.sim
            .groups
            .first()
            .map_or(self.sim.scene.settings.dt, |g| g.solver.settings().dt)
    }

    /// Steps as many frames as real time asks for (at most the clock's limit), never
    /// beyond `last_frame` frames in all.
    pub fn advance(&mut self, last_frame: Option<u64>) -> anyhow::Result<()> {
        let tick = self.clock.tick(self.dt());
        self.stats.steps_last = 0;
        self.stats.dropped_last = tick.dropped;
        for _ in 0..tick.steps {
            if last_frame.is_some_and(|n| self.frames >= n) {
                break;
            }
            self.step_once()?;
        }
        Ok(())
    }

    /// Steps one frame now (unless diverged), logging it.
    pub fn step_once(&mut self) -> anyhow::Result<()> {
        if self.diverged.is_some() {
            return Ok(());
        }
        let start = Instant::now();
        let dt = self.dt();
        match self.sim.step() {
            Ok(stats) => {
                self.stats.step_ms = start.elapsed().as_secs_f64() * 1e3;
                self.stats.contacts = stats.contacts;
                self.stats.crossings = stats.crossings;
                self.stats.stretch_error = stats.residual_max;
                self.stats.cg_iterations = stats.cg_iterations;
                self.stats.bending_residual = stats.bending_residual;
                self.stats.steps_last += 1;
                self.frames += 1;
                crate::seam_report::warn_open(&mut self.seams, &self.sim);
                if let Some(log) = self.log.as_mut() {
                    log.frame(&self.sim, stats, dt, self.grab.as_ref())?;
                }
            }
            Err(e) => {
                self.diverged = Some(e.to_string());
                self.clock.set_paused(true);
            }
        }
        Ok(())
    }

    /// Grabs the cloth under `ray`, if any.
    pub fn grab(&mut self, ray: &Ray, view_dir: weft_solver::glam::DVec3) -> bool {
        self.release();
        self.grab = Grab::start(&mut self.sim, ray, view_dir);
        self.grab.is_some()
    }

    /// Drags the held particle toward where `ray` meets its drag plane.
    pub fn drag(&mut self, ray: &Ray) {
        if let Some(g) = self.grab.as_mut() {
            g.drag(&mut self.sim, ray);
        }
    }

    /// Lets the held particle go.
    pub fn release(&mut self) {
        if let Some(g) = self.grab.take() {
            g.release(&mut self.sim);
        }
    }

    /// Rebuilds the scene's solvers: initial positions, the scene's parameters, time 0.
    pub fn reset(&mut self) -> anyhow::Result<()> {
        self.release();
        self.sim = Simulation::new(self.sim.scene.clone())?;
        self.diverged = None;
        let paused = self.clock.paused();
        self.clock.set_paused(paused);
        self.clock.reset_dropped();
        Ok(())
    }

    /// Switches to another scene (refused while recording: a log holds one scene).
    pub fn switch_scene(&mut self, source: SceneSource) -> anyhow::Result<()> {
        self.load(source, &[])
    }

    /// Loads the scene `source` with `overrides` in place of the current one, from time 0
    /// (refused while recording: a log holds one scene; a scene that does not load leaves
    /// the current one as it is).
    pub fn load(&mut self, source: SceneSource, overrides: &[Override]) -> anyhow::Result<()> {
        if self.log.is_some() {
            anyhow::bail!("a recorded session keeps its scene; stop and start a new one");
        }
        let scene = source.load(overrides).map_err(|e| {
            let lines: Vec<String> = e.0.iter().map(|e| e.to_string()).collect();
            anyhow::anyhow!(lines.join("\n"))
        })?;
        let sim = Simulation::new(scene)?;
        self.release();
        self.sim = sim;
        self.source = source;
        self.diverged = None;
        Ok(())
    }

    /// Switches every solver of the scene to `method` (parameters of every method are kept
    /// per cloth, so nothing else changes).
    pub fn set_method(&mut self, method: Method) -> Result<(), ParamError> {
        self.sim.set_method(method)
    }

    /// Closes the log (if any) with the status of how the session ended.
    pub fn finish(&mut self, interrupted: bool) -> anyhow::Result<()> {
        let Some(log) = self.log.take() else {
            return Ok(());
        };
        let status = match (&self.diverged, interrupted) {
            (Some(m), _) => Status::Diverged(m.clone()),
            (None, true) => Status::Interrupted,
            (None, false) => Status::Complete,
        };
        log.finish(&status)
    }
}

/// A session of the built-in scene, not recording (for tests).
#[cfg(test)]
pub(crate) fn test_session() -> Session {
    let scene = SceneSource::Default.load(&[]).expect("default scene");
    Session::new(
        Simulation::new(scene).expect("solvers"),
        SceneSource::Default,
        4,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn session() -> Session {
        test_session()
    }

    #[test]
    fn reset_puts_the_cloth_back_and_clears_a_divergence() {
        let mut s = session();
        let start = s.sim.cloth_positions(0).to_vec();
        for _ in 0..5 {
            s.step_once().expect("steps");
        }
        assert_eq!(s.frames, 5);
        assert_ne!(s.sim.cloth_positions(0), &start[..]);
        // A hitch of 10 frames' time, at most 4 stepped a displayed frame: some are dropped.
        s.clock.tick(s.dt());
        std::thread::sleep(std::time::Duration::from_secs_f64(10.0 * s.dt()));
        s.advance(None).expect("steps");
        assert!(s.clock.dropped_total() > 0);
        assert_ne!(s.sim.frame(), 0);
        s.diverged = Some("test".into());
        s.reset().expect("resets");
        assert_eq!(s.sim.cloth_positions(0), &start[..]);
        assert_eq!(s.diverged, None);
        assert_eq!(s.sim.frame(), 0);
        // The session's own count goes on (it numbers the log's frames); the panel's counts
        // (frames since the reset, frames dropped) start again.
        assert!(s.frames > 5);
        assert_eq!(s.clock.dropped_total(), 0);
    }

    /// The panel's solver figures are the frame's: the stretch error, and the conjugate
    /// gradients of XPBD's joint solve on the cantilever strip (none on the default cloth).
    #[test]
    fn the_panel_shows_the_frames_stretch_error_and_cg_iterations() {
        let mut s = session();
        s.step_once().expect("steps");
        let now = s.sim.stats(0.0, 0);
        assert!(s.stats.stretch_error > 0.0);
        assert_eq!(s.stats.stretch_error, now.residual_max);
        assert_eq!(
            s.stats.cg_iterations, 0,
            "the default cloth does not bend stiffly"
        );
        let strip = SceneSource::File(PathBuf::from("assets/scenes/cantilever.toml"));
        s.switch_scene(strip).expect("loads");
        s.step_once().expect("steps");
        assert!(s.sim.groups[0].solver.solves_jointly());
        assert!(s.stats.cg_iterations >= 10, "{}", s.stats.cg_iterations);
        assert_eq!(s.stats.stretch_error, s.sim.stats(0.0, 0).residual_max);
    }

    #[test]
    fn the_method_switches_in_every_solver_and_bad_values_are_refused() {
        let mut s = session();
        s.set_method(Method::MassSpring).expect("valid");
        assert!(
            s.sim
                .groups
                .iter()
                .all(|g| g.solver.settings().method == Method::MassSpring)
        );
        s.step_once().expect("steps with the new method");
        let solver = &mut s.sim.groups[0].solver;
        let bad = weft_solver::Settings {
            substeps: 0,
            ..*solver.settings()
        };
        assert!(solver.set_settings(bad).is_err());
        assert_eq!(solver.settings().substeps, 10, "the old value is kept");
    }

    #[test]
    fn switching_scene_loads_it_but_not_while_recording() {
        let mut s = session();
        let file = SceneSource::File(PathBuf::from("assets/scenes/sphere_drop.toml"));
        s.switch_scene(file.clone()).expect("switches");
        assert_eq!(s.source, file);
        assert_eq!(s.sim.scene.name, "assets/scenes/sphere_drop.toml");
        let missing = SceneSource::File(PathBuf::from("no/such.toml"));
        let e = s.switch_scene(missing).expect_err("missing file");
        assert!(format!("{e:#}").contains("no/such.toml"), "{e:#}");
        assert_eq!(s.source, file, "a failed switch keeps the scene");
        // Recording: the log holds one scene, so switching is refused.
        let path = std::env::temp_dir().join(format!("weft-session-{}.mcap", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let out = crate::output::Output::create(&path).expect("temp file");
        let partial = out.partial().to_path_buf();
        s.log = Some(
            SessionLog::new(out, &s.sim, weft_record::RecordOptions::default(), 0).expect("log"),
        );
        let e = s.switch_scene(SceneSource::Default).expect_err("refused");
        assert!(format!("{e}").contains("recorded"), "{e}");
        assert_eq!(s.source, file);
        s.step_once().expect("steps");
        assert!(
            !path.exists(),
            "nothing under the final name while recording"
        );
        s.finish(false).expect("finishes");
        assert!(s.log.is_none());
        assert!(path.exists(), "the finished log is renamed into place");
        assert!(!partial.exists(), "the temporary file is the finished log");
        let _ = std::fs::remove_file(path);
    }
}
