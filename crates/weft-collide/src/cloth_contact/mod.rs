//! Mesh-level cloth contact: vertex–triangle and edge–edge proximity within the cloths'
//! thickness, for every member cloth against itself and every other, inside each substep, with
//! a guarantee that no substep creates a crossing.
//!
//! Unlike particle–particle self-collision (`self_collision`), which keeps particles a
//! thickness apart and so holds only while no particle can slip between its neighbours (a
//! thickness near the particle spacing), contact here is between the surfaces: a vertex is
//! kept a thickness from every triangle and an edge from every edge they share no vertex with,
//! whatever the mesh spacing. Only pairs sharing a vertex are exempt; a pair of one cloth
//! whose rest distance is below the thickness keeps that rest distance instead (a thick
//! cloth's neighbours are not pushed apart).
//!
//! Each substep: the [`broad`] phase's Verlet list holds every pair that can touch (kept while
//! the particles stay within their skin, rebuilt otherwise); after each constraint sweep the
//! [`proximity`] contacts push close pairs apart with friction; after the substep's
//! velocities, the [`failsafe`] checks every listed pair over the substep's linear motion and
//! freezes impact zones at their start, so that no pair of elements touches during the
//! substep: a cloth that started without crossings has none at the substep's end (see
//! [`failsafe`] for what prescribed motion can still force). [`topology`] lists the elements,
//! [`geometry`] holds the closest-point queries. [`grid`] is the broad phase's uniform grid of element
//! boxes.
//!
//! Every part is parallel over pairs and sums in the list's order: same bits on any thread
//! count.
//!
//! The grid of `broad` and the segment distance of `geometry` resemble those of
//! `crate::crossings` on purpose: that module judges contact in the tests, so it shares no
//! code with it.

mod broad;
mod failsafe;
mod geometry;
mod grid;
mod proximity;
mod topology;

use weft_solver::{Particles, Solver};

use crate::error::CollideError;
use crate::friction::Friction;
use broad::{Candidates, Pair, Rule};
pub use failsafe::FailSafeStats;
use proximity::Sweep;
use topology::Elements;

/// Cloth contact settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClothContactParams {
    /// Coulomb friction between touching layers.
    pub friction: Friction,
    /// The fraction of a pair's distance its elements may not come within during a substep
    /// (η₀ of the continuous check) before the fail-safe freezes them; in (0, 1).
    pub impact_fraction: f64,
    /// The Verlet list's skin as a multiple of the largest thickness: larger keeps the list
    /// through more motion at the cost of more listed pairs. Changes only the cost.
    pub skin: f64,
    /// Jacobi sweeps of proximity contacts per projection (the later ones only while the first
    /// found contacts): two let a pressed stack settle in fewer substeps; at least one.
    pub passes: u32,
}

impl Default for ClothContactParams {
    fn default() -> Self {
        Self {
            friction: Friction::new(0.3, 0.2),
            impact_fraction: 0.1,
            skin: 2.0,
            passes: 2,
        }
    }
}

impl ClothContactParams {
    /// Checks the values make sense.
    pub fn validate(&self) -> Result<(), CollideError> {
        self.friction.validate()?;
        for (name, value, ok) in [
            (
                "cloth_contact.impact_fraction",
                self.impact_fraction,
                self.impact_fraction > 0.0 && self.impact_fraction < 1.0,
            ),
            (
                "cloth_contact.skin",
                self.skin,
                self.skin.is_finite() && self.skin > 0.0,
            ),
        ] {
            if !ok {
                return Err(CollideError::InvalidParameter {
                    name,
                    value,
                    expected: if name.ends_with("skin") {
                        "finite and > 0"
                    } else {
                        "in (0, 1)"
                    },
                });
            }
        }
        Ok(())
    }
}

/// What cloth contact did in the last substep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClothContactStats {
    /// Pairs closer than their distance in the last projection.
    pub contacts: usize,
    /// The deepest of them below their distance this substep (m).
    pub depth: f64,
    /// Pairs listed (vertex–triangle and edge–edge).
    pub listed: usize,
    /// Lists built from scratch so far.
    pub builds: u64,
    /// Lists refreshed so far (only the pairs of the few particles that left their boxes
    /// searched again).
    pub refreshes: u64,
    /// The continuous check's findings.
    pub fail_safe: FailSafeStats,
    /// Forced pairs ([`FailSafeStats::forced`]) summed over every substep so far.
    pub forced_so_far: u64,
}

/// Cloth contact state: the elements, the Verlet list and the scratch of each part.
#[derive(Clone, Debug)]
pub(crate) struct ClothContact {
    params: ClothContactParams,
    el: Elements,
    list: Candidates,
    sweep: Sweep,
    frozen: Vec<bool>,
    thickness: Vec<f64>,
    reach: f64,
    stats: ClothContactStats,
}

