//! The candidate list's skin, chosen from the work it causes.
//!
//! A Verlet list trades two costs against each other (Allen & Tildesley, "Computer Simulation
//! of Liquids", §5.3): a thicker skin lists more pairs, which every sweep filters, and a
//! thinner one is outgrown sooner, so the list is rebuilt and its members re-anchored more
//! often. Which skin is cheapest depends on the motion: a pile at rest wants a thin one, a
//! cloth folding fast or a single layer sliding (whose list holds few pairs at any skin) a
//! thick one. [`Skin`] counts both kinds of work in one unit over an epoch of sweeps, and at
//! its end moves one step along [`STEPS`]: thicker when the upkeep exceeds [`GROW_ABOVE`]
//! times the sweeps' filtering, thinner when it is below [`SHRINK_BELOW`] times it. The
//! counts, not clocks, decide, so the choice is the same on every run; and the skin changes
//! only the cost, never a result.

/// The skins the list may take, as fractions of the thickness. Those beyond one thickness are
/// for a single layer carried by a moving body (a garment on a walking character), whose list
/// holds few pairs at any skin while its members stray from their anchors all the time: the
/// skin grows past one thickness only while the list holds fewer than one pair per
/// [`SPARSE`] members.
pub(crate) const STEPS: [f64; 9] = [0.25, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0, 2.8, 4.0];

/// Members per listed pair, at least, for the skin to grow past one thickness. Where layers
/// lie on each other (a sheet folded on a sphere: 901 pairs for 16,384 members at one
/// thickness) a thicker skin lists tens of thousands of pairs, which the work model below,
/// fitted at skins up to one thickness, does not price: self-collision then cost more, not
/// less (1.9 → 2.5–4.3 ms per frame with steps up to 1.4–2.8).
const SPARSE: usize = 64;

/// Sweeps per epoch: the skin may change once per epoch.
const EPOCH: u32 = 32;

/// Work, in units of one listed pair filtered by one sweep, of a full list build per member
/// and per pair it lists, and of re-anchoring one member: the ratios of their measured costs
/// on a curtain folding onto itself at 128², 2 threads (the figures are in the performance
/// notes).
const BUILD_PER_MEMBER: u64 = 88;
const BUILD_PER_PAIR: u64 = 5;
const REANCHOR_PER_MEMBER: u64 = 1000;

/// Upkeep over filtering above which the skin grows, and below which it shrinks. With the
/// units above, these thresholds put the skin at the cheapest step of the unit cost
/// (filtering + upkeep per sweep) in every phase of the `self_collision_cost` example's two
/// scenes at 128² (a curtain falling, settling and at rest; a sheet dropped on a sphere).
const GROW_ABOVE: f64 = 4.0;
const SHRINK_BELOW: f64 = 0.5;

/// What [`Skin::record`] decides at the end of an epoch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Change {
    /// Keep the skin.
    Keep,
    /// The skin grew: the list must be rebuilt.
    Grow,
    /// The skin shrank: the list may be filtered down to the new radius.
    Shrink,
}

/// The skin now, and the work counted over the current epoch.
#[derive(Clone, Debug)]
pub(crate) struct Skin {
    /// Index into [`STEPS`], or `None` for a fixed skin.
    step: Option<usize>,
    margin: f64,
    sweeps: u32,
    filtered: u64,
    upkeep: u64,
    /// Steps taken so far.
    changes: u64,
}

impl Skin {
    /// A skin of `margin`, fixed, or (`adaptive`) starting at the step nearest to it.
    pub(crate) fn new(margin: f64, adaptive: bool) -> Self {
        let step = adaptive.then(|| {
            (0..STEPS.len())
                .min_by(|&a, &b| {
                    (STEPS[a] - margin)
                        .abs()
                        .total_cmp(&(STEPS[b] - margin).abs())
                })
                .unwrap_or(0)
        });
        Self {
            step,
            margin: step.map_or(margin, |s| STEPS[s]),
            sweeps: 0,
            filtered: 0,
            upkeep: 0,
            changes: 0,
        }
    }

    /// Steps taken so far.
    #[cfg(test)]
    pub(crate) fn changes(&self) -> u64 {
        self.changes
    }

    /// The skin, as a fraction of the thickness.
    pub(crate) fn margin(&self) -> f64 {
        self.margin
    }

    /// Counts a full build of `members` members listing `pairs` pairs.
    pub(crate) fn built(&mut self, members: usize, pairs: usize) {
        self.upkeep += BUILD_PER_MEMBER * members as u64 + BUILD_PER_PAIR * pairs as u64;
    }

    /// Counts `movers` members re-anchored.
    pub(crate) fn reanchored(&mut self, movers: usize) {
        self.upkeep += REANCHOR_PER_MEMBER * movers as u64;
    }

