//! Particle–particle self-collision (and collision between cloths) with friction.
//!
//! Each particle is a sphere of radius thickness / 2, so two particles are kept a thickness
//! apart (Müller, "Ten Minute Physics" #11; Macklin et al. 2014, §5 for particle contacts).
//! Pairs that share a triangle are left to the cloth's own constraints, and pairs that were
//! closer than a thickness at rest are only kept at their rest distance.
//!
//! Candidate pairs live in a Verlet ("skin") list (Verlet 1967; Allen & Tildesley, "Computer
//! Simulation of Liquids", §5.3): every non-exempt pair at most R = t (1 + search_margin) + s
//! apart when the list was built, t the largest member thickness and s the skin. The list is
//! reused while every member stays within s/2 of its anchor (up to a displacement common to
//! all), so that every pair within t (1 + search_margin) is always listed, as when pairs were
//! searched every substep; the few members that stray are re-anchored
//! and their new pairs added, and the list is rebuilt from a [`CellGrid`] (points sorted by
//! cell, swept once) when many do. [`SelfCollision::refresh`] says why no contact can be
//! missing. Pairs are solved Gauss–Seidel in (a, b) order, so results depend neither on
//! thread count nor on grid order, nor on when the list was rebuilt: a listed pair that is not
//! touching does nothing.

use glam::DVec3;
use weft_solver::{Particles, Solver};

use crate::error::CollideError;
use crate::friction::Friction;
use crate::spatial_hash::CellGrid;

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
    /// Extra search radius for candidate pairs, as a fraction of the thickness (contacts
    /// pushed inside the substep may bring new pairs this close).
    pub search_margin: f64,
}

