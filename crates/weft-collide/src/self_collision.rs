//! Particle–particle self-collision (and collision between cloths) with friction.
//!
//! Each particle is a sphere of radius thickness / 2, so two particles are kept a thickness
//! apart (Müller, "Ten Minute Physics" #11; Macklin et al. 2014, §5 for particle contacts).
//! Pairs that share a triangle are left to the cloth's own constraints, and pairs that were
//! closer than a thickness at rest are only kept at their rest distance. Candidate pairs come
//! from a [`SpatialHash`] rebuilt every substep; they are solved Gauss–Seidel in a fixed order,
//! so results do not depend on thread count or hashing order.

use glam::DVec3;
use weft_solver::{Particles, Solver};

use crate::error::CollideError;
use crate::friction::Friction;
use crate::spatial_hash::SpatialHash;

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

/// A candidate pair and the distance it must keep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pair {
    a: u32,
    b: u32,
    target: f64,
}

/// Self-collision state: member particles, rest data, hash and this substep's pairs.
#[derive(Clone, Debug)]
pub(crate) struct SelfCollision {
    params: SelfCollisionParams,
    /// Participating particles, ascending.
    members: Vec<u32>,
    /// Rest positions (global index; only members are meaningful).
    rest: Vec<DVec3>,
    /// Cloth of each particle (global index).
    cloth: Vec<u32>,
    /// CSR: particles sharing a triangle with particle `i` are
    /// `adjacency[offsets[i]..offsets[i + 1]]`, sorted.
    offsets: Vec<u32>,
    adjacency: Vec<u32>,
    hash: SpatialHash,
    pairs: Vec<Pair>,
    scratch: Vec<u32>,
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
            rest: solver.particles().positions.clone(),
            cloth,
            offsets,
            adjacency,
            hash: SpatialHash::new(1.0),
            pairs: Vec::new(),
            scratch: Vec::new(),
        })
    }

    /// Whether `a` and `b` share a triangle.
    pub(crate) fn adjacent(&self, a: u32, b: u32) -> bool {
        let (s, e) = (self.offsets[a as usize], self.offsets[a as usize + 1]);
        self.adjacency[s as usize..e as usize]
            .binary_search(&b)
            .is_ok()
    }

    /// The distance pair `(a, b)` must keep, or `None` if it is exempt.
    pub(crate) fn target(&self, a: u32, b: u32, thickness: &[f64]) -> Option<f64> {
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

    /// Finds this substep's candidate pairs at the current positions.
    pub(crate) fn find_pairs(&mut self, positions: &[DVec3], thickness: &[f64]) {
        self.pairs.clear();
        let max_t = self
            .members
            .iter()
            .map(|&i| thickness[i as usize])
            .fold(0.0f64, f64::max);
        if max_t <= 0.0 {
            return;
        }
        let radius = max_t * (1.0 + self.params.search_margin);
        if self.hash.spacing() != radius {
            self.hash = SpatialHash::new(radius);
        }
        self.hash.build(positions, &self.members);
        let mut scratch = std::mem::take(&mut self.scratch);
        for &a in &self.members {
            let pa = positions[a as usize];
            self.hash.query(pa, radius, &mut scratch);
            for &b in scratch.iter().filter(|&&b| b > a) {
                if pa.distance_squared(positions[b as usize]) > radius * radius {
                    continue;
                }
                if let Some(target) = self.target(a, b, thickness) {
                    self.pairs.push(Pair { a, b, target });
                }
            }
        }
        self.scratch = scratch;
    }

    /// Pushes touching pairs apart to their target distance, with friction; returns the
    /// number of contacts and the deepest overlap (m).
    pub(crate) fn solve(&self, p: &mut Particles) -> (usize, f64) {
        let mut contacts = 0;
        let mut deepest = 0.0f64;
        for pair in &self.pairs {
            let (a, b) = (pair.a as usize, pair.b as usize);
            let (wa, wb) = (p.inv_masses[a], p.inv_masses[b]);
            let w = wa + wb;
            if w == 0.0 {
                continue;
            }
            let delta = p.positions[a] - p.positions[b];
            let dist = delta.length();
            if dist >= pair.target || dist <= 1e-9 {
                continue;
            }
            let depth = pair.target - dist;
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
            contacts += 1;
            deepest = deepest.max(depth);
        }
        (contacts, deepest)
    }
}
