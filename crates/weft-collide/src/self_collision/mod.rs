//! Particle–particle self-collision (and collision between cloths) with friction.
//!
//! Each particle is a sphere of radius thickness / 2, so two particles are kept a thickness
//! apart (Müller, "Ten Minute Physics" #11; Macklin et al. 2014, §5 for particle contacts).
//! Pairs of one cloth that lie within π t / 2 of each other at rest (t the largest
//! thickness), or share a triangle, are left to the cloth's own constraints: where a sheet t
//! thick folds onto itself, the layers touch across half a circle of diameter t, so two points
//! facing each other across a fold lie at least π t / 2 apart along the cloth. Nearer pairs can
//! only touch by compressing the cloth, which its stretch and shear constraints resist. (Like
//! NVIDIA Flex's self-collide filter, which ignores pairs closer than the particle radius at
//! rest; a cloth whose rest shape brings distant parts that close should be split into
//! several cloths, whose pairs are never exempt.) The grid search itself leaves these pairs
//! out, so a single layer lists none of its own neighbours.
//!
//! Candidate pairs live in a Verlet ("skin") list (Verlet 1967; Allen & Tildesley, "Computer
//! Simulation of Liquids", §5.3): every non-exempt pair at most R = t (1 + m) apart when the
//! list was built, t the largest member thickness and m the search margin, which is the skin.
//! The list is reused while every member stays within m t / 2 of its anchor (up to a
//! displacement common to all), so that every pair within t, every pair that can touch, is
//! always listed; the few members that stray are re-anchored and their new pairs added, and the
//! list is rebuilt from a [`CellGrid`](crate::grid::CellGrid) (points sorted by cell, swept in runs of cells on
//! rayon's threads) when many do. [`SelfCollision::refresh`] says why no contact can be missing.
//!
//! Contacts are solved Jacobi-style with constraint averaging (Macklin et al. 2014, "Unified
//! Particle Physics for Real-Time Applications", §4.2): every listed pair closer than its
//! target at the start of a sweep gives its two particles corrections computed from those same
//! positions, and each particle moves by the mean of its corrections. The corrections are
//! rounded to a common quantum and summed exactly, so their order does not matter: results
//! depend neither on the thread count, nor on the list's order, nor on when it was rebuilt (a
//! listed pair that is not touching does nothing), and both the pair search and the sweep run
//! in parallel.
//!
//! The parts, one subject per file: [`list`] holds the candidate pairs and builds them,
//! [`check`] decides before each sweep whether the list still holds (and clamps the
//! displacements), [`reanchor`] updates it for the few members that strayed, [`skin`] picks
//! the skin from the work it causes, [`exemptions`] says which pairs the cloth's own
//! constraints keep, [`contact`] runs the sweep, and [`times`] keeps the counters and clocks.

mod check;
mod contact;
mod exemptions;
mod list;
mod reanchor;
mod skin;
#[cfg(test)]
mod tests;
mod times;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use glam::DVec3;
use weft_solver::Solver;

use crate::error::CollideError;
use crate::friction::Friction;

pub(crate) use check::Clamp;
use check::Scan;
use contact::Sweep;
use exemptions::Exemptions;
use list::List;
use reanchor::Movers;
use skin::Skin;
pub use times::SelfCollisionTimes;
use times::Tally;

/// Self-collision settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfCollisionParams {
    /// Friction between touching particles.
    pub friction: Friction,
    /// Largest displacement of a particle in one substep, as a fraction of its thickness.
    ///
    /// Two particles approach by at most twice this per substep, so below 0.5 a layer cannot
    /// jump through another within one substep (the velocity clamp of Müller's method).
    pub max_displacement: f64,
    /// The candidate list's skin, as a fraction of the thickness: pairs up to
    /// thickness · (1 + search_margin) apart are listed, and the list is kept until a particle
    /// strays half the margin. It changes only the cost, never the result: 0 searches anew
    /// whenever anything moved. With `adaptive_margin`, the skin starts here and then follows
    /// the motion.
    pub search_margin: f64,
    /// Whether the skin adapts to the motion: thin at rest, thick while the cloth folds or
    /// slides, one step at a time between 0.25 and 4.0, past 1.0 only while the list is
    /// sparse (see `skin.rs`). Like the skin itself, it changes only the cost.
    pub adaptive_margin: bool,
}

