//! Cloth crossings in words: the warning `run`, `view` and `render` print when a scene starts
//! with cloth already crossing, and the line `weft run` ends with (how many frames crossed, the
//! most in one frame, the closest approach), from the frames' independent count
//! ([`weft_sim::CrossingStats`]).

use weft_sim::{CrossingStats, FrameStats, Simulation};

/// Prints a warning for each cloth (or pair of cloths) that crosses at the start; returns how
/// many there were. The run goes on: contact cannot undo a crossing it did not cause.
pub fn warn_start(sim: &Simulation) -> usize {
    for c in sim.start_crossings() {
        eprintln!("weft: warning: {c}");
    }
    sim.start_crossings().len()
}

/// The crossings of a run's frames, gathered as they come.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CrossingTally {
    /// Frames measured.
    pub frames: u64,
    /// Frames with at least one crossing.
    pub crossed: u64,
    /// The frame with the most crossings and their count, when any crossed.
    pub most: Option<(u64, usize)>,
    /// The closest approach between non-adjacent elements over the run (m), when one came
    /// within the measure's reach.
    pub closest: Option<f64>,
    /// How far the closest approach was looked for (m).
    pub reach: f64,
}

impl CrossingTally {
    /// Counts frame `stats` (nothing when its crossings were not measured).
    pub fn add(&mut self, stats: &FrameStats) {
        let Some(c) = stats.crossings else {
            return;
        };
        self.frames += 1;
        self.reach = self.reach.max(c.reach);
        if c.crossings > 0 {
            self.crossed += 1;
            if self.most.is_none_or(|(_, n)| c.crossings > n) {
                self.most = Some((stats.frame, c.crossings));
            }
        }
        self.closest = weft_sim::crossings::closer(self.closest, c.closest);
    }

    /// The summary line, or `None` when no frame was measured.
    pub fn line(&self) -> Option<String> {
        if self.frames == 0 {
            return None;
        }
        let crossed = match self.most {
            None => format!("no cloth crossing in {}", frames(self.frames)),
            Some((frame, n)) => format!(
                "cloth crossed in {} of {} (most: {n} edge–triangle crossings at frame \
                 {frame})",
                self.crossed,
                frames(self.frames)
            ),
        };
        Some(format!("{crossed}; {}", closest(self.closest, self.reach)))
    }
}

/// `n` measured frame(s) in words.
fn frames(n: u64) -> String {
    format!("{n} measured frame{}", if n == 1 { "" } else { "s" })
}

/// The closest approach in words.
pub fn closest(closest: Option<f64>, reach: f64) -> String {
    match closest {
        Some(d) => format!("closest approach {:.2} mm", d * 1e3),
        None => format!("no elements within {:.1} mm", reach * 1e3),
    }
}

/// One frame's crossings in words, for the viewer's panel.
pub fn frame_text(c: &CrossingStats) -> String {
    format!("{}, {}", c.crossings, closest(c.closest, c.reach))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(frame: u64, crossings: usize, closest: Option<f64>) -> FrameStats {
        FrameStats {
            frame,
            crossings: Some(CrossingStats {
                crossings,
                closest,
                reach: 0.006,
            }),
            ..FrameStats::default()
        }
    }

    #[test]
    fn the_tally_keeps_the_worst_frame_and_the_closest_approach() {
        let mut t = CrossingTally::default();
        assert_eq!(t.line(), None, "nothing measured, nothing said");
        t.add(&FrameStats::default());
        assert_eq!(t.frames, 0, "an unmeasured frame is not counted");
        t.add(&frame(1, 0, Some(0.0021)));
        t.add(&frame(2, 0, None));
        assert_eq!(
            t.line().as_deref(),
            Some("no cloth crossing in 2 measured frames; closest approach 2.10 mm")
        );
        t.add(&frame(3, 7, Some(0.0004)));
        t.add(&frame(4, 12, None));
        t.add(&frame(5, 3, Some(0.0009)));
        assert_eq!(t.crossed, 3);
        assert_eq!(t.most, Some((4, 12)));
        assert_eq!(
            t.line().as_deref(),
            Some(
                "cloth crossed in 3 of 5 measured frames (most: 12 edge–triangle crossings at frame 4); \
                 closest approach 0.40 mm"
            )
        );
    }

    #[test]
    fn no_close_elements_name_the_reach() {
        let mut t = CrossingTally::default();
        t.add(&frame(1, 0, None));
        assert_eq!(
            t.line().as_deref(),
            Some("no cloth crossing in 1 measured frame; no elements within 6.0 mm")
        );
    }
}