impl Default for SelfCollisionParams {
    fn default() -> Self {
        Self {
            friction: Friction::new(0.3, 0.2),
            max_displacement: 0.45,
            search_margin: 0.5,
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

/// The skin s of the list, as a fraction of the thickness. The list holds the pairs within
/// R = t (1 + search_margin) + s, and a member may stray s/2 from its anchor (beyond the common
/// displacement) before it is re-anchored: two members within s/2 of their anchors are at
/// most s closer than their anchors, so every pair within t (1 + search_margin) now has anchors
/// within R and is listed. A larger skin means fewer re-anchorings and rebuilds but a longer
/// list to sweep; of 0.25, 0.5 and 1, 0.5 cost least overall in the 128² cost example
/// (`examples/self_collision_cost.rs`).
const SKIN: f64 = 0.5;

/// What decides each pair's treatment: cloths, rest positions and triangle adjacency.
#[derive(Clone, Debug)]
struct Exemptions {
    /// Rest positions (global index; only members are meaningful).
    rest: Vec<DVec3>,
    /// Cloth of each particle (global index).
    cloth: Vec<u32>,
    /// CSR: particles sharing a triangle with particle `i` are
    /// `adjacency[offsets[i]..offsets[i + 1]]`, sorted.
    offsets: Vec<u32>,
    adjacency: Vec<u32>,
}

impl Exemptions {
    /// Whether `a` and `b` share a triangle.
    fn adjacent(&self, a: u32, b: u32) -> bool {
        let (s, e) = (self.offsets[a as usize], self.offsets[a as usize + 1]);
        self.adjacency[s as usize..e as usize]
            .binary_search(&b)
            .is_ok()
    }

    /// The distance pair `(a, b)` must keep, or `None` if it is exempt.
    fn target(&self, a: u32, b: u32, thickness: &[f64]) -> Option<f64> {
        if self.adjacent(a, b) {
            return None;
        }
        let t = 0.5 * (thickness[a as usize] + thickness[b as usize]);
        if self.cloth[a as usize] == self.cloth[b as usize] {
            let rest = self.rest[a as usize].distance(self.rest[b as usize]);
            Some(t.min(rest))
        } else {
            Some(t)
        }
    }
}

/// Candidate pairs as struct-of-arrays, sorted by (a, b), a < b.
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

    /// Index of (a, b), or where it would go.
    fn position(&self, a: u32, b: u32) -> Result<usize, usize> {
        let (mut lo, mut hi) = (0, self.a.len());
        while lo < hi {
            let mid = (lo + hi) / 2;
            match (self.a[mid], self.b[mid]).cmp(&(a, b)) {
                std::cmp::Ordering::Less => lo = mid + 1,
                std::cmp::Ordering::Greater => hi = mid,
                std::cmp::Ordering::Equal => return Ok(mid),
            }
        }
        Err(lo)
    }

    /// Both lists in one, sorted (they share no pair), into `out`.
    fn merge_into(&self, other: &PairList, out: &mut PairList) {
        out.clear();
        let (mut i, mut j) = (0, 0);
        while i < self.a.len() || j < other.a.len() {
            let take_self = j == other.a.len()
                || (i < self.a.len() && (self.a[i], self.b[i]) < (other.a[j], other.b[j]));
            if take_self {
                out.push(self.a[i], self.b[i], self.target[i]);
                i += 1;
            } else {
                out.push(other.a[j], other.b[j], other.target[j]);
                j += 1;
            }
        }
    }
}

/// Self-collision state: member particles, rest data, and the Verlet list of candidate pairs.
#[derive(Clone, Debug)]
pub(crate) struct SelfCollision {
    params: SelfCollisionParams,
    /// Participating particles, ascending.
    members: Vec<u32>,
    exempt: Exemptions,
    grid: CellGrid,
    pairs: PairList,
    /// Each member's anchor x⁰ (member order): its position at the last full build, or, for
    /// a member re-anchored since, its position then less the common displacement.
    built_at: Vec<DVec3>,
    /// Members (slots) re-anchored since the last full build, and a flag per slot: their
    /// positions in `grid` are stale.
    reanchored: Vec<u32>,
    is_reanchored: Vec<bool>,
    /// Member slot of each particle (`u32::MAX` for non-members).
    slot_of: Vec<u32>,
    /// Pairs added for re-anchored members since the last full build (not in `pairs`), sorted.
    extra: PairList,
    /// Partial updates (re-anchoring a few members) so far.
    updates: u64,
    /// Scratch: members that moved past the limit; pairs found for them; pairs to add; the
    /// merged extra list.
    movers: Vec<u32>,
    new_pairs: Vec<(u32, u32)>,
    added: PairList,
    merged: PairList,
    /// Largest member thickness the list was built for; `None` when there is no list.
    built_for: Option<f64>,
    /// Lists built so far.
    rebuilds: u64,
    /// [`SKIN`], or another value in tests.
    skin: f64,
    /// Pairs whose treatment is not the default (keep the mean thickness): CSR over particles,
    /// `special[special_offsets[a]..special_offsets[a + 1]]` holds (b > a, target), sorted by
    /// b, with a negative target for exempt pairs. Built at the first list build after
    /// creation or a thickness change; `None` until then.
    special_offsets: Option<Vec<u32>>,
    special: Vec<(u32, f64)>,
    /// Build scratch: pairs as found, per-particle offsets, partners sorted by `a`.
    found: Vec<(u32, u32, ())>,
    counts: Vec<u32>,
    sorted: Vec<(u32, ())>,
}

/// Marks an exempt pair in [`SelfCollision::special`].
const EXEMPT: f64 = -1.0;

/// Counting sort of `(a, b, value)` by a, then by b within each a (a fixed order whatever
/// order the grid found them in): `out[offsets[a]..offsets[a + 1]]` is a's (b, value), and
/// `offsets` has `n + 1` entries.
fn sort_pairs<T: Copy + Default>(
    found: &[(u32, u32, T)],
    n: usize,
    offsets: &mut Vec<u32>,
    out: &mut Vec<(u32, T)>,
) {
    offsets.clear();
    offsets.resize(n + 1, 0);
    for &(a, _, _) in found {
        offsets[a as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    out.clear();
    out.resize(found.len(), (0, T::default()));
    for &(a, b, value) in found {
        let slot = &mut offsets[a as usize];
        out[*slot as usize] = (b, value);
        *slot += 1;
    }
    // offsets[a] is now a's end = a + 1's start: shift back to starts.
    for i in (1..=n).rev() {
        offsets[i] = offsets[i - 1];
    }
    offsets[0] = 0;
    for w in offsets.windows(2) {
        out[w[0] as usize..w[1] as usize].sort_unstable_by_key(|&(b, _)| b);
    }
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
        let mut neighbours: Vec<(u32, u32)> = Vec::new();
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
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    neighbours.extend([(a, b), (b, a)]);
                }
            }
        }
        members.sort_unstable();
        members.dedup();
        let mut slot_of = vec![u32::MAX; n];
        for (slot, &i) in members.iter().enumerate() {
            slot_of[i as usize] = slot as u32;
        }
        neighbours.sort_unstable();
        neighbours.dedup();
        let mut offsets = vec![0u32; n + 1];
        for &(a, _) in &neighbours {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let adjacency = neighbours.iter().map(|&(_, b)| b).collect();
        Ok(Self {
            params,
            members,
            exempt: Exemptions {
                rest: solver.particles().positions.clone(),
                cloth,
                offsets,
                adjacency,
            },
            grid: CellGrid::new(),
            pairs: PairList::default(),
            built_at: Vec::new(),
            reanchored: Vec::new(),
            is_reanchored: Vec::new(),
            slot_of,
            extra: PairList::default(),
            updates: 0,
            movers: Vec::new(),
            new_pairs: Vec::new(),
            added: PairList::default(),
            merged: PairList::default(),
            built_for: None,
            rebuilds: 0,
            skin: SKIN,
            special_offsets: None,
            special: Vec::new(),
            found: Vec::new(),
            counts: Vec::new(),
            sorted: Vec::new(),
        })
    }

    /// The distance pair `(a, b)` must keep, or `None` if it is exempt.
    pub(crate) fn target(&self, a: u32, b: u32, thickness: &[f64]) -> Option<f64> {
        self.exempt.target(a, b, thickness)
    }

    /// Lists built so far.
    pub(crate) fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// Partial updates (a few members re-anchored) so far.
    pub(crate) fn updates(&self) -> u64 {
        self.updates
    }

    /// Candidate pairs in the current list.
    pub(crate) fn pair_count(&self) -> usize {
        self.pairs.a.len() + self.extra.a.len()
    }

    /// Drops the list (thickness changed): the next [`SelfCollision::refresh`] rebuilds it.
    pub(crate) fn invalidate(&mut self) {
        self.built_for = None;
        self.special_offsets = None;
    }

    /// Finds the pairs whose treatment is not the default: those sharing a triangle (exempt)
    /// and those closer at rest than their mean thickness (kept at their rest distance), i.e.
    /// every pair for which [`Exemptions::target`] is not `Some(mean thickness)`.
    fn find_special(&mut self, thickness: &[f64], max_t: f64) -> Vec<u32> {
        let n = thickness.len();
        let exempt = &self.exempt;
        let mut found = Vec::new();
        for &a in &self.members {
            let (s, e) = (exempt.offsets[a as usize], exempt.offsets[a as usize + 1]);
            for &b in &exempt.adjacency[s as usize..e as usize] {
                if b > a {
                    found.push((a, b, EXEMPT));
                }
            }
        }
        // Closer at rest than the mean thickness ≤ max_t.
        self.grid.build(&exempt.rest, &self.members, max_t);
        self.grid.for_each_pair(max_t, |i, j| {
            let (a, b) = (i.min(j), i.max(j));
            let mean = 0.5 * (thickness[a as usize] + thickness[b as usize]);
            match exempt.target(a, b, thickness) {
                Some(target) if target != mean => found.push((a, b, target)),
                _ => {} // exempt pairs are in already; the others take the default
            }
        });
        let mut offsets = Vec::new();
        sort_pairs(&found, n, &mut offsets, &mut self.special);
        offsets
    }

    /// The list radius R for largest thickness `t` (m).
    fn radius(&self, t: f64) -> f64 {
        t * (1.0 + self.params.search_margin + self.skin)
    }

    /// How far a member may stray from its anchor for thickness `t` (m): half the skin.
    fn limit(&self, t: f64) -> f64 {
        0.5 * self.skin * t
    }

    /// Makes sure the list holds every pair that may touch at `positions`.
    ///
    /// Invariant: the list (`pairs` and `extra`) holds every non-exempt pair whose anchors are
    /// at most R = t (1 + m) + s apart (m the search margin, s the skin), |x⁰ₐ − x⁰ᵦ| ≤ R. With
    /// displacements Δᵢ = xᵢ − x⁰ᵢ and a common displacement c (their mean), a member is a
    /// mover if |Δᵢ − c| > s/2. Movers are re-anchored at x⁰ᵢ = xᵢ − c (so Δᵢ − c = 0) and
    /// their pairs within R of the new anchor added, which keeps the invariant; when there are
    /// many, the list is rebuilt. Then |Δᵢ − c| ≤ s/2 for every member, so |Δₐ − Δᵦ| ≤ s and,
    /// by the triangle inequality, |x⁰ₐ − x⁰ᵦ| ≤ |xₐ − xᵦ| + s: every pair within t (1 + m) now
    /// is listed. Every target is at most t (the mean of two thicknesses, or less), so no
    /// contact is missing, with m t to spare for pairs pushed together within a sweep — the
    /// guarantee of a fresh search every sweep. c lets a cloth that falls or is carried as a
    /// whole keep its list. The check runs before every sweep, so it also catches moves
    /// between frames (pins, grabs, edits).
    pub(crate) fn refresh(&mut self, positions: &[DVec3], thickness: &[f64]) {
        let Some(t) = self.built_for else {
            return self.rebuild(positions, thickness);
        };
        if t <= 0.0 || self.members.is_empty() {
            return; // no thickness or no members: no pairs, whatever the motion
        }
        let limit = self.limit(t);
        let limit2 = limit * limit;
        let displacements = || {
            self.members
                .iter()
                .zip(&self.built_at)
                .map(|(&i, x0)| positions[i as usize] - *x0)
        };
        let (lo, hi, sum) = displacements().fold(
            (
                DVec3::splat(f64::INFINITY),
                DVec3::splat(f64::NEG_INFINITY),
                DVec3::ZERO,
            ),
            |(lo, hi, sum), d| (lo.min(d), hi.max(d), sum + d),
        );
        // Every |Δᵢ − box centre| is at most the box's half-diagonal: often that settles it.
        if (0.5 * (hi - lo)).length_squared() <= limit2 {
            return;
        }
        let c = sum / self.members.len() as f64;
        let cap = (self.members.len() / 64).max(64);
        self.movers.clear();
        for (slot, d) in displacements().enumerate() {
            if (d - c).length_squared() > limit2 {
                if self.movers.len() == cap {
                    return self.rebuild(positions, thickness);
                }
                self.movers.push(slot as u32);
            }
        }
        if !self.movers.is_empty() {
            self.reanchor(positions, thickness, c, t);
        }
    }

    /// Re-anchors `movers` at xᵢ − c and lists their pairs within R of the new anchors (see
    /// [`SelfCollision::refresh`]); rebuilds instead once many members have been re-anchored.
    fn reanchor(&mut self, positions: &[DVec3], thickness: &[f64], c: DVec3, t: f64) {
        for &m in &self.movers {
            let m = m as usize;
            self.built_at[m] = positions[self.members[m] as usize] - c;
            if !self.is_reanchored[m] {
                self.is_reanchored[m] = true;
                self.reanchored.push(m as u32);
            }
        }
        if self.reanchored.len() > (self.members.len() / 32).max(64) {
            return self.rebuild(positions, thickness);
        }
        self.updates += 1;
        let radius = self.radius(t);
        let r2 = radius * radius;
        let new_pairs = &mut self.new_pairs;
        new_pairs.clear();
        for &m in &self.movers {
            let (x0, id) = (self.built_at[m as usize], self.members[m as usize]);
            let pair = |j: u32| (id.min(j), id.max(j));
            // Members never re-anchored sit in the grid at their anchors.
            self.grid.for_each_near(x0, radius, |j| {
                if j != id && !self.is_reanchored[self.slot_of[j as usize] as usize] {
                    new_pairs.push(pair(j));
                }
            });
            for &r in &self.reanchored {
                if r != m && self.built_at[r as usize].distance_squared(x0) <= r2 {
                    new_pairs.push(pair(self.members[r as usize]));
                }
            }
        }
        new_pairs.sort_unstable();
        new_pairs.dedup();
        let special_offsets = self.special_offsets.as_deref().unwrap_or(&[]);
        let added = &mut self.added;
        added.clear();
        for &(a, b) in new_pairs.iter() {
            if self.pairs.position(a, b).is_ok() || self.extra.position(a, b).is_ok() {
                continue;
            }
            let (s, e) = (
                special_offsets[a as usize] as usize,
                special_offsets[a as usize + 1] as usize,
            );
            let special = &self.special[s..e];
            let target = match special.binary_search_by_key(&b, |&(sb, _)| sb) {
                Ok(k) => special[k].1,
                Err(_) => 0.5 * (thickness[a as usize] + thickness[b as usize]),
            };
            if target != EXEMPT {
                added.push(a, b, target);
            }
        }
        if !added.a.is_empty() {
            self.extra.merge_into(added, &mut self.merged);
            std::mem::swap(&mut self.extra, &mut self.merged);
        }
    }

    /// Builds the list at `positions`: pairs from the grid, their targets, sorted by (a, b).
    fn rebuild(&mut self, positions: &[DVec3], thickness: &[f64]) {
        self.rebuilds += 1;
        for &r in &self.reanchored {
            self.is_reanchored[r as usize] = false;
        }
        self.reanchored.clear();
        self.is_reanchored.resize(self.members.len(), false);
        self.extra.clear();
        self.built_at.clear();
        self.built_at
            .extend(self.members.iter().map(|&i| positions[i as usize]));
        let max_t = self
            .members
            .iter()
            .map(|&i| thickness[i as usize])
            .fold(0.0f64, f64::max);
        self.built_for = Some(max_t);
        self.pairs.clear();
        if max_t <= 0.0 {
            return;
        }
        if self.special_offsets.is_none() {
            self.special_offsets = Some(self.find_special(thickness, max_t));
        }
        let radius = self.radius(max_t);
        self.grid.build(positions, &self.members, radius);
        let found = &mut self.found;
        found.clear();
        self.grid
            .for_each_pair(radius, |i, j| found.push((i.min(j), i.max(j), ())));
        let n = positions.len();
        sort_pairs(found, n, &mut self.counts, &mut self.sorted);
        // Each a's partners and its special pairs are both sorted by b: merge them. The
        // result is what Exemptions::target gives, without its searches and square roots.
        let special_offsets = self.special_offsets.as_deref().unwrap_or(&[]);
        let pairs = &mut self.pairs;
        for a in 0..n {
            let (s, e) = (self.counts[a] as usize, self.counts[a + 1] as usize);
            if s == e {
                continue;
            }
            let (ss, se) = (special_offsets[a] as usize, special_offsets[a + 1] as usize);
            let special = &self.special[ss..se];
            let mut k = 0;
            for &(b, ()) in &self.sorted[s..e] {
                while k < special.len() && special[k].0 < b {
                    k += 1;
                }
                let target = match special.get(k) {
                    Some(&(sb, target)) if sb == b => target,
                    _ => 0.5 * (thickness[a] + thickness[b as usize]),
                };
                if target != EXEMPT {
                    pairs.a.push(a as u32);
                    pairs.b.push(b);
                    pairs.target.push(target);
                }
            }
        }
    }

    /// Limits each member's displacement this substep to `max_displacement` · thickness.
    pub(crate) fn clamp_displacements(&self, p: &mut Particles, thickness: &[f64]) {
        for &i in &self.members {
            let i = i as usize;
            if p.inv_masses[i] == 0.0 {
                continue;
            }
            let limit = self.params.max_displacement * thickness[i];
            let d = p.positions[i] - p.prev_positions[i];
            let len = d.length();
            if len > limit {
                p.positions[i] = p.prev_positions[i] + d * (limit / len);
            }
        }
    }

    /// Pushes touching pairs apart to their target distance, with friction; returns the
    /// number of contacts and the deepest overlap (m). Call [`SelfCollision::refresh`] first.
    pub(crate) fn solve(&self, p: &mut Particles) -> (usize, f64) {
        let mut acc = (0, 0.0f64);
        // `pairs` and `extra` in one (a, b) order: the order a full rebuild would give.
        let mut k = 0;
        for e in 0..self.extra.a.len() {
            let (a, b) = (self.extra.a[e], self.extra.b[e]);
            let end = self.pairs.position(a, b).unwrap_or_else(|i| i);
            self.solve_range(p, &self.pairs, k..end, &mut acc);
            self.solve_range(p, &self.extra, e..e + 1, &mut acc);
            k = end;
        }
        self.solve_range(p, &self.pairs, k..self.pairs.a.len(), &mut acc);
        acc
    }

    /// Solves `list[range]`, adding to (contacts, deepest).
    fn solve_range(
        &self,
        p: &mut Particles,
        list: &PairList,
        range: std::ops::Range<usize>,
        (contacts, deepest): &mut (usize, f64),
    ) {
        let (a, b, target) = (
            &list.a[range.clone()],
            &list.b[range.clone()],
            &list.target[range],
        );
        for ((&a, &b), &target) in a.iter().zip(b).zip(target) {
            let (a, b) = (a as usize, b as usize);
            let delta = p.positions[a] - p.positions[b];
            // Most listed pairs are not touching: rule them out before any square root.
            let dist2 = delta.length_squared();
            if dist2 >= target * target {
                continue;
            }
            let (wa, wb) = (p.inv_masses[a], p.inv_masses[b]);
            let w = wa + wb;
            if w == 0.0 {
                continue;
            }
            let dist = dist2.sqrt();
            if dist >= target || dist <= 1e-9 {
                continue;
            }
            let depth = target - dist;
            let n = delta / dist;
            // Distance constraint C = |xa − xb| − target ≥ 0, mass-weighted projection
            // (Müller et al. 2007, eq. 9–10).
            p.positions[a] += n * (depth * wa / w);
            p.positions[b] -= n * (depth * wb / w);
            // Friction on the relative tangential displacement over the substep.
            let rel =
                (p.positions[a] - p.prev_positions[a]) - (p.positions[b] - p.prev_positions[b]);
            let tangential = rel - n * n.dot(rel);
            let corr = self.params.friction.correction(tangential, depth);
            p.positions[a] -= corr * (wa / w);
            p.positions[b] += corr * (wb / w);
            *contacts += 1;
            *deepest = deepest.max(depth);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenarios::self_fold;
    use weft_solver::{
        ClothParams, Forces, GridDesc, Mass, Method, Orientation, Settings, SolverBuilder,
        SubstepContext, SubstepHook,
    };

    /// A deterministic pseudo-random number in [−1, 1) (64-bit LCG, Knuth's MMIX constants).
    fn rand(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    const N: usize = 24;
    const SPACING: f64 = 0.01;

    /// An N×N cloth of thickness = spacing (flat at rest), and positions accordion-folded in
    /// layers of 4 rows 0.9 thickness apart, every particle jittered by up to 0.3 thickness:
    /// a random folded configuration.
    fn folded() -> (Solver, Vec<DVec3>, Vec<f64>) {
        let mesh = GridDesc {
            resolution: (N, N),
            size: (SPACING * (N - 1) as f64, SPACING * (N - 1) as f64),
            center: DVec3::ZERO,
            orientation: Orientation::Horizontal,
            mass: Mass::Total(0.1),
            pins: vec![],
        }
        .build()
        .expect("grid");
        let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("builder");
        b.add_cloth("cloth", &mesh, ClothParams::default(), SPACING)
            .expect("cloth");
        let solver = b.build();
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

    /// The whole list (`pairs` and `extra`), in solve order.
    fn whole(sc: &SelfCollision) -> PairList {
        let mut out = PairList::default();
        sc.pairs.merge_into(&sc.extra, &mut out);
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
        assert!(list.windows(2).all(|w| w[0] < w[1]), "{when}: not sorted");
        let guaranteed = SPACING * (1.0 + sc.params.search_margin);
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
        sc.refresh(&x, &t);
        assert_eq!(sc.rebuilds(), 1);
        let contacts = listed_contacts(&sc, &x);
        assert!(contacts.len() > 200, "only {} contacts", contacts.len());
        // Whatever limit the list uses, moves up to it must keep every close pair listed.
        let limit = sc.limit(SPACING);
        assert!(limit > 0.0);
        assert_complete(&sc, &x, &t, "built");
        // Exactly the pairs within R at the build, no more.
        let list = listed(&sc);
        let radius = SPACING * (1.0 + params.search_margin + SKIN);
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
        sc.refresh(&x, &t);
        assert_eq!(
            (sc.rebuilds(), sc.updates()),
            (1, 0),
            "list changed although nothing moved half the skin"
        );
        assert_complete(&sc, &x, &t, "after the moves");
        // The moves did bring unlisted pairs closer than R: the skin was needed.
        let closer = brute_pairs(&sc, &x, &t, |_| radius);
        assert!(closer.iter().any(|p| list.binary_search(p).is_err()));
    }

    #[test]
    fn movers_are_reanchored_the_whole_cloth_may_move_and_many_movers_rebuild() {
        let (solver, mut x, t) = folded();
        let params = SelfCollisionParams::default();
        let mut sc = SelfCollision::new(&solver, &[0], params).expect("self-collision");
        let limit = 0.5 * SKIN * SPACING;
        sc.refresh(&x, &t);
        // The whole cloth carried 10 half-skins away: its list still holds.
        for xi in &mut x {
            *xi += DVec3::new(10.0 * limit, -3.0 * limit, 0.0);
        }
        sc.refresh(&x, &t);
        assert_eq!((sc.rebuilds(), sc.updates()), (1, 0), "carried");
        x[100].x += 0.99 * limit;
        sc.refresh(&x, &t);
        assert_eq!(
            (sc.rebuilds(), sc.updates()),
            (1, 0),
            "moved within the skin"
        );
        // Particles 200 and 201 jump onto particle 300 (far away at rest): new contacts.
        x[200] = x[300] + DVec3::new(0.0, 0.2 * SPACING, 0.0);
        x[201] = x[300] + DVec3::new(0.2 * SPACING, 0.0, 0.0);
        assert!(listed(&sc).binary_search(&(200, 300)).is_err());
        sc.refresh(&x, &t);
        assert_eq!((sc.rebuilds(), sc.updates()), (1, 1), "two movers");
        assert!(listed(&sc).binary_search(&(200, 300)).is_ok());
        assert!(listed(&sc).binary_search(&(201, 300)).is_ok());
        assert_complete(&sc, &x, &t, "after re-anchoring");
        // Everything shaken by half a skin: a full rebuild.
        let mut seed = 3;
        for xi in &mut x {
            *xi += DVec3::new(rand(&mut seed), rand(&mut seed), rand(&mut seed)) * (2.0 * limit);
        }
        sc.refresh(&x, &t);
        assert_eq!((sc.rebuilds(), sc.updates()), (2, 1), "shaken");
        assert_complete(&sc, &x, &t, "after the rebuild");
        // A thickness change drops the list.
        sc.invalidate();
        sc.refresh(&x, &t);
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
            if std::mem::take(&mut self.fresh) {
                self.sc.clamp_displacements(p, &self.thickness);
            }
            self.sc.refresh(&p.positions, &self.thickness);
            let (contacts, _) = self.sc.solve(p);
            for (x, t) in p.positions.iter_mut().zip(&self.thickness) {
                x.y = x.y.max(*t);
            }
            contacts
        }
    }

    fn fold_with(skin: f64) -> (Vec<DVec3>, u64, u64) {
        let (mut solver, _) = self_fold(Method::Xpbd, 10, 30).expect("scenario");
        let mut sc = SelfCollision::new(&solver, &[0], SelfCollisionParams::default())
            .expect("self-collision");
        sc.skin = skin;
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
        )
    }

    #[test]
    fn skin_list_folds_exactly_like_a_search_before_every_sweep() {
        // No skin: any motion at all rebuilds the list, i.e. a fresh search every sweep.
        let (every, sweeps, _) = fold_with(0.0);
        let (skin, rebuilds, updates) = fold_with(SKIN);
        assert!(updates > 0, "no partial update was exercised");
        assert_eq!(sweeps, 90 * 10, "a fresh search every sweep");
        assert!(
            4 * rebuilds < 3 * sweeps,
            "{rebuilds} rebuilds in {sweeps} sweeps"
        );
        let differ = every
            .iter()
            .zip(&skin)
            .filter(|(a, b)| a.to_array() != b.to_array())
            .count();
        assert_eq!(differ, 0, "{differ} particles differ");
    }
}