impl Default for SelfCollisionParams {
    fn default() -> Self {
        Self {
            friction: Friction::new(0.3, 0.2),
            max_displacement: 0.45,
            search_margin: 0.5,
            adaptive_margin: true,
        }
    }
}

impl SelfCollisionParams {
    /// Checks a `max_displacement`: in (0, 0.5], so that two layers, each moving at most this
    /// fraction of the thickness per substep, cannot pass through each other within one.
    /// Says what is expected otherwise.
    pub fn check_max_displacement(v: f64) -> Result<(), &'static str> {
        if v.is_finite() && v > 0.0 && v <= 0.5 {
            Ok(())
        } else {
            Err("in (0, 0.5]")
        }
    }

    /// Checks a `search_margin`: finite and ≥ 0. Says what is expected otherwise.
    pub fn check_search_margin(v: f64) -> Result<(), &'static str> {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err("finite and >= 0")
        }
    }

    /// Checks the values make sense (the friction's, then
    /// [`SelfCollisionParams::check_max_displacement`] and
    /// [`SelfCollisionParams::check_search_margin`]).
    pub fn validate(&self) -> Result<(), CollideError> {
        self.friction.validate()?;
        for (name, value, check) in [
            (
                "self_collision.max_displacement",
                self.max_displacement,
                Self::check_max_displacement as fn(f64) -> Result<(), &'static str>,
            ),
            (
                "self_collision.search_margin",
                self.search_margin,
                Self::check_search_margin,
            ),
        ] {
            check(value).map_err(|expected| CollideError::InvalidParameter {
                name,
                value,
                expected,
            })?;
        }
        Ok(())
    }
}

/// Self-collision state: member particles, rest data, and the Verlet list of candidate pairs,
/// with the scratch of each part and the counters.
#[derive(Clone, Debug)]
pub(crate) struct SelfCollision {
    params: SelfCollisionParams,
    /// The list's skin now.
    skin: Skin,
    /// Participating particles, ascending.
    members: Vec<u32>,
    /// Member slot of each particle (`u32::MAX` for non-members).
    slot_of: Vec<u32>,
    exempt: Exemptions,
    /// The candidate pairs and the anchors they were listed at.
    list: List,
    /// Per chunk of particles, the last check's findings.
    scans: Vec<Scan>,
    /// Scratch of a partial update: the members that strayed and their new pairs.
    moved: Movers,
    /// Scratch of a sweep.
    sweep: Sweep,
    /// Rebuilds, partial updates and time spent so far.
    tally: Tally,
    /// Raised to abandon the frame in progress (see [`SelfCollision::set_stop`]).
    stop: Option<Arc<AtomicBool>>,
}

