//! A kinematic body inside the collision world: its parts at the substep's start and end,
//! the broad phase, and each particle's sweep, contact planes and projection.

use std::sync::Arc;

use rayon::prelude::*;
use weft_solver::Particles;

use super::contact::{Plane, planes, project, sweep};
use super::grid::PartGrid;
use super::motion::MovingPart;
use super::{BodyPart, KinematicBody};
use crate::chunk::{CHUNK, moving_views};
use crate::friction::Friction;

/// Preferred edge of the broad phase's cells (m): a few limb radii.
const CELL: f64 = 0.05;

/// Substeps one broad phase serves at most (see [`Window`]).
const WINDOW_SUBSTEPS: usize = 10;

/// The span of time the broad phase holds for: every part listed in every cell it could touch
/// at any time from `from` to `until`, for contacts within `reach`. Built at the window's start
/// pose with each part grown by a bound on how far it travels over the window (the sum of its
/// substeps' travel bounds, at most [`CELL`]), so one build serves up to [`WINDOW_SUBSTEPS`]
/// substeps instead of one.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Window {
    from: f64,
    until: f64,
    reach: f64,
}

impl Window {
    /// Whether the window holds for the substep `t0 → t1` (to rounding of the substep times).
    fn covers(&self, t0: f64, t1: f64, reach: f64) -> bool {
        let tol = |t: f64| 1e-12 * t.abs().max(1.0);
        self.reach == reach
            && t0 >= self.from - tol(self.from)
            && t1 <= self.until + tol(self.until)
    }
}

/// A body in the world.
#[derive(Clone, Debug)]
pub(crate) struct BodyCollider {
    body: Arc<dyn KinematicBody>,
    friction: Friction,
    /// Parts at the substep's start and end.
    start: Vec<BodyPart>,
    end: Vec<BodyPart>,
    /// The time `end` was evaluated at.
    end_time: Option<f64>,
    moving: Vec<MovingPart>,
    grid: PartGrid,
    /// What the grid holds for, if anything.
    window: Option<Window>,
    /// Scratch of a window's build: poses ahead, each part's travel so far, the grown parts.
    ahead: [Vec<BodyPart>; 2],
    travel: Vec<f64>,
    grown: Vec<MovingPart>,
    /// Per chunk of particles, scratch for one particle's contact planes.
    scratch: Vec<Vec<Plane>>,
}

