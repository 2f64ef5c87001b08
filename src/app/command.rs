//! What the keys and the panel's buttons both ask of the simulation — pause, step, reset — with
//! one meaning each, wherever it was asked.

use crate::app::session::Session;

/// A request to the simulation from a key or a panel button.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// Pause or resume the simulation.
    TogglePause,
    /// Step one frame (pauses first).
    Step,
    /// Rebuild the scene from its file: initial positions, time 0.
    Reset,
}

impl Command {
    /// Applies the command to `session`. A reset that fails leaves the scene as it was and
    /// puts its message in `error` (the panel shows it); a step that fails is returned, and
    /// ends the viewer (its log is finished with the error).
    pub fn apply(self, session: &mut Session, error: &mut Option<String>) -> anyhow::Result<()> {
        match self {
            Command::TogglePause => {
                let paused = session.clock.paused();
                session.clock.set_paused(!paused);
            }
            Command::Step => {
                session.clock.set_paused(true);
                session.step_once()?;
            }
            Command::Reset => {
                if let Err(e) = session.reset() {
                    *error = Some(format!("{e:#}"));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::session::test_session as session;

    #[test]
    fn pause_toggles_and_step_pauses_and_advances_one_frame() {
        let mut s = session();
        let mut error = None;
        let paused = s.clock.paused();
        Command::TogglePause
            .apply(&mut s, &mut error)
            .expect("toggles");
        assert_eq!(s.clock.paused(), !paused);
        s.clock.set_paused(false);
        Command::Step.apply(&mut s, &mut error).expect("steps");
        assert!(s.clock.paused(), "a step pauses");
        assert_eq!(s.frames, 1);
        assert_eq!(error, None);
    }

    #[test]
    fn a_failed_reset_is_shown_and_the_viewer_goes_on() {
        let mut s = session();
        let mut error = None;
        Command::Step.apply(&mut s, &mut error).expect("steps");
        // A scene its solvers refuse: the reset fails, the simulation is kept.
        s.sim.scene.cloths[0]
            .params
            .get_mut(weft_solver::Family::Stretch)
            .compliance = -1.0;
        let before = s.sim.cloth_positions(0).to_vec();
        Command::Reset
            .apply(&mut s, &mut error)
            .expect("a failed reset does not end the viewer");
        let shown = error.expect("the failure is shown");
        assert!(shown.contains("stretch.compliance"), "{shown}");
        assert_eq!(s.sim.cloth_positions(0), &before[..]);
    }
}