impl SelfCollision {
    /// Self-collision over `cloths` of `solver`; rest state = the solver's current positions.
    pub(crate) fn new(
        solver: &Solver,
        cloths: &[usize],
        params: SelfCollisionParams,
    ) -> Result<Self, CollideError> {
        params.validate()?;
        let n = solver.particles().len();
        let mut cloth = vec![u32::MAX; n];
        let rest = &solver.particles().positions;
        let mut longest_edge = 0.0f64;
        let mut members = Vec::new();
        for &c in cloths {
            let info = solver.cloths().get(c).ok_or(CollideError::NoSuchCloth {
                index: c,
                count: solver.cloths().len(),
            })?;
            for i in info.particles.clone() {
                cloth[i] = c as u32;
                members.push(i as u32);
            }
            for t in &info.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                    longest_edge = longest_edge.max(rest[a].distance(rest[b]));
                }
            }
        }
        members.sort_unstable();
        members.dedup();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &i in &members {
            (lo, hi) = (lo.min(rest[i as usize]), hi.max(rest[i as usize]));
        }
        let extent = (hi - lo).max_element().max(0.0);
        let mut slot_of = vec![u32::MAX; n];
        for (slot, &i) in members.iter().enumerate() {
            slot_of[i as usize] = slot as u32;
        }
        Ok(Self {
            params,
            skin: Skin::new(params.search_margin, params.adaptive_margin),
            members,
            slot_of,
            exempt: Exemptions::new(rest.clone(), cloth, longest_edge, extent),
            list: List::default(),
            scans: Vec::new(),
            moved: Movers::default(),
            sweep: Sweep::new(n),
            tally: Tally::default(),
            stop: None,
        })
    }

    /// A flag polled while the list is built: once raised, a build stops within a
    /// particle's partners and leaves no list (the frame in progress is being abandoned).
    pub(crate) fn set_stop(&mut self, flag: Arc<AtomicBool>) {
        self.stop = Some(flag);
    }

    /// The distance pair `(a, b)` must keep, or `None` if it is exempt (see
    /// [`Exemptions::apart`]).
    pub(crate) fn target(&self, a: u32, b: u32, thickness: &[f64]) -> Option<f64> {
        let t = self
            .list
            .built_for
            .unwrap_or_else(|| self.max_thickness(thickness));
        self.exempt.target(a, b, thickness, self.exempt.apart(t))
    }

    /// The largest member thickness (m), 0 without members.
    fn max_thickness(&self, thickness: &[f64]) -> f64 {
        self.members
            .iter()
            .map(|&i| thickness[i as usize])
            .fold(0.0f64, f64::max)
    }

    /// Lists built so far.
    pub(crate) fn rebuilds(&self) -> u64 {
        self.tally.rebuilds
    }

    /// Partial updates (a few members re-anchored) so far.
    pub(crate) fn updates(&self) -> u64 {
        self.tally.updates
    }

    /// Time spent in each part so far.
    pub(crate) fn times(&self) -> SelfCollisionTimes {
        self.tally.times
    }

    /// Candidate pairs in the current list.
    pub(crate) fn pair_count(&self) -> usize {
        self.list.len()
    }

    /// Drops the list (thickness changed): the next [`SelfCollision::refresh`] rebuilds it.
    pub(crate) fn invalidate(&mut self) {
        self.list.built_for = None;
    }

    /// The list radius R for largest thickness `t` (m).
    fn radius(&self, t: f64) -> f64 {
        t * (1.0 + self.skin.margin())
    }

    /// How far a member may stray from its anchor for thickness `t` (m): half the skin.
    fn limit(&self, t: f64) -> f64 {
        0.5 * self.skin.margin() * t
    }

    /// Makes sure the list holds every pair that may touch at `positions`.
    ///
    /// Invariant: the list (`pairs` and `extra`) holds every non-exempt pair whose anchors are
    /// at most R = t (1 + m) apart (m t the skin). With displacements Δᵢ = xᵢ − x⁰ᵢ and a
    /// common displacement c (their mean), a member is a mover if |Δᵢ − c| > m t / 2. Movers
    /// are re-anchored at x⁰ᵢ = xᵢ − c (so Δᵢ − c = 0) and their pairs within R of the new
    /// anchor added, which keeps the invariant; when there are many, the list is rebuilt. Then
    /// |Δᵢ − c| ≤ m t / 2 for every member, so |Δₐ − Δᵦ| ≤ m t and, by the triangle
    /// inequality, |x⁰ₐ − x⁰ᵦ| ≤ |xₐ − xᵦ| + m t: every pair within t now is listed. Every
    /// target is at most t (the mean of two thicknesses), so no contact is missing —
    /// the guarantee of a fresh search every sweep. c lets a cloth that falls or is carried as
    /// a whole keep its list. The check runs before every sweep, so it also catches moves
    /// between frames (pins, grabs, edits).
    ///
    /// With `clamp`, each member's displacement this substep is first limited to
    /// `max_displacement` · thickness (see [`SelfCollisionParams`]), in the same pass over the
    /// particles as the check. The check's common displacement is predicted from the last two
    /// (any common vector keeps the invariant; a good guess leaves fewer movers), so the whole
    /// check is one parallel pass.
    ///
    /// First, the work the last sweep did counts towards the skin's choice (see
    /// [`skin`]): a thicker skin drops the list, to be rebuilt below; a thinner one
    /// filters it down, before the check runs against the thinner skin's limit.
    pub(crate) fn refresh(
        &mut self,
        positions: &mut [DVec3],
        thickness: &[f64],
        clamp: Option<Clamp<'_>>,
    ) {
        self.timed(|t| &mut t.check, |s| s.check(positions, thickness, clamp));
    }
}
