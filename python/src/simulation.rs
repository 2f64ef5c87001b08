//! `weft.Simulation`: a scene's solvers from Python.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::PyArray2;
use pyo3::exceptions::{
    PyIndexError, PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use weft_record::{RecordOptions, Status};
use weft_scene::{CappedDirFiles, Limits, SceneErrors};

use crate::convert::{points_array, points_from, sim_error, triangles_array, vec3};
use crate::recording::Recording;
use crate::watch::{State, Stopped, step_watched};
use crate::{SceneError, SimulationError};

/// A Weft scene and its solvers (one per method in the scene), stepped in lockstep.
///
/// `scene` is a path to a scene file (str or os.PathLike) or the text of one (a str holding
/// a newline, or one that names no file and reads as TOML); meshes are read relative to the
/// scene file, or to the working directory for a text. `overrides` maps dotted keys to values
/// as `weft run --set KEY=VALUE` does (`{"sim.substeps": 20, "cloth.flag.stretch_compliance":
/// 1e-6}`); `method` is `--method`. A scene that does not load or validate raises
/// `weft.SceneError` (a `ValueError`) with the CLI's FILE:LINE: key: message lines, and so
/// does one estimated to need more memory than is available.
#[pyclass(module = "weft")]
pub struct Simulation {
    state: State,
    stop: Arc<AtomicBool>,
    scene_file: Option<PathBuf>,
}

fn scene_error(e: &SceneErrors) -> PyErr {
    SceneError::new_err(e.to_string())
}

/// Whether a str is a scene's text rather than a path.
fn is_text(s: &str) -> bool {
    s.contains('\n')
        || (!Path::new(s).exists() && (s.contains('=') || s.trim_start().starts_with('[')))
}

impl Simulation {
    fn cloth(&self, name: &str) -> PyResult<usize> {
        self.state.sim.cloth_index(name).map_err(sim_error)
    }

    /// Closes the recording (if any) with `status`; returns the final path.
    fn close(&mut self, status: &Status) -> PyResult<Option<PathBuf>> {
        let Some(mut r) = self.state.recording.take() else {
            return Ok(None);
        };
        let frames = self.state.sim.frame();
        // A finished recording ends at the last frame stepped, as `weft run --every` does.
        if *status == Status::Complete
            && let Err(e) = r.last_frame(&self.state.sim, &self.state.last)
        {
            r.abandon();
            return Err(PyOSError::new_err(e.0));
        }
        r.finish(status, frames)
            .map(Some)
            .map_err(|e| PyOSError::new_err(e.0))
    }
}

impl Drop for Simulation {
    fn drop(&mut self) {
        // A recording still open when the simulation goes is closed as cut short: whole and
        // readable, and it says so.
        let _ = self.close(&Status::Interrupted);
    }
}

#[pymethods]
impl Simulation {
    #[new]
    #[pyo3(signature = (scene, overrides=None, method=None))]
    fn new(
        scene: &Bound<'_, PyAny>,
        overrides: Option<&Bound<'_, PyDict>>,
        method: Option<&str>,
    ) -> PyResult<Self> {
        let set = crate::convert::overrides(method, overrides)?;
        let limits = Limits::available();
        let text = match scene.cast::<PyString>() {
            Ok(s) => Some(s.to_cow()?.into_owned()).filter(|t| is_text(t)),
            Err(_) => None,
        };
        let (loaded, scene_file) = match text {
            Some(text) => {
                let files = CappedDirFiles {
                    dir: PathBuf::from("."),
                    max_bytes: limits.max_file_bytes,
                };
                (
                    weft_scene::from_text_with("<string>", &text, &set, &files, &limits),
                    None,
                )
            }
            _ => {
                let path: PathBuf = scene.extract()?;
                (weft_scene::load_with(&path, &set, &limits), Some(path))
            }
        };
        let loaded = loaded.map_err(|e| scene_error(&e))?;
        let mut sim =
            weft_sim::Simulation::new(loaded).map_err(|e| scene_error(&SceneErrors(vec![e])))?;
        let stop = Arc::new(AtomicBool::new(false));
        sim.set_stop(Arc::clone(&stop));
        let last = sim.stats(0.0, 0);
        Ok(Self {
            state: State {
                sim,
                last,
                recording: None,
            },
            stop,
            scene_file,
        })
    }

    /// Steps `frames` frames (each `sim.dt` long), logging each if recording. The GIL is
    /// released meanwhile, and Ctrl-C (any signal whose handler raises) stops the frame in
    /// progress within a substep and raises `KeyboardInterrupt`: the frames stepped before it
    /// stay, the one in progress is abandoned part-way (its substeps done stay in the state;
    /// `frame` and `time` count whole frames), and a recording is closed as `weft run` closes
    /// its log on Ctrl-C. A divergence raises `weft.SimulationError` (a recording is closed,
    /// saying so).
    #[pyo3(signature = (frames=1))]
    fn step(&mut self, py: Python<'_>, frames: u64) -> PyResult<()> {
        py.check_signals()?;
        self.stop.store(false, Ordering::SeqCst);
        let stop = Arc::clone(&self.stop);
        let state = &mut self.state;
        let (ended, signal) = py.detach(|| step_watched(state, frames, &stop));
        match (ended, signal) {
            (Ok(()), None) => Ok(()),
            (Err(Stopped::Diverged(e)), _) => {
                let message = e.to_string();
                self.close(&Status::Diverged(message.clone()))?;
                Err(SimulationError::new_err(message))
            }
            (Err(Stopped::Log(e)), _) => {
                if let Some(r) = self.state.recording.take() {
                    r.abandon();
                }
                Err(PyOSError::new_err(e.0))
            }
            (_, signal) => {
                let closed = self.close(&Status::Interrupted);
                let e = signal.unwrap_or_else(|| PyKeyboardInterrupt::new_err(()));
                closed.map(|_| ()).and(Err(e))
            }
        }
    }

    /// Simulated time (s): the frames stepped times the time step.
    #[getter]
    fn time(&self) -> f64 {
        self.state.sim.time()
    }

    /// Frames stepped so far.
    #[getter]
    fn frame(&self) -> u64 {
        self.state.sim.frame()
    }

    /// The frame time step in use (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.state.sim.dt()
    }

    /// The names of the scene's cloths, in the scene's order (by name).
    #[getter]
    fn cloths(&self) -> Vec<String> {
        let cloths = &self.state.sim.scene.cloths;
        cloths.iter().map(|c| c.name.clone()).collect()
    }

    /// Positions of cloth `name` (m), a new `(n, 3)` float64 array in particle order.
    fn positions<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let i = self.cloth(name)?;
        Ok(points_array(py, self.state.sim.cloth_positions(i)))
    }

    /// Velocities of cloth `name` (m/s), a new `(n, 3)` float64 array in particle order.
    fn velocities<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let i = self.cloth(name)?;
        Ok(points_array(py, self.state.sim.cloth_velocities(i)))
    }

    /// Places cloth `name`'s particles at `positions`, a float64 array of shape `(n, 3)`
    /// (finite), from the next frame on; velocities are kept. Another dtype raises
    /// `TypeError`; another shape, or a value that is not finite, `ValueError`.
    fn set_positions(&mut self, name: &str, positions: &Bound<'_, PyAny>) -> PyResult<()> {
        let i = self.cloth(name)?;
        let n = self.state.sim.cloth_positions(i).len();
        let points = points_from(positions, n, "positions")?;
        self.state
            .sim
            .set_cloth_positions(i, &points)
            .map_err(sim_error)
    }

    /// The triangles of cloth `name`: particle indices, a new `(m, 3)` uint32 array.
    fn triangles<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let i = self.cloth(name)?;
        Ok(triangles_array(
            py,
            &self.state.sim.scene.cloths[i].mesh.triangles,
        ))
    }

    /// Grabs particle `index` of cloth `name` and drags it to `target` (three numbers, m),
    /// as the viewer's mouse drag does: the particle is held (inverse mass 0) and moved to
    /// the target over the next frame's substeps. Calling it again moves the target (or
    /// grabs another particle, letting the first go). An index out of range raises
    /// `IndexError`; a target that is not finite, `ValueError`.
    fn grab(&mut self, name: &str, index: i64, target: &Bound<'_, PyAny>) -> PyResult<()> {
        let i = self.cloth(name)?;
        let target = vec3(target, "target")?;
        let count = self.state.sim.cloth_positions(i).len();
        if index < 0 {
            return Err(PyIndexError::new_err(format!(
                "cloth `{name}` has {count} particles: index {index} is negative"
            )));
        }
        let particle = usize::try_from(index).unwrap_or(usize::MAX);
        if particle >= count {
            return Err(sim_error(weft_sim::SimError::NoSuchParticle {
                cloth: name.to_owned(),
                index: particle,
                count,
            }));
        }
        if !target.is_finite() {
            return Err(PyValueError::new_err(format!(
                "target: expected three finite numbers (m), got {target}"
            )));
        }
        let sim = &mut self.state.sim;
        if sim.held().map(|(c, p, _)| (c, p)) != Some((i, particle)) {
            sim.grab(i, particle).map_err(sim_error)?;
        }
        sim.drag_to(target).map_err(sim_error)
    }

    /// Lets the grabbed particle go (if any): its mass comes back and it keeps its drag
    /// velocity.
    fn release(&mut self) {
        self.state.sim.release();
    }

    /// The last frame's statistics, as the log's `/stats` channel has them: `frame`, `time`
    /// (s), `kinetic_energy` (J), `residual_max` and `residual_rms` (m, the distance
    /// constraints' violation), `contacts`, `cg_iterations` (conjugate-gradient iterations:
    /// implicit mass-spring's, XPBD's of stiff bending and stretch), `bending_residual`
    /// (under XPBD with bending hinges only: 0 converged, 1 a hinge about twice too soft),
    /// and `step_ms` (the step's wall-clock time, ms).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.state.last;
        let d = PyDict::new(py);
        d.set_item("frame", s.frame)?;
        d.set_item("time", s.time)?;
        d.set_item("kinetic_energy", s.kinetic_energy)?;
        d.set_item("residual_max", s.residual_max)?;
        d.set_item("residual_rms", s.residual_rms)?;
        d.set_item("contacts", s.contacts)?;
        d.set_item("cg_iterations", s.cg_iterations)?;
        if let Some(b) = s.bending_residual {
            d.set_item("bending_residual", b)?;
        }
        d.set_item("step_ms", s.step_ms)?;
        Ok(d)
    }

    /// Changes a live setting from the next frame on, as the viewer's side panel does, by
    /// its scene key: `sim.method` (a name from `weft.methods()`), `sim.dt` (s, or a
    /// fraction such as "1/120"), `sim.substeps`, `sim.iterations`, `sim.gravity` and
    /// `wind.velocity` (three numbers), `sim.damping`, `wind.drag`,
    /// `cloth.<name>.thickness`, and `cloth.<name>.<family>_<field>` for the families
    /// `stretch`, `shear`, `bend_distance`, `bend_dihedral`, `bend_isometric`, `tether` and
    /// the fields `compliance`, `damping`, `pbd_stiffness`, `spring_stiffness`,
    /// `spring_damping`. An unknown key or cloth raises `KeyError`; a value of the wrong type
    /// `TypeError`; one out of range (NaN included) `ValueError`, changing nothing.
    fn set(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = crate::convert::value(value, key)?;
        self.state.sim.set(key, &v).map_err(sim_error)
    }

    /// Starts an MCAP log at `path`, as `weft run --out` writes it: the current state first,
    /// then every frame stepped, until `stop_recording()`. `frames` is the run's planned
    /// length, written in the log's metadata as `weft run --frames` writes it (`weft replay`
    /// replays that many; without it the log says 0, as the viewer's do); `log`, `every`,
    /// `mesh_every`, `precision`, `compression` and `timing` are `weft run`'s options of those
    /// names. Recorded from frame 0 with neither live changes nor grabs, the log is
    /// byte-for-byte `weft run`'s for the same frames and options.
    #[pyo3(signature = (path, frames=None, log="particles", every=1, mesh_every=1, precision="f32", compression="none", timing=false))]
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        path: PathBuf,
        frames: Option<u64>,
        log: &str,
        every: u64,
        mesh_every: u64,
        precision: &str,
        compression: &str,
        timing: bool,
    ) -> PyResult<()> {
        let choice = |e: weft_record::UnknownChoice| PyValueError::new_err(e.to_string());
        if every == 0 {
            return Err(PyValueError::new_err("every must be at least 1"));
        }
        let options = RecordOptions {
            channels: log.parse().map_err(choice)?,
            every,
            mesh_every,
            precision: precision.parse().map_err(choice)?,
            compression: compression.parse().map_err(choice)?,
            timing,
        };
        if self.state.recording.is_some() {
            return Err(PyRuntimeError::new_err(
                "already recording: stop_recording() first",
            ));
        }
        if let Some(scene) = &self.scene_file
            && let (Ok(a), Ok(b)) = (path.canonicalize(), scene.canonicalize())
            && a == b
        {
            return Err(PyValueError::new_err(format!(
                "{} is the scene file: refusing to overwrite it with a log",
                path.display()
            )));
        }
        let state = &mut self.state;
        let r = Recording::start(&path, &state.sim, &state.last, frames.unwrap_or(0), options)
            .map_err(|e| PyOSError::new_err(e.0))?;
        state.recording = Some(r);
        Ok(())
    }

    /// Finishes the log (status `complete`), renames it into place and returns its path;
    /// `None` when not recording.
    fn stop_recording(&mut self) -> PyResult<Option<PathBuf>> {
        self.close(&Status::Complete)
    }

    fn __repr__(&self) -> String {
        let sim = &self.state.sim;
        format!(
            "<weft.Simulation {:?}: cloths {:?}, frame {}, t = {:.4} s>",
            sim.scene.name,
            self.cloths(),
            sim.frame(),
            sim.time()
        )
    }
}