    /// Counts one sweep over `listed` pairs of a list of `members` members; at the end of an
    /// epoch, moves the skin one step towards the balance of upkeep and filtering, and says
    /// how it moved.
    pub(crate) fn record(&mut self, listed: usize, members: usize) -> Change {
        self.filtered += listed as u64;
        self.sweeps += 1;
        let Some(step) = self.step else {
            return Change::Keep;
        };
        let sparse = listed.saturating_mul(SPARSE) < members;
        // A skin past one thickness is for a sparse list only: once the list fills (layers
        // landing on each other), back to one thickness at once, a new epoch begun.
        if STEPS[step] > 1.0 && !sparse {
            let one = STEPS.iter().rposition(|&m| m <= 1.0).unwrap_or(0);
            (self.sweeps, self.filtered, self.upkeep) = (0, 0, 0);
            return self.take(step, one, Change::Shrink);
        }
        if self.sweeps < EPOCH {
            return Change::Keep;
        }
        let ratio = self.upkeep as f64 / self.filtered.max(1) as f64;
        (self.sweeps, self.filtered, self.upkeep) = (0, 0, 0);
        let thicker = step + 1 < STEPS.len() && (STEPS[step + 1] <= 1.0 || sparse);
        if ratio > GROW_ABOVE && thicker {
            self.take(step, step + 1, Change::Grow)
        } else if ratio < SHRINK_BELOW && step > 0 {
            self.take(step, step - 1, Change::Shrink)
        } else {
            Change::Keep
        }
    }

    /// Moves from step `from` to step `to`, which `change` describes.
    fn take(&mut self, from: usize, to: usize, change: Change) -> Change {
        self.step = Some(to);
        self.margin = STEPS[to];
        self.changes += u64::from(to != from);
        change
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fixed_skin_never_moves() {
        let mut skin = Skin::new(0.3, false);
        for _ in 0..10 * EPOCH {
            skin.built(1000, 0);
            assert_eq!(skin.record(1, 1000), Change::Keep);
        }
        assert_eq!((skin.margin(), skin.changes()), (0.3, 0));
    }

    #[test]
    fn upkeep_grows_the_skin_and_idle_pairs_shrink_it_one_step_per_epoch() {
        let mut skin = Skin::new(0.45, true);
        assert_eq!(skin.margin(), 0.5, "starts at the nearest step");
        // Rebuilt every sweep with few pairs: one step thicker per epoch, up to the last.
        let (up, last) = (STEPS.len() as u32 - 3, STEPS.len() as u32 - 1);
        for sweep in 1..=(up + 2) * EPOCH {
            skin.built(100, 10);
            let change = skin.record(10, 1000);
            assert_eq!(
                change == Change::Grow,
                sweep % EPOCH == 0 && sweep <= up * EPOCH
            );
            assert_ne!(change, Change::Shrink);
        }
        assert_eq!(skin.margin(), STEPS[STEPS.len() - 1]);
        // Many pairs, nothing rebuilt: one step thinner per epoch, down to the first.
        for sweep in 1..=(last + 2) * EPOCH {
            let change = skin.record(100_000, 10_000_000);
            assert_eq!(
                change == Change::Shrink,
                sweep % EPOCH == 0 && sweep <= last * EPOCH
            );
            assert_ne!(change, Change::Grow);
        }
        assert_eq!(
            (skin.margin(), skin.changes()),
            (STEPS[0], u64::from(up + last))
        );
        // Upkeep between the thresholds keeps it: here equal to the filtering.
        for _ in 0..4 * EPOCH {
            skin.reanchored(1);
            assert_eq!(
                skin.record(REANCHOR_PER_MEMBER as usize, 1_000_000),
                Change::Keep
            );
        }
        // Just above the growth threshold grows it.
        for sweep in 1..=EPOCH {
            skin.reanchored(5);
            let change = skin.record(REANCHOR_PER_MEMBER as usize, 1_000_000);
            assert_eq!(change == Change::Grow, sweep == EPOCH);
        }
        assert_eq!(skin.margin(), STEPS[1]);
    }

    #[test]
    fn only_a_sparse_list_grows_past_one_thickness() {
        // The same upkeep, rebuilt every sweep: a list of one pair per 10 members stops at one
        // thickness, one of one pair per 100 members goes on to the thickest step.
        for (listed, top) in [(100, 1.0), (10, STEPS[STEPS.len() - 1])] {
            let mut skin = Skin::new(0.5, true);
            for _ in 0..2 * STEPS.len() as u32 * EPOCH {
                skin.built(100, listed);
                skin.record(listed, 1000);
            }
            assert_eq!(skin.margin(), top, "{listed} pairs for 1000 members");
        }
        // At the thickest step, a list that fills goes back to one thickness at the next
        // sweep, and stays there while full.
        let mut skin = Skin::new(STEPS[STEPS.len() - 1], true);
        assert_eq!(skin.record(10, 1000), Change::Keep);
        assert_eq!(skin.record(100, 1000), Change::Shrink);
        assert_eq!(skin.margin(), 1.0);
        for _ in 0..4 * EPOCH {
            skin.built(100, 100);
            assert_ne!(skin.record(100, 1000), Change::Grow);
        }
        assert_eq!(skin.margin(), 1.0);
    }
}
