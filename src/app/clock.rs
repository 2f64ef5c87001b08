//! The fixed-step simulation clock: real time accumulates, the simulation advances in whole
//! frames of the scene's Δt, at most a few per display frame.
//!
//! This is the "fix your timestep" accumulator (G. Fiedler, *Fix Your Timestep!*, 2004): the
//! physics never takes a longer step because a display frame was slow; when it falls behind by
//! more than `max_steps` frames, the surplus is dropped (the simulation runs slower than real
//! time) and counted, so the statistics can say so.

use std::time::Instant;

/// A source of monotonic time in seconds (a fake one in tests).
pub trait TimeSource {
    /// Seconds since some fixed origin; never decreases.
    fn now(&mut self) -> f64;
}

/// The real clock.
#[derive(Debug)]
pub struct WallClock(Instant);

impl Default for WallClock {
    fn default() -> Self {
        Self(Instant::now())
    }
}

impl TimeSource for WallClock {
    fn now(&mut self) -> f64 {
        self.0.elapsed().as_secs_f64()
    }
}

/// What one display frame should do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tick {
    /// Simulation frames to step now.
    pub steps: u32,
    /// Frames of real time dropped because more than `max_steps` were due.
    pub dropped: u32,
}

/// The accumulator.
#[derive(Debug)]
pub struct FixedClock<T: TimeSource> {
    source: T,
    last: f64,
    accumulator: f64,
    max_steps: u32,
    paused: bool,
    resync: bool,
    dropped_total: u64,
}

impl<T: TimeSource> FixedClock<T> {
    /// A clock reading `source`, stepping at most `max_steps` (≥ 1) frames per display frame.
    pub fn new(mut source: T, max_steps: u32) -> Self {
        let last = source.now();
        Self {
            source,
            last,
            accumulator: 0.0,
            max_steps: max_steps.max(1),
            paused: false,
            resync: false,
            dropped_total: 0,
        }
    }

    /// Reads the time source and says how many frames of `dt` (s) to step now.
    ///
    /// While paused, real time passes without accumulating.
    pub fn tick(&mut self, dt: f64) -> Tick {
        let now = self.source.now();
        let elapsed = if self.resync {
            0.0
        } else {
            (now - self.last).max(0.0)
        };
        self.last = now;
        self.resync = false;
        if self.paused || !(dt.is_finite() && dt > 0.0) {
            return Tick::default();
        }
        self.accumulator += elapsed;
        let due = (self.accumulator / dt).floor();
        let steps = due.min(f64::from(self.max_steps)) as u32;
        self.accumulator -= f64::from(steps) * dt;
        let mut dropped = 0;
        if due > f64::from(self.max_steps) {
            // Keep only the fraction of a frame: the rest is time the simulation gives up.
            dropped = (due - f64::from(self.max_steps)).min(f64::from(u32::MAX)) as u32;
            self.accumulator = self.accumulator.rem_euclid(dt);
            self.dropped_total += u64::from(dropped);
        }
        if !self.accumulator.is_finite() {
            self.accumulator = 0.0;
        }
        Tick { steps, dropped }
    }

    /// Seconds of real time waiting to be simulated (less than `dt` after a tick).
    #[cfg(test)]
    pub fn accumulator(&self) -> f64 {
        self.accumulator
    }

    /// Pauses or resumes; resuming does not catch up on the paused time.
    pub fn set_paused(&mut self, paused: bool) {
        self.resync |= self.paused && !paused;
        self.paused = paused;
        self.accumulator = 0.0;
    }

    /// Forgets the real time since the last tick (e.g. the time a window took to open).
    pub fn restart(&mut self) {
        self.resync = true;
        self.accumulator = 0.0;
    }

    /// Whether the clock is paused.
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Frames dropped since the start (or the last reset of the count).
    pub fn dropped_total(&self) -> u64 {
        self.dropped_total
    }

