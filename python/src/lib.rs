//! `weft._weft`, the native module of the `weft` Python package: [`Simulation`] (a scene
//! stepped with the GIL released, its arrays as numpy arrays, live settings, grabs and MCAP
//! recordings), the exceptions, and the lists of methods and materials.
//!
//! Its modules:
//!
//! - `convert`: between Python and Weft: overrides, live values, vectors, numpy arrays, exceptions.
//! - `recording`: `Simulation.record`: the MCAP log `weft run --out` writes, as the CLI does.
//! - `simulation`: `weft.Simulation`: a scene's solvers from Python.
//! - `watch`: stepping with the GIL released while the calling thread hears Ctrl-C.

// pyo3's macros expand to code that the workspace's `missing_docs` cannot see documented
// (their docs are the Python docstrings, which these `///` comments become).
#![allow(missing_docs)]

mod convert;
mod recording;
mod simulation;
mod watch;

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use simulation::Simulation;

create_exception!(
    weft,
    SceneError,
    PyValueError,
    "A scene that does not load or validate: one line per problem, FILE:LINE: key: message, \
     as `weft check` prints them."
);
create_exception!(
    weft,
    SimulationError,
    PyRuntimeError,
    "The simulation diverged (a particle left the divergence bound or became non-finite); \
     the message is the solver's, naming the frame, the particle and the stability limit."
);

/// The methods a scene or `Simulation.set("sim.method", ...)` may name.
#[pyfunction]
fn methods() -> Vec<&'static str> {
    weft_solver::Method::ALL.iter().map(|m| m.name()).collect()
}

/// The fabric presets a cloth's `material` may name (published Kawabata measurements).
#[pyfunction]
fn materials() -> Vec<&'static str> {
    weft_solver::PRESETS
        .iter()
        .map(|(name, _, _)| *name)
        .collect()
}

/// Weft's simulator from Python.
#[pymodule]
fn _weft(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Simulation>()?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(materials, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