impl ClothContact {
    /// Contact among `cloths` of `solver` (each particle `thickness[i]` thick); rest state =
    /// the solver's current positions.
    pub(crate) fn new(
        solver: &Solver,
        cloths: &[usize],
        params: ClothContactParams,
        thickness: &[f64],
    ) -> Result<Self, CollideError> {
        params.validate()?;
        let params = ClothContactParams {
            passes: params.passes.max(1),
            ..params
        };
        let mut c = Self {
            params,
            el: Elements::new(solver, cloths)?,
            list: Candidates::default(),
            sweep: Sweep::default(),
            frozen: Vec::new(),
            thickness: Vec::new(),
            reach: 0.0,
            stats: ClothContactStats::default(),
        };
        c.set_thickness(thickness);
        Ok(c)
    }

    /// Takes new per-particle thicknesses (the list is rebuilt at the next check).
    pub(crate) fn set_thickness(&mut self, thickness: &[f64]) {
        self.thickness = thickness.to_vec();
        self.reach = (self.el.vertices.iter())
            .map(|&i| thickness[i as usize])
            .fold(0.0, f64::max);
        self.list.invalidate();
    }

    /// The last substep's statistics.
    pub(crate) fn stats(&self) -> ClothContactStats {
        self.stats
    }

    /// Makes sure the list holds every pair that can touch on the paths `prev → x`.
    fn check(&mut self, p: &Particles) {
        let (el, thickness) = (&self.el, &self.thickness);
        let target = |pair: Pair| {
            let (a, b, rest) = match pair {
                Pair::VertexFace(v, f) => {
                    let t = el.triangles[f as usize];
                    let r = |i: u32| el.rest[i as usize];
                    let d = geometry::point_triangle_distance(r(v), [r(t[0]), r(t[1]), r(t[2])]);
                    (v, t[0], d)
                }
                Pair::EdgeEdge(e, g) => {
                    let ([a0, a1], [b0, b1]) = (el.edges[e as usize], el.edges[g as usize]);
                    let r = |i: u32| el.rest[i as usize];
                    (
                        a0,
                        b0,
                        geometry::segment_distance(r(a0), r(a1), r(b0), r(b1)),
                    )
                }
            };
            let t = 0.5 * (thickness[a as usize] + thickness[b as usize]);
            if el.cloth[a as usize] == el.cloth[b as usize] {
                t.min(rest)
            } else {
                t
            }
        };
        let rule = Rule {
            reach: self.reach,
            skin: self.params.skin * self.reach.max(1e-6),
            keep: target,
        };
        (self.list).check(el, &p.prev_positions, &p.positions, &rule);
        self.stats.builds = self.list.builds;
        self.stats.refreshes = self.list.refreshes;
        self.stats.listed = self.list.vf.len() + self.list.ee.len();
    }

    /// After prediction: the list for the predicted paths.
    pub(crate) fn begin_substep(&mut self, p: &Particles) {
        self.stats.contacts = 0;
        self.stats.depth = 0.0;
        self.stats.fail_safe = FailSafeStats::default();
        self.check(p);
    }

    /// Before the colliders' contacts of a projection: where each particle is, so that
    /// [`Self::project`] can weigh those the colliders move.
    pub(crate) fn before_colliders(&mut self, p: &Particles) {
        self.sweep.remember(p);
    }

    /// One sweep of proximity contacts; returns the contact count and the deepest overlap.
    pub(crate) fn project(&mut self, p: &mut Particles) -> (usize, f64) {
        self.check(p);
        self.sweep.weigh(p);
        self.list.measure_at(&p.positions);
        let mut s = self
            .sweep
            .run(&self.el, &self.list, p, self.params.friction);
        for _ in 1..self.params.passes {
            if s.contacts == 0 {
                break;
            }
            self.list.measure_at(&p.positions);
            let more = self
                .sweep
                .run(&self.el, &self.list, p, self.params.friction);
            s.depth = s.depth.max(more.depth);
        }
        self.stats.contacts = s.contacts;
        self.stats.depth = self.stats.depth.max(s.depth);
        (s.contacts, s.depth)
    }

    /// After the substep's velocities: the continuous check and its fail-safe.
    pub(crate) fn end_substep(&mut self, p: &mut Particles) {
        // Measures the list along the substep's paths for the fail-safe's bounds.
        self.check(p);
        let eta = self.params.impact_fraction;
        self.stats.fail_safe = failsafe::enforce(&self.el, &self.list, p, eta, &mut self.frozen);
        self.stats.forced_so_far += self.stats.fail_safe.forced as u64;
    }
}
