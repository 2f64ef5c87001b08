//! What the collision benches share: timing warm frames.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Bencher, measurement::WallTime};
use weft_collide::CollisionWorld;
use weft_solver::{Solver, StepStats};

/// Frames stepped from one copy before the next copy is made: every timed frame is within a
/// third of a second of the state given (without its colliders a cloth would otherwise fall
/// for thousands of frames and leave the divergence bound).
const REFRESH: u64 = 20;

/// One frame of `solver`, through `world` if given.
fn frame(solver: &mut Solver, world: Option<&mut CollisionWorld>) -> StepStats {
    match world {
        Some(w) => solver.step_with(w),
        None => solver.step(),
    }
    .expect("stable")
}

/// Times frames of copies of `solver` (with copies of `world`, if given), each frame warm: the
/// same copy's previous frame ran just before it, as in a running app. A fresh copy, made and
/// stepped once untimed, every [`REFRESH`] frames. (Each frame timed on a fresh copy instead,
/// made in criterion's batches, starts with cold caches: the bare solve measured 1.9× its
/// warm time that way.)
pub fn warm_frames(b: &mut Bencher<'_, WallTime>, solver: &Solver, world: Option<&CollisionWorld>) {
    b.iter_custom(|iters| {
        let mut total = Duration::ZERO;
        let mut copy = None;
        for i in 0..iters {
            if i % REFRESH == 0 {
                copy = None;
            }
            let (s, w) = copy.get_or_insert_with(|| {
                let (mut s, mut w) = (solver.clone(), world.cloned());
                frame(&mut s, w.as_mut());
                (s, w)
            });
            let start = Instant::now();
            black_box(frame(s, w.as_mut()));
            total += start.elapsed();
        }
        total
    });
}
