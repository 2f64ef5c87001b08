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
//! list is rebuilt from a [`CellGrid`] (points sorted by cell, swept in runs of cells on
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

use std::time::{Duration, Instant};

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;
use weft_solver::{Particles, Solver};

use crate::error::CollideError;
use crate::friction::Friction;
use crate::self_contact::{Bins, State, apply, find_contacts};
use crate::skin::{Change, Skin};
use crate::spatial_hash::{CellGrid, Queries};
use crate::times::SelfCollisionTimes;

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
    /// slides, one step at a time between 0.25 and 1.0 (see `skin.rs`). Like the skin itself,
    /// it changes only the cost.
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
    /// Checks the values make sense.
    pub fn validate(&self) -> Result<(), CollideError> {
        self.friction.validate()?;
        for (name, value, ok) in [
            (
                "self_collision.max_displacement",
                self.max_displacement,
                self.max_displacement > 0.0,
            ),
            (
                "self_collision.search_margin",
                self.search_margin,
                self.search_margin >= 0.0,
            ),
        ] {
            if !(value.is_finite() && ok) {
                return Err(CollideError::InvalidParameter {
                    name,
                    value,
                    expected: "finite and positive",
                });
            }
        }
        Ok(())
    }
}

/// A list is rebuilt rather than updated when more than 1/MOVERS_CAP of the members stray at
/// once, or more than 1/REANCHORED_CAP have strayed since the last build: a partial update
/// costs about eight times a rebuild per member (measured at 128², 2 threads).
const MOVERS_CAP: usize = 16;
const REANCHORED_CAP: usize = 8;

/// Below this many listed pairs a sweep runs on one thread.
const SERIAL_PAIRS: usize = 4096;

/// Members per rayon task in the per-member loops.
const MEMBER_CHUNK: usize = 4096;

/// Cloth length a sheet `t` thick folds over when its two layers touch, as a multiple of
/// `t`: its mid-surface bends through half a circle of diameter `t`, π t / 2 long.
const FOLD: f64 = std::f64::consts::FRAC_PI_2;

/// What decides whether a pair is exempt: the members' rest positions and cloths.
///
/// A pair is exempt when both particles belong to one cloth and lie at most
/// [`Exemptions::apart`] apart at rest. The test runs on tags (see [`Exemptions::tag`]): the
/// rest positions with each cloth moved away from the others, so that one distance test,
/// inside the grid's search, both leaves exempt pairs out and keeps every pair of two cloths.
#[derive(Clone, Debug)]
struct Exemptions {
    /// Rest positions (global index; only members are meaningful).
    rest: Vec<DVec3>,
    /// Cloth of each particle (global index).
    cloth: Vec<u32>,
    /// The longest triangle edge at rest (m).
    longest_edge: f64,
    /// The largest extent of the members' rest box (m).
    extent: f64,
    /// Every particle's tag, for the distance in `tags_for` (NaN before the first).
    tags: Vec<DVec3>,
    tags_for: f64,
}

impl Exemptions {
    /// The rest distance up to which a pair of one cloth is exempt for largest thickness `t`:
    /// the longer of [`FOLD`] · t and the longest edge (so that every pair sharing a triangle
    /// is), with a margin of 10⁻⁶ for rounding.
    fn apart(&self, t: f64) -> f64 {
        (FOLD * t).max(self.longest_edge) * (1.0 + 1e-6)
    }

    /// Particle `i`'s tag for exemption distance `apart`: its rest position moved along x by
    /// its cloth's index times one rest extent and twice `apart`, so that two cloths' tags are
    /// always more than `apart` apart.
    #[inline(always)]
    fn tag(&self, i: usize, apart: f64) -> DVec3 {
        let gap = self.extent + 2.0 * apart;
        let mut tag = self.rest[i];
        tag.x += f64::from(self.cloth[i]) * gap;
        tag
    }

    /// The distance pair `(a, b)` must keep (their mean thickness), or `None` if it is exempt
    /// for exemption distance `apart`.
    fn target(&self, a: u32, b: u32, thickness: &[f64], apart: f64) -> Option<f64> {
        let (a, b) = (a as usize, b as usize);
        (self.tag(a, apart).distance_squared(self.tag(b, apart)) > apart * apart)
            .then(|| 0.5 * (thickness[a] + thickness[b]))
    }

    /// Every particle's tag for exemption distance `apart` (made once per distance).
    fn tags(&mut self, apart: f64) -> &[DVec3] {
        if self.tags_for != apart {
            self.tags = (0..self.rest.len()).map(|i| self.tag(i, apart)).collect();
            self.tags_for = apart;
        }
        &self.tags
    }
}

/// What limits a substep's displacements (see [`SelfCollision::refresh`]).
#[derive(Clone, Copy)]
pub(crate) struct Clamp<'a> {
    /// Positions at the start of the substep.
    pub prev: &'a [DVec3],
    /// Inverse masses (pinned particles are left alone).
    pub w: &'a [f64],
}

impl Clamp<'_> {
    /// Moves particle `i` back towards its start of substep until it is at most `limit` away.
    #[inline(always)]
    fn apply(&self, i: usize, x: &mut DVec3, limit: f64) {
        if self.w[i] == 0.0 {
            return;
        }
        let d = *x - self.prev[i];
        // Most particles move less than the limit: compare squares, and take the root only
        // for those that do not.
        let len2 = d.length_squared();
        if len2 > limit * limit {
            *x = self.prev[i] + d * (limit / len2.sqrt());
        }
    }
}

