//! Stepping with the GIL released and Ctrl-C heard. Python runs signal handlers on its main
//! thread only, so the calling thread stays the watcher: the frames are stepped on rayon's
//! pool (where the solver hands each frame anyway, as `weft run` does), while the caller waits
//! for them and every [`POLL`] takes the GIL to run `PyErr_CheckSignals`. A signal handler that
//! raises (SIGINT's `KeyboardInterrupt`) raises the solver's stop flag, which it polls once a
//! substep, so a step of any size ends within a poll and a substep.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::prelude::*;
use weft_sim::{FrameStats, Simulation};
use weft_solver::SolverError;

use crate::recording::{LogError, Recording};

/// How often the waiting caller checks for signals.
pub const POLL: Duration = Duration::from_millis(50);

/// A simulation, its last frame's statistics and its recording.
pub struct State {
    /// The scene's solvers.
    pub sim: Simulation,
    /// The statistics of the last frame stepped (the initial state's at first).
    pub last: FrameStats,
    /// The MCAP log being written, if any.
    pub recording: Option<Recording>,
}

/// Why stepping ended before every frame was stepped.
pub enum Stopped {
    /// The stop flag, raised before a frame or inside one (then abandoned part-way).
    Interrupted,
    /// The solver diverged.
    Diverged(SolverError),
    /// The log could not be written.
    Log(LogError),
}

/// Steps `frames` frames, logging each, until the stop flag is raised.
fn run(state: &mut State, frames: u64, stop: &AtomicBool) -> Result<(), Stopped> {
    for _ in 0..frames {
        if stop.load(Ordering::SeqCst) {
            return Err(Stopped::Interrupted);
        }
        match state.sim.step() {
            Ok(stats) => {
                state.last = stats;
                if let Some(r) = state.recording.as_mut() {
                    r.frame(&state.sim, &stats).map_err(Stopped::Log)?;
                }
            }
            Err(e) if state.sim.interrupted(&e) => {
                return Err(Stopped::Interrupted);
            }
            Err(e) => return Err(Stopped::Diverged(e)),
        }
    }
    Ok(())
}

/// Steps `frames` frames on rayon's pool while this thread (GIL released) watches for
/// signals; returns how stepping ended and the error a signal handler raised, if any.
pub fn step_watched(
    state: &mut State,
    frames: u64,
    stop: &AtomicBool,
) -> (Result<(), Stopped>, Option<PyErr>) {
    let (tx, rx) = mpsc::sync_channel(1);
    let mut signal = None;
    let ended = rayon::in_place_scope(|s| {
        s.spawn(move |_| {
            // The receiver waits until this is sent (or the sender dropped by a panic).
            let _ = tx.send(run(state, frames, stop));
        });
        loop {
            match rx.recv_timeout(POLL) {
                Ok(ended) => break ended,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if signal.is_none()
                        && let Err(e) = Python::attach(|py| py.check_signals())
                    {
                        signal = Some(e);
                        stop.store(true, Ordering::SeqCst);
                    }
                }
                // The stepping panicked: the scope re-raises the panic when it closes.
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    break Err(Stopped::Interrupted);
                }
            }
        }
    });
    (ended, signal)
}