    /// Starts the count of dropped frames again (the scene was reset).
    pub fn reset_dropped(&mut self) {
        self.dropped_total = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A time source that returns the times it is given, in order.
    struct Fake(Vec<f64>, usize);

    impl TimeSource for Fake {
        fn now(&mut self) -> f64 {
            let t = self.0[self.1.min(self.0.len() - 1)];
            self.1 += 1;
            t
        }
    }

    fn clock(times: &[f64], max_steps: u32) -> FixedClock<Fake> {
        FixedClock::new(Fake(times.to_vec(), 0), max_steps)
    }

    /// A power of two, so that sums of multiples of it are exact.
    const DT: f64 = 1.0 / 64.0;

    #[test]
    fn steps_whole_frames_and_carries_the_remainder() {
        // 0 → 2.5 Δt: two frames, 0.5 Δt left; → 3.1 Δt: one more, 0.1 Δt left.
        let mut c = clock(&[0.0, 2.5 * DT, 3.1 * DT], 8);
        assert_eq!(
            c.tick(DT),
            Tick {
                steps: 2,
                dropped: 0
            }
        );
        assert!((c.accumulator() - 0.5 * DT).abs() < 1e-12);
        assert_eq!(c.tick(DT).steps, 1);
        assert!((c.accumulator() - 0.1 * DT).abs() < 1e-12);
    }

    #[test]
    fn display_faster_than_the_simulation_steps_every_few_frames() {
        // Display at Δt/4 per frame: over 100 display frames exactly 25 frames are stepped,
        // never more than one at a time.
        let times: Vec<f64> = (0..=100).map(|i| i as f64 * DT / 4.0).collect();
        let mut c = clock(&times, 8);
        let mut total = 0;
        for _ in 0..100 {
            let t = c.tick(DT);
            assert!(t.steps <= 1);
            total += t.steps;
        }
        assert_eq!(total, 25);
    }

    #[test]
    fn a_slow_frame_steps_at_most_max_and_drops_the_rest() {
        // A hitch of 100.5 Δt: 4 frames are stepped, 96 dropped, and nothing is left over
        // to make the next frames catch up (0.5 Δt + 0.75 Δt: one frame next).
        let mut c = clock(&[0.0, 100.5 * DT, 101.25 * DT], 4);
        assert_eq!(
            c.tick(DT),
            Tick {
                steps: 4,
                dropped: 96
            }
        );
        assert!(c.accumulator() < DT);
        assert_eq!(c.dropped_total(), 96);
        assert_eq!(c.tick(DT).steps, 1);
    }

    #[test]
    fn paused_time_is_not_simulated_later() {
        let mut c = clock(&[0.0, 32.0 * DT, 96.0 * DT, 98.0 * DT], 1000);
        c.set_paused(true);
        assert_eq!(c.tick(DT).steps, 0);
        c.set_paused(false);
        assert_eq!(c.tick(DT).steps, 0, "the 64 Δt paused are not stepped");
        assert_eq!(c.tick(DT).steps, 2);
    }

    #[test]
    fn a_restart_forgets_the_time_before_it() {
        let mut c = clock(&[0.0, 50.0 * DT, 51.0 * DT], 8);
        c.restart();
        assert_eq!(c.tick(DT), Tick::default());
        assert_eq!(c.tick(DT).steps, 1);
        assert_eq!(c.dropped_total(), 0);
    }

    #[test]
    fn an_absurdly_small_time_step_keeps_stepping_the_maximum() {
        let mut c = clock(&[0.0, 1.0, 2.0], 4);
        for _ in 0..2 {
            let t = c.tick(1e-300);
            assert_eq!(t.steps, 4);
            assert_eq!(t.dropped, u32::MAX);
            assert!(c.accumulator().is_finite());
        }
    }

    #[test]
    fn a_bad_time_step_steps_nothing() {
        let mut c = clock(&[0.0, 1.0], 4);
        assert_eq!(c.tick(f64::NAN), Tick::default());
    }
}