/// One chunk's part of a list check: the box and sum of its members' displacements, and its
/// movers (slots).
#[derive(Clone, Debug)]
struct Scan {
    lo: DVec3,
    hi: DVec3,
    sum: DVec3,
    movers: Vec<u32>,
}

impl Default for Scan {
    fn default() -> Self {
        Self {
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
            sum: DVec3::ZERO,
            movers: Vec::new(),
        }
    }
}

impl Scan {
    /// Empties the findings, keeping the movers' storage.
    fn reset(&mut self) {
        let empty = Scan::default();
        (self.lo, self.hi, self.sum) = (empty.lo, empty.hi, empty.sum);
        self.movers.clear();
    }
}

/// Candidate pairs as struct-of-arrays, a < b.
#[derive(Clone, Debug, Default)]
struct PairList {
    a: Vec<u32>,
    b: Vec<u32>,
    target: Vec<f64>,
}

impl PairList {
    fn clear(&mut self) {
        self.a.clear();
        self.b.clear();
        self.target.clear();
    }

    fn push(&mut self, a: u32, b: u32, target: f64) {
        self.a.push(a);
        self.b.push(b);
        self.target.push(target);
    }

    fn len(&self) -> usize {
        self.a.len()
    }

    /// Keeps the pairs for which `keep(a, b, target)` holds, in order.
    fn retain(&mut self, mut keep: impl FnMut(u32, u32, f64) -> bool) {
        let mut n = 0;
        for k in 0..self.a.len() {
            let (a, b, target) = (self.a[k], self.b[k], self.target[k]);
            self.a[n] = a;
            self.b[n] = b;
            self.target[n] = target;
            n += usize::from(keep(a, b, target));
        }
        self.a.truncate(n);
        self.b.truncate(n);
        self.target.truncate(n);
    }
}

