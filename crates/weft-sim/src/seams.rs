//! Seams that did not close: a garment's seam pairs still apart once the seams were due to
//! have closed (a little after the cloth's `seam_time`), for the warning `weft run`, `weft view`
//! and `weft render` print. A seam pulls its pair together over `seam_time` and then holds it;
//! a pair still open after that is held apart by something else: a fold caught between the
//! seam's edges (mesh contact lets nothing through), the body's friction, or springs too soft
//! to pull it shut.

use std::fmt;

use crate::Simulation;

/// A seam pair counts as open beyond this gap (m): the dressed garments' own tests hold a
/// closed seam below it.
pub const OPEN_GAP: f64 = 1e-3;

/// How long after its `seam_time` a cloth's seams are looked at (s): a seam that can close has
/// closed within a few frames of its closing time.
pub const SETTLE: f64 = 0.25;

/// A cloth whose seams are still open after they were due to close.
#[derive(Clone, Debug, PartialEq)]
pub struct OpenSeams {
    /// The cloth's name in the scene.
    pub cloth: String,
    /// Its seam pairs more than [`OPEN_GAP`] apart.
    pub open: usize,
    /// Its seam pairs.
    pub pairs: usize,
    /// The widest gap (m).
    pub widest: f64,
    /// Its `seam_time` (s).
    pub seam_time: f64,
}

impl fmt::Display for OpenSeams {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cloth `{}`: {} of its {} seam pairs are still open {SETTLE} s after seam_time \
             ({} s), the widest {:.1} cm apart. Something holds them: a fold caught in the \
             seam, the body's friction or soft springs; a longer seam_time gives the panels \
             time to settle as they close",
            self.cloth,
            self.open,
            self.pairs,
            self.seam_time,
            self.widest * 100.0
        )
    }
}

/// The seams of scene cloth `i` now, when it has seams: its pairs and their gaps.
fn gaps(sim: &Simulation, i: usize) -> Option<Vec<f64>> {
    let c = sim.scene.cloths.get(i)?;
    if c.seams.is_empty() {
        return None;
    }
    let x = sim.cloth_positions(i);
    let at = |v: u32| x.get(v as usize).copied();
    Some(
        (c.seams.iter())
            .filter_map(|&[a, b]| Some(at(a)?.distance(at(b)?)))
            .collect(),
    )
}

/// Whether scene cloth `i` has seams and they are due to have closed ([`SETTLE`] after its
/// `seam_time`).
fn due(sim: &Simulation, i: usize) -> bool {
    (sim.scene.cloths.get(i))
        .is_some_and(|c| !c.seams.is_empty() && sim.time() + 1e-9 >= c.seam_time + SETTLE)
}

impl Simulation {
    /// Scene cloth `i`'s seams, if they are due to have closed ([`SETTLE`] after its
    /// `seam_time`) and some pair is still more than [`OPEN_GAP`] apart.
    pub fn open_seams(&self, i: usize) -> Option<OpenSeams> {
        if !due(self, i) {
            return None;
        }
        let c = &self.scene.cloths[i];
        let gaps = gaps(self, i)?;
        let open = gaps.iter().filter(|&&g| g > OPEN_GAP).count();
        (open > 0).then(|| OpenSeams {
            cloth: c.name.clone(),
            open,
            pairs: gaps.len(),
            widest: gaps.iter().copied().fold(0.0, f64::max),
            seam_time: c.seam_time,
        })
    }
}

/// Looks at each cloth's seams once, on the first frame they are due to have closed, and
/// reports those still open; starts over when the simulation's time goes back (a reset).
#[derive(Clone, Debug, Default)]
pub struct SeamWatch {
    /// Per scene cloth, whether its seams were looked at.
    looked: Vec<bool>,
    /// The time of the last look (s).
    last: f64,
}

impl SeamWatch {
    /// The cloths of `sim` whose seams came due since the last call and are still open.
    pub fn look(&mut self, sim: &Simulation) -> Vec<OpenSeams> {
        let n = sim.scene.cloths.len();
        if self.looked.len() != n || sim.time() < self.last {
            self.looked = vec![false; n];
        }
        self.last = sim.time();
        let mut found = Vec::new();
        for i in 0..n {
            if !self.looked[i] && due(sim, i) {
                self.looked[i] = true;
                found.extend(sim.open_seams(i));
            }
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use weft_scene::Override;

    /// The shipped skirt, sewn at once (`seam_time` 0), without cloth contact.
    fn skirt() -> Simulation {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/skirt.toml");
        let ov: Vec<Override> = ["cloth.skirt.seam_time=0", "self_collision.enabled=false"]
            .iter()
            .map(|s| s.parse().expect("override"))
            .collect();
        Simulation::new(weft_scene::load(&path, &ov).expect("skirt")).expect("builds")
    }

    #[test]
    fn a_seam_pulled_open_after_it_was_due_to_close_is_reported_once() {
        let mut sim = skirt();
        let mut watch = SeamWatch::default();
        assert_eq!(sim.open_seams(0), None, "not due at the start");
        // Due after SETTLE (15 frames at 60 a second): every pair closed by then.
        while sim.time() + 1e-9 < SETTLE {
            assert!(watch.look(&sim).is_empty());
            sim.step().expect("steps");
        }
        assert_eq!(sim.open_seams(0), None, "the seams closed");
        assert!(watch.look(&sim).is_empty());
        // One seam pair pulled 5 cm apart: an open seam, the widest 5 cm, reported by a
        // watch that has not looked yet, and by this one not again.
        let [a, _] = sim.scene.cloths[0].seams[3];
        let mut x = sim.cloth_positions(0).to_vec();
        x[a as usize].x += 0.05;
        sim.set_cloth_positions(0, &x).expect("positions");
        let open = sim.open_seams(0).expect("open");
        assert_eq!(
            (open.open, open.pairs),
            (1, sim.scene.cloths[0].seams.len())
        );
        assert!((open.widest - 0.05).abs() < 1e-3, "{open:?}");
        let said = open.to_string();
        assert!(
            said.contains("`skirt`: 1 of its") && said.contains("seam_time"),
            "{said}"
        );
        assert!(watch.look(&sim).is_empty(), "looked at once");
        assert_eq!(SeamWatch::default().look(&sim), vec![open]);
    }
}