impl BodyCollider {
    /// A body with its friction, placed at time `t`.
    pub fn new(body: Arc<dyn KinematicBody>, friction: Friction, t: f64) -> Self {
        let mut end = Vec::with_capacity(body.part_count());
        body.parts_at(t, &mut end);
        Self {
            body,
            friction,
            start: end.clone(),
            end,
            end_time: Some(t),
            moving: Vec::new(),
            grid: PartGrid::default(),
            window: None,
            ahead: [Vec::new(), Vec::new()],
            travel: Vec::new(),
            grown: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// The parts at the end of the current substep.
    pub fn parts(&self) -> &[BodyPart] {
        &self.end
    }

    /// The friction coefficients.
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// Moves the body to its poses at `t0` and `t1` (the substep's ends) and, unless its window
    /// still holds, builds the broad phase for contacts within `reach` (m) anew.
    pub fn set_time(&mut self, t0: f64, t1: f64, reach: f64) {
        // The last substep's end is this one's start (to rounding of the substep times).
        let reuse = self
            .end_time
            .is_some_and(|t| (t - t0).abs() <= 1e-12 * t0.abs().max(1.0));
        if reuse {
            std::mem::swap(&mut self.start, &mut self.end);
        } else {
            self.body.parts_at(t0, &mut self.start);
        }
        self.body.parts_at(t1, &mut self.end);
        self.end_time = Some(t1);
        let extent = reach + CELL;
        self.moving.clear();
        self.moving.extend(
            self.start
                .iter()
                .zip(&self.end)
                .map(|(a, b)| MovingPart::new(a, b, extent)),
        );
        if !self.window.is_some_and(|w| w.covers(t0, t1, reach)) {
            self.build_window(t0, t1, reach);
        }
    }

    /// Builds the broad phase for substeps of `t1 − t0` from `t0` on, as many as
    /// [`WINDOW_SUBSTEPS`] while no part's summed travel bound exceeds [`CELL`] (at least this
    /// substep), at the start pose with each part grown by its bound: a material point of a
    /// part moves at most its bound over the window, so every cell a part can touch then is
    /// listed. The poses ahead depend on time alone ([`KinematicBody`]).
    fn build_window(&mut self, t0: f64, t1: f64, reach: f64) {
        let extent = reach + CELL;
        let h = t1 - t0;
        self.travel.clear();
        self.travel.extend(self.moving.iter().map(|m| m.travel));
        let [before, after] = &mut self.ahead;
        before.clone_from(&self.end);
        let mut substeps = 1;
        while substeps < WINDOW_SUBSTEPS && h > 0.0 {
            self.body.parts_at(t0 + (substeps + 1) as f64 * h, after);
            let grows = before
                .iter()
                .zip(after.iter())
                .zip(&self.travel)
                .map(|((a, b), t)| t + MovingPart::new(a, b, extent).travel);
            let next: Vec<f64> = grows.collect();
            if next.iter().any(|&t| t > CELL) {
                break;
            }
            self.travel = next;
            std::mem::swap(before, after);
            substeps += 1;
        }
        self.grown.clear();
        self.grown.extend(
            self.start
                .iter()
                .zip(&self.travel)
                .map(|(p, &t)| MovingPart {
                    travel: t,
                    ..MovingPart::new(p, p, extent)
                }),
        );
        self.grid.build(&self.grown, reach, CELL);
        self.window = Some(Window {
            from: t0,
            until: t0 + substeps as f64 * h,
            reach,
        });
    }

    /// Each free particle against the body, after self-collision, in one pass: on the
    /// substep's first projection (`fresh`) its substep path swept against the moving parts,
    /// then the contact planes of every part within twice its thickness (or holding it),
    /// projected on at once — one broad-phase lookup per particle for all of it. In parallel
    /// over fixed chunks, each particle on its own: the same bits on any thread count.
    pub fn contact(&mut self, p: &mut Particles, thickness: &[f64], fresh: bool) -> BodyContacts {
        let chunks = p.len().div_ceil(CHUNK);
        if self.scratch.len() != chunks {
            self.scratch = vec![Vec::new(); chunks];
        }
        let (parts, grid, friction) = (&self.moving, &self.grid, self.friction);
        let (positions, prev, inv) = moving_views(p);
        positions
            .par_chunks_mut(CHUNK)
            .zip(self.scratch.par_iter_mut())
            .enumerate()
            .map(|(k, (xs, mine))| {
                let mut out = BodyContacts::default();
                for (j, x) in xs.iter_mut().enumerate() {
                    let i = k * CHUNK + j;
                    if inv[i] == 0.0 {
                        continue;
                    }
                    let r = thickness[i];
                    let mut here = grid.candidates(*x);
                    if fresh {
                        let n = sweep(parts, grid, here, prev[i], x, r);
                        if n > 0 {
                            out.swept += n;
                            here = grid.candidates(*x);
                        }
                    }
                    mine.clear();
                    planes(parts, here, *x, 2.0 * r, mine);
                    if mine.is_empty() {
                        continue;
                    }
                    out.planes += mine.len();
                    let (c, d) = project(parts, mine, prev[i], x, r, friction);
                    out.contacts += c;
                    out.deepest = out.deepest.max(d);
                }
                out
            })
            .reduce(BodyContacts::default, BodyContacts::combine)
    }
}

/// What one pass of [`BodyCollider::contact`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct BodyContacts {
    /// Particles stopped by the swept test.
    pub swept: usize,
    /// Contact planes found.
    pub planes: usize,
    /// Projections onto a plane.
    pub contacts: usize,
    /// Deepest overlap with the thickness shell (m).
    pub deepest: f64,
}

impl BodyContacts {
    /// Sums of counts, the larger depth: the same whatever the order.
    fn combine(self, o: Self) -> Self {
        Self {
            swept: self.swept + o.swept,
            planes: self.planes + o.planes,
            contacts: self.contacts + o.contacts,
            deepest: self.deepest.max(o.deepest),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::body::RoundCone;
    use crate::test_rand::rand;

    /// A tapered limb 0.4 m long turning at `spin` rad/s about an axis through one end while it
    /// translates at `speed` m/s.
    struct Limb {
        spin: f64,
        speed: f64,
    }

    impl KinematicBody for Limb {
        fn part_count(&self) -> usize {
            1
        }

        fn parts_at(&self, t: f64, out: &mut Vec<BodyPart>) {
            let rotation = DQuat::from_rotation_z(self.spin * t);
            let translation = DVec3::new(self.speed * t, 0.0, 0.0);
            let at = |p: DVec3| rotation * p + translation;
            out.clear();
            out.push(BodyPart {
                shape: RoundCone::new(at(DVec3::ZERO), at(DVec3::new(0.4, 0.0, 0.0)), 0.06, 0.04),
                rotation,
                translation,
            });
        }
    }

    /// Over 60 substeps of 1/600 s, every point within `reach` of the limb at a substep's start
    /// or end (sampled around both poses) has the limb among its grid candidates, and at every
    /// new window no material point near the limb moves farther over the window than the
    /// travel the grid was grown by; returns how many broad phases were built.
    fn windows(limb: Limb) -> usize {
        let (h, reach) = (1.0 / 600.0, 0.008);
        let body: Arc<dyn KinematicBody> = Arc::new(limb);
        let mut c = BodyCollider::new(body.clone(), Friction::default(), 0.0);
        let (mut s, mut builds, mut last, mut near) = (7u64, 0, None, 0);
        let mut parts = Vec::new();
        for k in 0..60 {
            let (t0, t1) = (k as f64 * h, (k + 1) as f64 * h);
            c.set_time(t0, t1, reach);
            if c.window != last
                && let Some(w) = c.window
            {
                builds += 1;
                // Material points within the travel bound's extent of the window's start pose,
                // carried rigidly to each substep end in the window.
                body.parts_at(w.from, &mut parts);
                let start = parts[0];
                let bound = c.grown[0].travel * (1.0 + 1e-9);
                let mut points = Vec::new();
                while points.len() < 200 {
                    let mid = start.shape.a.lerp(start.shape.b, 0.5 + 0.7 * rand(&mut s));
                    let p = mid + DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 0.1;
                    if start.shape.signed_distance(p) <= reach + CELL {
                        points.push(start.rotation.inverse() * (p - start.translation));
                    }
                }
                let mut t = w.from + h;
                while t <= w.until + 1e-12 {
                    body.parts_at(t, &mut parts);
                    for &local in &points {
                        let moved = (parts[0].rotation * local + parts[0].translation)
                            - (start.rotation * local + start.translation);
                        assert!(moved.length() <= bound, "{moved} over {bound} at {t} s");
                    }
                    t += h;
                }
            }
            last = c.window;
            for t in [t0, t1] {
                body.parts_at(t, &mut parts);
                let cone = parts[0].shape;
                for _ in 0..2000 {
                    let mid = cone.a.lerp(cone.b, 0.5 + 0.7 * rand(&mut s));
                    let p = mid + DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 0.08;
                    if cone.signed_distance(p) <= reach {
                        near += 1;
                        assert!(c.grid.candidates(p).contains(&0), "{p} at {t} s");
                    }
                }
            }
        }
        assert!(near > 50_000, "{near} points near the limb");
        builds
    }

    #[test]
    fn a_window_lists_the_limb_wherever_it_reaches_and_spans_several_substeps() {
        // A walking limb (tip at 3 m/s): a few broad phases for 60 substeps.
        let slow = windows(Limb {
            spin: 5.0,
            speed: 1.0,
        });
        assert!(slow <= 12, "{slow} builds");
        // A limb 10 cm a substep: a broad phase every substep, still listing it everywhere.
        let fast = windows(Limb {
            spin: 40.0,
            speed: 60.0,
        });
        assert_eq!(fast, 60);
    }
}
