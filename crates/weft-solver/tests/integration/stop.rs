//! A raised stop flag ends the frame in progress at the next substep, on the fused path and on
//! the general (hooked) path, and the frame is reported as interrupted, not counted.

use crate::common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use common::*;
use weft_solver::{Forces, Method, Particles, SolverError, SubstepContext, SubstepHook};

/// Counts substeps and raises `flag` at the start of substep `at`.
struct RaiseAt {
    flag: Arc<AtomicBool>,
    at: u32,
    seen: u32,
}

impl SubstepHook for RaiseAt {
    fn begin_substep(&mut self, ctx: &SubstepContext, _particles: &Particles) {
        self.seen += 1;
        if ctx.substep == self.at {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
}

#[test]
fn a_raised_flag_stops_the_frame_at_the_next_substep() {
    let mut s = solver(
        settings(Method::Xpbd, 1.0 / 60.0, 50, 2),
        Forces::default(),
        &hanging_grid(8),
        in_plane(0.0, 0.0, 0.0),
    );
    let flag = Arc::new(AtomicBool::new(false));
    s.set_stop(Arc::clone(&flag));
    s.step().expect("a frame with the flag down runs");
    let mut hook = RaiseAt {
        flag: Arc::clone(&flag),
        at: 3,
        seen: 0,
    };
    let err = s
        .step_with(&mut hook)
        .expect_err("the flag went up inside the frame");
    assert_eq!(err, SolverError::Interrupted { frame: 1 });
    assert_eq!(hook.seen, 4, "substeps 0..=3 ran, then the stop was seen");
}

#[test]
fn a_fused_frame_with_the_flag_up_moves_nothing() {
    let mut s = solver(
        settings(Method::Xpbd, 1.0 / 60.0, 50, 2),
        Forces::default(),
        &hanging_grid(8),
        in_plane(0.0, 0.0, 0.0),
    );
    let before = s.particles().positions.clone();
    let flag = Arc::new(AtomicBool::new(true));
    s.set_stop(flag);
    let err = s.step().expect_err("stopped");
    assert!(
        matches!(err, SolverError::Interrupted { frame: 0 }),
        "{err}"
    );
    assert_eq!(s.particles().positions, before);
    assert_eq!(s.frame(), 0, "an abandoned frame is not counted");
}