/// A pair (a < b) as one key.
#[inline(always)]
fn pair_key(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

/// Self-collision state: member particles, rest data, and the Verlet list of candidate pairs.
#[derive(Clone, Debug)]
pub(crate) struct SelfCollision {
    params: SelfCollisionParams,
    /// The list's skin now.
    skin: Skin,
    /// Participating particles, ascending.
    members: Vec<u32>,
    exempt: Exemptions,
    grid: CellGrid,
    /// The pairs of the last full build, one list per run of grid cells.
    pairs: Vec<PairList>,
    /// Each member's position at the last full build (member order): a pair is in `pairs`
    /// exactly when it is not exempt and these two are at most R apart by the grid's own test.
    built_pos: Vec<DVec3>,
    /// Each member's anchor x⁰ (member order): its position at the last full build, or, for
    /// a member re-anchored since, its position then less the common displacement.
    built_at: Vec<DVec3>,
    /// Members (slots) re-anchored since the last full build, and a flag per slot: their
    /// positions in `grid` are stale.
    reanchored: Vec<u32>,
    is_reanchored: Vec<bool>,
    /// Member slot of each particle (`u32::MAX` for non-members).
    slot_of: Vec<u32>,
    /// Pairs added for re-anchored members since the last full build (not in `pairs`), in the
    /// order they were added, and the same pairs as keys ([`pair_key`]) to look them up.
    extra: PairList,
    in_extra: FxHashSet<u64>,
    /// Partial updates (re-anchoring a few members) so far.
    updates: u64,
    /// Scratch: members that moved past the limit, a flag per slot for them (false between
    /// re-anchorings), and the pairs found for them.
    movers: Vec<u32>,
    is_mover: Vec<bool>,
    new_pairs: Vec<(u32, u32)>,
    /// The members' mean displacement from their anchors at the last two checks.
    drift: [DVec3; 2],
    /// Per chunk of particles, the last check's findings.
    scans: Vec<Scan>,
    /// Re-anchored members (slots) by anchor, in cells of the grid's size (built at the first
    /// re-anchoring after a build, then updated with each re-anchoring's movers); the movers'
    /// anchors, sorted once by cell for both grids' queries; a query's answer.
    recent: CellGrid,
    near_points: Vec<DVec3>,
    near_queries: Queries,
    near: Vec<u32>,
    /// Largest member thickness the list was built for; `None` when there is no list.
    built_for: Option<f64>,
    /// Lists built so far.
    rebuilds: u64,
    /// Sweep scratch: per list, the corrections of its touching pairs binned by particle
    /// range; per particle, the exact sum of its corrections and their count (zero between
    /// sweeps).
    contacts: Vec<Bins>,
    sums: Vec<DVec3>,
    counts: Vec<u32>,
    /// Time spent in each part so far.
    times: SelfCollisionTimes,
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
            exempt: Exemptions {
                rest: rest.clone(),
                cloth,
                longest_edge,
                extent,
                tags: Vec::new(),
                tags_for: f64::NAN,
            },
            grid: CellGrid::new(),
            pairs: Vec::new(),
            built_pos: Vec::new(),
            built_at: Vec::new(),
            reanchored: Vec::new(),
            is_reanchored: Vec::new(),
            slot_of,
            extra: PairList::default(),
            in_extra: FxHashSet::default(),
            updates: 0,
            movers: Vec::new(),
            is_mover: Vec::new(),
            new_pairs: Vec::new(),
            drift: [DVec3::ZERO; 2],
            scans: Vec::new(),
            recent: CellGrid::new(),
            near: Vec::new(),
            near_points: Vec::new(),
            near_queries: Queries::default(),
            built_for: None,
            rebuilds: 0,
            contacts: Vec::new(),
            sums: vec![DVec3::ZERO; n],
            counts: vec![0; n],
            times: SelfCollisionTimes::default(),
        })
    }

    /// The distance pair `(a, b)` must keep, or `None` if it is exempt (see
    /// [`Exemptions::apart`]).
    pub(crate) fn target(&self, a: u32, b: u32, thickness: &[f64]) -> Option<f64> {
        let t = self
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
        self.rebuilds
    }

    /// Partial updates (a few members re-anchored) so far.
    pub(crate) fn updates(&self) -> u64 {
        self.updates
    }

    /// Time spent in each part so far.
    pub(crate) fn times(&self) -> SelfCollisionTimes {
        self.times
    }

    /// Candidate pairs in the current list.
    pub(crate) fn pair_count(&self) -> usize {
        self.pairs.iter().map(PairList::len).sum::<usize>() + self.extra.len()
    }

    /// Drops the list (thickness changed): the next [`SelfCollision::refresh`] rebuilds it.
    pub(crate) fn invalidate(&mut self) {
        self.built_for = None;
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
    /// [`crate::skin`]): a thicker skin drops the list, to be rebuilt below; a thinner one
    /// filters it down, before the check runs against the thinner skin's limit.
    pub(crate) fn refresh(
        &mut self,
        positions: &mut [DVec3],
        thickness: &[f64],
        clamp: Option<Clamp<'_>>,
    ) {
        self.timed(|t| &mut t.check, |s| s.check(positions, thickness, clamp));
    }

    /// Runs `f` and adds the time it took to the part `part` picks, less the time of the parts
    /// timed inside it (a check that rebuilds counts the build as a build, not as check).
    fn timed<T>(
        &mut self,
        part: fn(&mut SelfCollisionTimes) -> &mut Duration,
        f: impl FnOnce(&mut Self) -> T,
    ) -> T {
        let (start, before) = (Instant::now(), self.times.total());
        let out = f(self);
        let inside = self.times.total() - before;
        *part(&mut self.times) += start.elapsed().saturating_sub(inside);
        out
    }

    /// [`SelfCollision::refresh`] without its clock.
    fn check(&mut self, positions: &mut [DVec3], thickness: &[f64], clamp: Option<Clamp<'_>>) {
        match self.skin.record(self.pair_count()) {
            Change::Keep => {}
            Change::Grow => self.built_for = None,
            Change::Shrink => self.shrink(),
        }
        let max = self.params.max_displacement;
        // The list's thickness, half-skin² and predicted common displacement, unless there is
        // no list to check (none built yet, or no thickness or members: no pairs).
        let check = self
            .built_for
            .filter(|&t| t > 0.0 && !self.members.is_empty())
            .map(|t| {
                let limit = self.limit(t);
                (t, limit * limit, 2.0 * self.drift[0] - self.drift[1])
            });
        // Per fixed chunk of particles (so the sum is the same on any thread count): clamp,
        // then the box and the sum of the members' displacements, and the movers.
        self.scans
            .resize_with(positions.len().div_ceil(MEMBER_CHUNK), Scan::default);
        let (slot_of, built_at) = (&self.slot_of, &self.built_at);
        positions
            .par_chunks_mut(MEMBER_CHUNK)
            .zip(self.scans.par_iter_mut())
            .enumerate()
            .for_each(|(k, (xs, scan))| {
                scan.reset();
                // In locals, not through `scan`: the movers' pushes would otherwise make the
                // compiler store and reload the three sums at every particle.
                let (mut lo, mut hi, mut sum) = (scan.lo, scan.hi, scan.sum);
                let movers = &mut scan.movers;
                for (j, x) in xs.iter_mut().enumerate() {
                    let i = k * MEMBER_CHUNK + j;
                    let slot = slot_of[i];
                    if slot == u32::MAX {
                        continue;
                    }
                    if let Some(clamp) = clamp {
                        clamp.apply(i, x, max * thickness[i]);
                    }
                    if let Some((_, limit2, guess)) = check {
                        let d = *x - built_at[slot as usize];
                        (lo, hi, sum) = (lo.min(d), hi.max(d), sum + d);
                        if (d - guess).length_squared() > limit2 {
                            movers.push(slot);
                        }
                    }
                }
                (scan.lo, scan.hi, scan.sum) = (lo, hi, sum);
            });
        let Some((t, limit2, guess)) = check else {
            if self.built_for.is_none() {
                self.rebuild(positions, thickness);
            }
            return;
        };
        let empty = Scan::default();
        let (lo, hi, sum) = self
            .scans
            .iter()
            .fold((empty.lo, empty.hi, empty.sum), |(lo, hi, sum), s| {
                (lo.min(s.lo), hi.max(s.hi), sum + s.sum)
            });
        self.drift = [sum / self.members.len() as f64, self.drift[0]];
        // Every |Δᵢ − box centre| is at most the box's half-diagonal: often that settles it.
        if (0.5 * (hi - lo)).length_squared() <= limit2 {
            return;
        }
        self.movers.clear();
        for scan in &self.scans {
            self.movers.extend_from_slice(&scan.movers);
        }
        if self.movers.len() > (self.members.len() / MOVERS_CAP).max(64) {
            return self.rebuild(positions, thickness);
        }
        if !self.movers.is_empty() {
            self.reanchor(positions, thickness, guess, t);
        }
    }

    /// Re-anchors `movers` at xᵢ − c and lists their pairs within R of the new anchors (see
    /// [`SelfCollision::refresh`]); rebuilds instead once many members have been re-anchored.
    fn reanchor(&mut self, positions: &[DVec3], thickness: &[f64], c: DVec3, t: f64) {
        self.timed(
            |times| &mut times.reanchor,
            |s| s.reanchor_movers(positions, thickness, c, t),
        );
    }

    /// [`SelfCollision::reanchor`] without its clock.
    fn reanchor_movers(&mut self, positions: &[DVec3], thickness: &[f64], c: DVec3, t: f64) {
        let before = self.reanchored.len();
        for &m in &self.movers {
            let m = m as usize;
            self.built_at[m] = positions[self.members[m] as usize] - c;
            if !self.is_reanchored[m] {
                self.is_reanchored[m] = true;
                self.reanchored.push(m as u32);
            }
        }
        if self.reanchored.len() > (self.members.len() / REANCHORED_CAP).max(64) {
            return self.rebuild(positions, thickness);
        }
        self.updates += 1;
        self.skin.reanchored(self.movers.len());
        let (radius, apart) = (self.radius(t), self.exempt.apart(t));
        let r2 = radius * radius;
        let spacing = self.grid.spacing();
        if before == 0 {
            self.recent.build(&self.built_at, &self.reanchored, spacing);
        } else {
            // Movers re-anchored before leave their old cells; the others keep their places.
            let mut new_ones = self.reanchored[before..].to_vec();
            new_ones.sort_unstable();
            self.recent.update(&self.built_at, &self.movers, |m| {
                new_ones.binary_search(&m).is_err()
            });
        }
        let new_pairs = &mut self.new_pairs;
        new_pairs.clear();
        // Members never re-anchored sit in the grid at their anchors.
        self.near_points.clear();
        self.near_points
            .extend(self.movers.iter().map(|&m| self.built_at[m as usize]));
        self.near_queries.sort(&self.near_points, spacing);
        self.is_mover.resize(self.members.len(), false);
        for &m in &self.movers {
            self.is_mover[m as usize] = true;
        }
        let (members, slot_of, is_reanchored) = (&self.members, &self.slot_of, &self.is_reanchored);
        let (movers, is_mover) = (&self.movers, &self.is_mover);
        self.grid.for_each_near_all(
            &self.near_points,
            &self.near_queries,
            radius,
            &mut self.near,
            |k, j| {
                let id = members[movers[k] as usize];
                if j != id && !is_reanchored[slot_of[j as usize] as usize] {
                    new_pairs.push((id.min(j), id.max(j)));
                }
            },
        );
        // Re-anchored members, at their anchors in `recent`. Two movers find each other
        // (the distance test is symmetric): the pair is kept from the lower slot's query, so
        // that no pair is found twice.
        self.recent.for_each_near_all(
            &self.near_points,
            &self.near_queries,
            radius,
            &mut self.near,
            |k, r| {
                let m = movers[k];
                if r != m && (m < r || !is_mover[r as usize]) {
                    let (id, j) = (members[m as usize], members[r as usize]);
                    new_pairs.push((id.min(j), id.max(j)));
                }
            },
        );
        for &m in &self.movers {
            self.is_mover[m as usize] = false;
        }
        for &(a, b) in &self.new_pairs {
            let (sa, sb) = (self.slot_of[a as usize], self.slot_of[b as usize]);
            // Listed at the build (the grid's test, replayed), or added since.
            let built =
                self.built_pos[sa as usize].distance_squared(self.built_pos[sb as usize]) <= r2;
            if built {
                continue;
            }
            if let Some(target) = self.exempt.target(a, b, thickness, apart)
                && self.in_extra.insert(pair_key(a, b))
            {
                self.extra.push(a, b, target);
            }
        }
    }

    /// Builds the list at `positions`: pairs from the grid, run by run on rayon's threads,
    /// with their targets.
    fn rebuild(&mut self, positions: &[DVec3], thickness: &[f64]) {
        self.timed(|t| &mut t.rebuild, |s| s.build(positions, thickness));
    }

    /// [`SelfCollision::rebuild`] without its clock.
    fn build(&mut self, positions: &[DVec3], thickness: &[f64]) {
        self.rebuilds += 1;
        for &r in &self.reanchored {
            self.is_reanchored[r as usize] = false;
        }
        self.reanchored.clear();
        self.is_reanchored.resize(self.members.len(), false);
        self.extra.clear();
        self.in_extra.clear();
        self.built_at.clear();
        self.built_at
            .extend(self.members.iter().map(|&i| positions[i as usize]));
        self.built_pos.clone_from(&self.built_at);
        self.drift = [DVec3::ZERO; 2];
        let max_t = self.max_thickness(thickness);
        self.built_for = Some(max_t);
        self.pairs.iter_mut().for_each(PairList::clear);
        if max_t <= 0.0 {
            return;
        }
        let apart = self.exempt.apart(max_t);
        let radius = self.radius(max_t);
        self.grid.build(positions, &self.members, radius);
        self.grid.tag(self.exempt.tags(apart));
        // A few runs per thread balance the load; the runs change nothing but the cost.
        let runs = self.grid.cell_runs(4 * rayon::current_num_threads());
        self.pairs.resize_with(runs.len(), PairList::default);
        let grid = &self.grid;
        self.pairs.par_iter_mut().zip(runs).for_each(|(list, run)| {
            list.clear();
            let mut row = Vec::new();
            // Exempt pairs are left out by the search itself.
            grid.for_each_row_in(run, radius, apart, &mut row, |i, near| {
                let ti = thickness[i as usize];
                for &j in near {
                    list.push(i.min(j), i.max(j), 0.5 * (ti + thickness[j as usize]));
                }
            });
        });
        self.skin.built(self.members.len(), self.pair_count());
    }

    /// Lists for the (thinner) skin's radius R: keeps in `pairs` those whose positions at the
    /// build are within R, the grid's test replayed (what a build at R would list), moves to
    /// `extra` the others whose anchors are within R (a member re-anchored since the build is
    /// nearer its partner now), and keeps in `extra` those whose anchors are within R. Every
    /// non-exempt pair whose anchors are within R stays listed, and none twice. Rare (at most
    /// once per epoch): serial.
    fn shrink(&mut self) {
        let Some(t) = self.built_for else { return };
        let radius = self.radius(t);
        let r2 = radius * radius;
        let slot_of = &self.slot_of;
        let near = |anchors: &[DVec3], a: u32, b: u32| {
            let (sa, sb) = (slot_of[a as usize], slot_of[b as usize]);
            anchors[sa as usize].distance_squared(anchors[sb as usize]) <= r2
        };
        // Pairs of the build's lists are not in `extra`: the moved ones can join it as they
        // are.
        let extra = &mut self.extra;
        extra.retain(|a, b, _| near(&self.built_at, a, b));
        for list in &mut self.pairs {
            list.retain(|a, b, target| {
                let built = near(&self.built_pos, a, b);
                if !built && near(&self.built_at, a, b) {
                    extra.push(a, b, target);
                }
                built
            });
        }
        self.in_extra.clear();
        self.in_extra
            .extend(extra.a.iter().zip(&extra.b).map(|(&a, &b)| pair_key(a, b)));
    }

    /// One Jacobi sweep over the touching pairs (see the module doc); returns the number of
    /// contacts and the deepest overlap (m). Call [`SelfCollision::refresh`] first.
    pub(crate) fn solve(&mut self, p: &mut Particles) -> (usize, f64) {
        let start = Instant::now();
        let lists: Vec<&PairList> = self.pairs.iter().chain([&self.extra]).collect();
        self.contacts.resize_with(lists.len(), Default::default);
        let friction = self.params.friction;
        let state = State {
            x: &p.positions,
            prev: &p.prev_positions,
            w: &p.inv_masses,
        };
        let n = p.positions.len();
        let find = |(list, out): (&&PairList, &mut Bins)| {
            out.reset(n);
            find_contacts((&list.a, &list.b, &list.target), state, friction, out)
        };
        // A few thousand pairs take less time than waking another thread: below that, the
        // lists are not split among threads.
        let total: usize = lists.iter().map(|l| l.len()).sum();
        let serial = if total < SERIAL_PAIRS { usize::MAX } else { 1 };
        let deepest = lists
            .par_iter()
            .zip(self.contacts.par_iter_mut())
            .with_min_len(serial)
            .map(find)
            .reduce(|| 0.0, f64::max);
        let found = Instant::now();
        self.times.find += found - start;
        self.sums.resize(n, DVec3::ZERO);
        self.counts.resize(n, 0);
        let contacts = apply(
            &self.contacts,
            &mut p.positions,
            &mut self.sums,
            &mut self.counts,
        );
        self.times.apply += found.elapsed();
        (contacts, deepest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenarios::self_fold;
    use crate::skin::STEPS;
    use crate::test_rand::rand;
    use weft_solver::{
        ClothParams, Forces, GridDesc, Mass, Method, Orientation, Settings, SolverBuilder,
        SubstepContext, SubstepHook,
    };

    const N: usize = 24;
    const SPACING: f64 = 0.01;

    /// A solver with `cloths` horizontal `n`×`n` sheets of `size` (m) at the same rest place,
    /// each SPACING thick.
    fn sheets(cloths: usize, n: usize, size: (f64, f64)) -> Solver {
        let mesh = GridDesc {
            resolution: (n, n),
            size,
            center: DVec3::ZERO,
            orientation: Orientation::Horizontal,
            mass: Mass::Total(0.1),
            pins: vec![],
        }
        .build()
        .expect("grid");
        let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("builder");
        for k in 0..cloths {
            b.add_cloth(format!("cloth {k}"), &mesh, ClothParams::default(), SPACING)
                .expect("cloth");
        }
        b.build()
    }

    /// An N×N cloth of thickness = spacing (flat at rest), and positions accordion-folded in
    /// layers of 4 rows 0.9 thickness apart, every particle jittered by up to 0.3 thickness:
    /// a random folded configuration.
    fn folded() -> (Solver, Vec<DVec3>, Vec<f64>) {
        let side = SPACING * (N - 1) as f64;
        let solver = sheets(1, N, (side, side));
        let mut seed = 7;
        let mut x = solver.particles().positions.clone();
        for j in 0..N {
            for i in 0..N {
                let (layer, k) = (j / 4, j % 4);
                let along = if layer % 2 == 0 { k } else { 3 - k };
                let jitter = DVec3::new(rand(&mut seed), rand(&mut seed), rand(&mut seed));
                x[j * N + i] = DVec3::new(
                    i as f64 * SPACING,
                    layer as f64 * 0.9 * SPACING,
                    along as f64 * SPACING,
                ) + jitter * (0.3 * SPACING / 3f64.sqrt());
            }
        }
        let thickness = vec![SPACING; solver.particles().len()];
        (solver, x, thickness)
    }

    /// The whole list (`pairs` and `extra`), sorted by (a, b); asserts no pair is listed twice.
    fn whole(sc: &SelfCollision) -> PairList {
        // The keys of the extra pairs are exactly its pairs.
        let keys: FxHashSet<u64> = (0..sc.extra.len())
            .map(|k| pair_key(sc.extra.a[k], sc.extra.b[k]))
            .collect();
        assert_eq!(keys, sc.in_extra, "the extra pairs' keys are not its pairs");
        let mut all: Vec<(u32, u32, f64)> = sc
            .pairs
            .iter()
            .chain([&sc.extra])
            .flat_map(|l| (0..l.len()).map(move |k| (l.a[k], l.b[k], l.target[k])))
            .collect();
        all.sort_by_key(|&(a, b, _)| (a, b));
        assert!(
            all.windows(2).all(|w| (w[0].0, w[0].1) < (w[1].0, w[1].1)),
            "a pair is listed twice"
        );
        let mut out = PairList::default();
        for (a, b, t) in all {
            out.push(a, b, t);
        }
        out
    }

    /// Pairs listed by `sc` that touch at `x`.
    fn listed_contacts(sc: &SelfCollision, x: &[DVec3]) -> Vec<(u32, u32)> {
        let PairList { a, b, target } = whole(sc);
        (0..a.len())
            .filter(|&k| x[a[k] as usize].distance(x[b[k] as usize]) < target[k])
            .map(|k| (a[k], b[k]))
            .collect()
    }

    /// Every non-exempt pair closer than `within(target)` at `x`, by brute force over all pairs.
    fn brute_pairs(
        sc: &SelfCollision,
        x: &[DVec3],
        t: &[f64],
        within: impl Fn(f64) -> f64,
    ) -> Vec<(u32, u32)> {
        let n = x.len() as u32;
        let mut out = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                if let Some(target) = sc.target(a, b, t) {
                    if x[a as usize].distance(x[b as usize]) < within(target) {
                        out.push((a, b));
                    }
                }
            }
        }
        out
    }

    fn listed(sc: &SelfCollision) -> Vec<(u32, u32)> {
        let w = whole(sc);
        w.a.iter().copied().zip(w.b.iter().copied()).collect()
    }

    /// Asserts every non-exempt pair within t (1 + search margin) at `x` is listed, and that the
    /// touching pairs are exactly the brute-force ones.
    fn assert_complete(sc: &SelfCollision, x: &[DVec3], t: &[f64], when: &str) {
        let list = listed(sc);
        let guaranteed = SPACING;
        let missing: Vec<_> = brute_pairs(sc, x, t, |_| guaranteed)
            .into_iter()
            .filter(|p| list.binary_search(p).is_err())
            .collect();
        assert!(missing.is_empty(), "{when}: pairs missing: {missing:?}");
        assert_eq!(
            listed_contacts(sc, x),
            brute_pairs(sc, x, t, |target| target),
            "{when}: contacts"
        );
    }

    #[test]
    fn skin_list_holds_exactly_the_brute_force_contacts_until_a_half_skin_move() {
        let (solver, mut x, t) = folded();
        let params = SelfCollisionParams::default();
        let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
        sc.refresh(&mut x, &t, None);
        assert_eq!(sc.rebuilds(), 1);
        let contacts = listed_contacts(&sc, &x);
        assert!(contacts.len() > 200, "only {} contacts", contacts.len());
        // Whatever limit the list uses, moves up to it must keep every close pair listed.
        let limit = sc.limit(SPACING);
        assert!(limit > 0.0);
        assert_complete(&sc, &x, &t, "built");
        // Exactly the pairs within R at the build, no more.
        let list = listed(&sc);
        let radius = SPACING * (1.0 + params.search_margin);
        assert_eq!(list, brute_pairs(&sc, &x, &t, |_| radius * (1.0 + 1e-12)));

        // Adversarial moves within the skin: each particle heads for the nearest particle the
        // list does not pair it with; less their mean, scaled to just under half the skin.
        let x0 = x.clone();
        let mut moves: Vec<DVec3> = (0..x.len())
            .map(|a| {
                (0..x.len())
                    .filter(|&b| b != a && sc.target(a as u32, b as u32, &t).is_some())
                    .filter(|&b| {
                        list.binary_search(&(a.min(b) as u32, a.max(b) as u32))
                            .is_err()
                    })
                    .min_by(|&b, &c| x0[a].distance(x0[b]).total_cmp(&x0[a].distance(x0[c])))
                    .map_or(DVec3::ZERO, |b| (x0[b] - x0[a]).normalize())
            })
            .collect();
        let mean = moves.iter().sum::<DVec3>() / moves.len() as f64;
        let longest = moves
            .iter()
            .map(|m| (*m - mean).length())
            .fold(0.0, f64::max);
        for m in &mut moves {
            *m = (*m - mean) * (0.999 * limit / longest);
        }
        for (xi, (x0i, m)) in x.iter_mut().zip(x0.iter().zip(&moves)) {
            *xi = *x0i + *m;
        }
        sc.refresh(&mut x, &t, None);
        assert_eq!(
            (sc.rebuilds(), sc.updates()),
            (1, 0),
            "list changed although nothing moved half the skin"
        );
        assert_complete(&sc, &x, &t, "after the moves");
        // The moves did bring unlisted pairs closer than R: the skin was needed.
        let closer = brute_pairs(&sc, &x, &t, |_| radius);
        assert!(closer.iter().any(|p| list.binary_search(p).is_err()));
        // A sweep reports one contact per touching pair.
        let touching = listed_contacts(&sc, &x).len();
        let mut p = solver.particles().clone();
        (p.positions, p.prev_positions) = (x.clone(), x);
        assert_eq!(sc.solve(&mut p).0, touching);
    }

    #[test]
    fn movers_are_reanchored_the_whole_cloth_may_move_and_many_movers_rebuild() {
        let (solver, mut x, t) = folded();
        let params = SelfCollisionParams::default();
        let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
        let limit = 0.5 * params.search_margin * SPACING;
        sc.refresh(&mut x, &t, None);
        // The whole cloth carried 10 half-skins away: its list still holds.
        for xi in &mut x {
            *xi += DVec3::new(10.0 * limit, -3.0 * limit, 0.0);
        }
        sc.refresh(&mut x, &t, None);
        assert_eq!((sc.rebuilds(), sc.updates()), (1, 0), "carried");
        x[100].x += 0.99 * limit;
        sc.refresh(&mut x, &t, None);
        assert_eq!(
            (sc.rebuilds(), sc.updates()),
            (1, 0),
            "moved within the skin"
        );
        // Particles 200 and 201 jump onto particle 300 (far away at rest): new contacts.
        x[200] = x[300] + DVec3::new(0.0, 0.2 * SPACING, 0.0);
        x[201] = x[300] + DVec3::new(0.2 * SPACING, 0.0, 0.0);
        assert!(listed(&sc).binary_search(&(200, 300)).is_err());
        sc.refresh(&mut x, &t, None);
        assert_eq!((sc.rebuilds(), sc.updates()), (1, 1), "two movers");
        assert!(listed(&sc).binary_search(&(200, 300)).is_ok());
        assert!(listed(&sc).binary_search(&(201, 300)).is_ok());
        assert_complete(&sc, &x, &t, "after re-anchoring");
        // 200 jumps again (re-anchored a second time) and 202 for the first time: the grid of
        // re-anchored members, updated in place, holds each once at its anchor.
        x[200] = x[300] + DVec3::new(0.0, -0.2 * SPACING, 0.0);
        x[202] = x[300] + DVec3::new(-0.2 * SPACING, 0.0, 0.0);
        sc.refresh(&mut x, &t, None);
        assert_eq!((sc.rebuilds(), sc.updates()), (1, 2), "re-anchored again");
        assert_eq!(sc.reanchored.len(), 3);
        let mut fresh = CellGrid::new();
        fresh.build(&sc.built_at, &sc.reanchored, sc.grid.spacing());
        assert_eq!(sc.recent.entries(), fresh.entries());
        assert!(listed(&sc).binary_search(&(202, 300)).is_ok());
        assert_complete(&sc, &x, &t, "after re-anchoring again");
        // Everything shaken by half a skin: a full rebuild.
        let mut seed = 3;
        for xi in &mut x {
            *xi += DVec3::new(rand(&mut seed), rand(&mut seed), rand(&mut seed)) * (2.0 * limit);
        }
        sc.refresh(&mut x, &t, None);
        assert_eq!((sc.rebuilds(), sc.updates()), (2, 2), "shaken");
        assert_complete(&sc, &x, &t, "after the rebuild");
        // A thickness change drops the list.
        sc.invalidate();
        sc.refresh(&mut x, &t, None);
        assert_eq!(sc.rebuilds(), 3);
    }

    /// Self-collision alone, with the ground as a floor at one thickness.
    struct Hook {
        sc: SelfCollision,
        thickness: Vec<f64>,
        fresh: bool,
    }

    impl SubstepHook for Hook {
        fn begin_substep(&mut self, _: &SubstepContext, _: &Particles) {
            self.fresh = true;
        }

        fn project(&mut self, _: &SubstepContext, p: &mut Particles) -> usize {
            let clamp = std::mem::take(&mut self.fresh).then_some(Clamp {
                prev: &p.prev_positions,
                w: &p.inv_masses,
            });
            self.sc.refresh(&mut p.positions, &self.thickness, clamp);
            let (contacts, _) = self.sc.solve(p);
            for (x, t) in p.positions.iter_mut().zip(&self.thickness) {
                x.y = x.y.max(*t);
            }
            contacts
        }
    }

    /// The self-fold scenario, 90 frames, with `params`: final positions, rebuilds, partial
    /// updates and changes of skin.
    fn fold_with(params: SelfCollisionParams) -> (Vec<DVec3>, u64, u64, u64) {
        let (mut solver, _) = self_fold(Method::Xpbd, 10, 30).expect("scenario");
        let sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
        let thickness = vec![solver.cloths()[0].thickness; solver.particles().len()];
        let mut hook = Hook {
            sc,
            thickness,
            fresh: true,
        };
        for _ in 0..90 {
            solver.step_with(&mut hook).expect("step");
        }
        (
            solver.particles().positions.clone(),
            hook.sc.rebuilds(),
            hook.sc.updates(),
            hook.sc.skin.changes(),
        )
    }

    #[test]
    fn skin_list_folds_exactly_like_a_search_before_every_sweep() {
        // No skin: any motion at all rebuilds the list, i.e. a fresh search every sweep.
        let (every, sweeps, _, _) = fold_with(SelfCollisionParams {
            search_margin: 0.0,
            adaptive_margin: false,
            ..SelfCollisionParams::default()
        });
        assert_eq!(sweeps, 90 * 10, "a fresh search every sweep");
        // A fixed skin, and the adaptive one (the default), which must change along the way.
        let fixed = SelfCollisionParams {
            adaptive_margin: false,
            ..SelfCollisionParams::default()
        };
        for params in [fixed, SelfCollisionParams::default()] {
            let (skin, rebuilds, updates, changes) = fold_with(params);
            assert!(updates > 0, "no partial update was exercised");
            assert!(
                4 * rebuilds < 3 * sweeps,
                "{rebuilds} rebuilds in {sweeps} sweeps"
            );
            assert_eq!(
                changes > 0,
                params.adaptive_margin,
                "{changes} changes of skin"
            );
            let differ = every
                .iter()
                .zip(&skin)
                .filter(|(a, b)| a.to_array() != b.to_array())
                .count();
            assert_eq!(differ, 0, "{differ} particles differ");
        }
    }

    #[test]
    fn a_thinner_skin_keeps_every_pair_whose_anchors_are_within_its_radius_once() {
        let (solver, mut x, t) = folded();
        let params = SelfCollisionParams {
            adaptive_margin: false,
            ..SelfCollisionParams::default()
        };
        let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
        sc.refresh(&mut x, &t, None);
        let (r_old, r_new) = (sc.radius(SPACING), SPACING * (1.0 + STEPS[0]));
        // A pair the build listed between the two radii; its first particle moves past the
        // limit to within one thickness of the second, so it is re-anchored there: the thinner
        // skin must keep that pair, now from `extra`.
        let list = listed(&sc);
        let &(a, b) = list
            .iter()
            .find(|&&(a, b)| {
                let d = x[a as usize].distance(x[b as usize]);
                d > 1.1 * r_new && d <= r_old
            })
            .expect("a pair between the radii");
        let to_b = x[b as usize] - x[a as usize];
        x[a as usize] += to_b * (1.0 - 0.9 * SPACING / to_b.length());
        sc.refresh(&mut x, &t, None);
        assert_eq!((sc.rebuilds(), sc.updates()), (1, 1));
        let in_pairs = |sc: &SelfCollision| {
            sc.pairs
                .iter()
                .any(|l| (0..l.len()).any(|k| (l.a[k], l.b[k]) == (a, b)))
        };
        assert!(in_pairs(&sc));
        sc.skin = Skin::new(STEPS[0], false);
        sc.shrink();
        assert!(
            !in_pairs(&sc),
            "the build's test at the thinner radius drops it"
        );
        assert!(
            (0..sc.extra.len()).any(|k| (sc.extra.a[k], sc.extra.b[k]) == (a, b)),
            "its anchors keep it listed"
        );
        // Exactly the non-exempt pairs whose anchors are within the new radius, or whose
        // positions at the build were (`whole` asserts none is listed twice).
        let listed = listed(&sc);
        let anchors: Vec<DVec3> = (0..x.len())
            .map(|i| sc.built_at[sc.slot_of[i] as usize])
            .collect();
        let built: Vec<DVec3> = (0..x.len())
            .map(|i| sc.built_pos[sc.slot_of[i] as usize])
            .collect();
        let mut expected = brute_pairs(&sc, &anchors, &t, |_| r_new * (1.0 + 1e-12));
        expected.extend(brute_pairs(&sc, &built, &t, |_| r_new * (1.0 + 1e-12)));
        expected.sort_unstable();
        expected.dedup();
        assert_eq!(listed, expected);
        assert_complete(&sc, &x, &t, "after shrinking");
    }

    #[test]
    fn exempt_pairs_are_those_of_one_cloth_within_a_fold_length_at_rest() {
        // Two cloths with the same rest positions. Cells of 1 × 0.6 spacing: pairs one column
        // and two rows apart, 1.562 spacings, lie just within the fold length (1.571).
        let n = 12;
        let side = SPACING * (n - 1) as f64;
        let solver = sheets(2, n, (side, 0.6 * side));
        let rest = solver.particles().positions.clone();
        let count = rest.len();
        let t = vec![SPACING; count];
        // A skin of 1.1 thickness: R = 2.1 t reaches same-cloth pairs beyond the fold length
        // (2 t apart) and leaves none on its border.
        let params = SelfCollisionParams {
            search_margin: 1.1,
            adaptive_margin: false,
            ..SelfCollisionParams::default()
        };
        let mut sc = SelfCollision::new(&solver, &[0, 1], params).expect("self-collision");
        let cloth = |i: usize| i / (n * n);
        let mut shares_triangle = vec![false; count * count];
        for info in solver.cloths() {
            for tri in &info.triangles {
                for k in 0..3 {
                    let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                    shares_triangle[a * count + b] = true;
                    shares_triangle[b * count + a] = true;
                }
            }
        }
        let fold = std::f64::consts::FRAC_PI_2 * SPACING;
        let (mut exempt, mut kept_same) = (0, 0);
        for a in 0..count {
            for b in a + 1..count {
                let target = sc.target(a as u32, b as u32, &t);
                let rest_distance = rest[a].distance(rest[b]);
                if cloth(a) != cloth(b) {
                    assert_eq!(target, Some(SPACING), "two cloths' pair ({a}, {b})");
                } else if shares_triangle[a * count + b] || rest_distance < 0.999 * fold {
                    assert_eq!(target, None, "({a}, {b}), {rest_distance} m apart at rest");
                    exempt += 1;
                } else if rest_distance > 1.001 * fold {
                    assert_eq!(target, Some(SPACING), "({a}, {b})");
                    kept_same += 1;
                }
            }
        }
        assert!(
            exempt > 500 && kept_same > 10_000,
            "{exempt} exempt, {kept_same} kept"
        );
        // The list built with the cloths at their rest places: every pair of the two cloths
        // within R (the rest places coincide), and none of one cloth within the fold length.
        let mut x = rest.clone();
        sc.refresh(&mut x, &t, None);
        let radius = 2.1 * SPACING;
        let list = listed(&sc);
        assert_eq!(list, brute_pairs(&sc, &x, &t, |_| radius * (1.0 + 1e-12)));
        assert!(
            list.iter()
                .any(|&(a, b)| cloth(a as usize) == cloth(b as usize))
        );
        assert!(list.iter().any(|&(a, b)| a as usize + n * n == b as usize));
        assert!(
            list.iter()
                .all(|&(a, b)| cloth(a as usize) != cloth(b as usize)
                    || rest[a as usize].distance(rest[b as usize]) > fold)
        );
    }
}
