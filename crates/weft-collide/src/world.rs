//! The collision world: colliders plus optional self-collision, run inside the solver's
//! substeps through [`SubstepHook`].
//!
//! Contacts are resolved by projection for every method, mass-spring included. An explicit
//! penalty force would need a stiffness of its own, and with explicit integration that
//! stiffness brings its own stability limit on the substep (ω h < 2 with ω = √(k/m)); a stiff
//! enough penalty to keep a falling cloth out of a sphere is easily past it. Projection has no
//! stiffness: it moves the particle to the surface, and the shared loop's velocity update
//! v = (x − x_prev) / h then removes the normal approach velocity, exactly as it does for XPBD
//! and PBD.

use weft_solver::{Particles, Solver, SubstepContext, SubstepHook};

use crate::collider::{Collider, ColliderDesc};
use crate::error::{CollideError, ShapeError};
use crate::self_collision::{SelfCollision, SelfCollisionParams};

/// What the last substep's contacts did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactStats {
    /// Particle–collider contacts resolved in the last projection.
    pub collider_contacts: usize,
    /// Particle–particle contacts resolved in the last projection.
    pub self_contacts: usize,
    /// Deepest particle–collider overlap with the thickness shell seen this substep (m).
    pub max_depth: f64,
    /// Deepest particle–particle overlap seen this substep (m).
    pub max_self_depth: f64,
    /// Particles stopped by continuous (swept) collision this substep.
    pub swept: usize,
}

/// Colliders and self-collision for one solver; implements [`SubstepHook`].
#[derive(Clone, Debug)]
pub struct CollisionWorld {
    colliders: Vec<Collider>,
    thickness: Vec<f64>,
    self_collision: Option<SelfCollision>,
    candidates: Vec<Vec<u32>>,
    fresh: bool,
    stats: ContactStats,
}

/// Rounds of re-query per particle and collider (a push out of one face may land in another).
const ROUNDS: usize = 3;

impl CollisionWorld {
    /// An empty world for `solver`'s particles, with each cloth's thickness.
    pub fn new(solver: &Solver) -> Self {
        let mut world = Self {
            colliders: Vec::new(),
            thickness: Vec::new(),
            self_collision: None,
            candidates: Vec::new(),
            fresh: true,
            stats: ContactStats::default(),
        };
        world.sync_thickness(solver);
        world
    }

    /// Re-reads every cloth's thickness from `solver` (after [`Solver::set_thickness`]).
    pub fn sync_thickness(&mut self, solver: &Solver) {
        self.thickness = vec![0.0; solver.particles().len()];
        for cloth in solver.cloths() {
            self.thickness[cloth.particles.clone()].fill(cloth.thickness);
        }
        if let Some(sc) = &mut self.self_collision {
            sc.invalidate();
        }
    }

    /// Builds and adds a collider; returns its index.
    pub fn add_collider(&mut self, desc: &ColliderDesc) -> Result<usize, ShapeError> {
        self.colliders.push(Collider::new(desc)?);
        self.candidates.push(Vec::new());
        Ok(self.colliders.len() - 1)
    }

    /// The colliders.
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// Turns on particle–particle collision among `cloths` (within and between them), taking
    /// the solver's current positions as the rest state.
    pub fn enable_self_collision(
        &mut self,
        solver: &Solver,
        cloths: &[usize],
        params: SelfCollisionParams,
    ) -> Result<(), CollideError> {
        self.self_collision = Some(SelfCollision::new(solver, cloths, params)?);
        Ok(())
    }

    /// Turns self-collision off.
    pub fn disable_self_collision(&mut self) {
        self.self_collision = None;
    }

    /// Whether particles `a` and `b` are exempt from self-collision (share a triangle), or
    /// `None` when self-collision is off.
    pub fn self_collision_target(&self, a: u32, b: u32) -> Option<Option<f64>> {
        self.self_collision
            .as_ref()
            .map(|s| s.target(a, b, &self.thickness))
    }

    /// Self-collision candidate lists: full builds and partial updates so far and the current
    /// list's length, or `None` when self-collision is off.
    pub fn self_collision_lists(&self) -> Option<(u64, u64, usize)> {
        self.self_collision
            .as_ref()
            .map(|s| (s.rebuilds(), s.updates(), s.pair_count()))
    }

    /// Per-particle thickness (m).
    pub fn thickness(&self) -> &[f64] {
        &self.thickness
    }

    /// Statistics of the last substep.
    pub fn stats(&self) -> ContactStats {
        self.stats
    }

    fn max_thickness(&self) -> f64 {
        self.thickness.iter().copied().fold(0.0, f64::max)
    }

    /// Once per substep, before the first projection: clamp, sweep, gather candidates.
    fn prepare(&mut self, p: &mut Particles) {
        if let Some(sc) = &self.self_collision {
            sc.clamp_displacements(p, &self.thickness);
        }
        self.sweep(p);
        // Broad phase: one AABB per collider grown by the search margin; inside a mesh
        // collider parry's BVH prunes triangles per query.
        let margin = 3.0 * self.max_thickness();
        for (collider, list) in self.colliders.iter().zip(&mut self.candidates) {
            list.clear();
            let aabb = collider.world_aabb(margin as f32);
            for (i, x) in p.positions.iter().enumerate() {
                if p.inv_masses[i] == 0.0 {
                    continue;
                }
                let inside = aabb.is_none_or(|a| {
                    x.cmpge(a.mins.as_dvec3()).all() && x.cmple(a.maxs.as_dvec3()).all()
                });
                if inside {
                    list.push(i as u32);
                }
            }
        }
    }

    /// Continuous collision for fast particles: a particle whose substep path crosses a
    /// collider's surface is stopped a thickness before it.
    fn sweep(&mut self, p: &mut Particles) {
        let mut swept = 0;
        for i in 0..p.len() {
            let r = self.thickness[i];
            let from = p.prev_positions[i];
            let to = p.positions[i];
            let step = (to - from).length();
            if p.inv_masses[i] == 0.0 || step <= 0.5 * r.max(1e-6) {
                continue;
            }
            for c in &self.colliders {
                // Only a path that starts outside the surface can tunnel through it.
                let outside = c.closest(from, step + r).is_none_or(|s| s.distance >= 0.0);
                if !outside {
                    continue;
                }
                if let Some((toi, n)) = c.sweep(from, p.positions[i]) {
                    let hit = from + (p.positions[i] - from) * toi;
                    p.positions[i] = hit + n * r;
                    swept += 1;
                }
            }
        }
        self.stats.swept = swept;
    }

    /// Pushes particles out of colliders to surface + thickness, with Coulomb friction.
    fn resolve_colliders(&mut self, p: &mut Particles) -> usize {
        let mut contacts = 0;
        let mut deepest = self.stats.max_depth;
        for (c, list) in self.colliders.iter().zip(&self.candidates) {
            let friction = c.friction();
            for &i in list {
                let i = i as usize;
                let r = self.thickness[i];
                let mut x = p.positions[i];
                for _ in 0..ROUNDS {
                    let Some(s) = c.closest(x, 2.0 * r) else {
                        break;
                    };
                    let depth = r - s.distance;
                    if depth <= 1e-6 * r.max(1e-3) {
                        break;
                    }
                    x += s.normal * depth;
                    // Relative tangential displacement over the substep against the surface's
                    // own motion there (Macklin et al. 2014, eq. 24).
                    let rel = (x - p.prev_positions[i]) - c.displacement_at(s.point);
                    let tangential = rel - s.normal * s.normal.dot(rel);
                    x -= friction.correction(tangential, depth);
                    contacts += 1;
                    deepest = deepest.max(depth);
                }
                p.positions[i] = x;
            }
        }
        self.stats.max_depth = deepest;
        contacts
    }
}

impl SubstepHook for CollisionWorld {
    /// A world with no collider and no self-collision does nothing, so the solver may fuse.
    fn is_active(&self) -> bool {
        !self.colliders.is_empty() || self.self_collision.is_some()
    }

    fn begin_substep(&mut self, ctx: &SubstepContext, _particles: &Particles) {
        let t0 = ctx.time - ctx.h;
        for c in &mut self.colliders {
            c.set_time(t0, ctx.time);
        }
        self.fresh = true;
        self.stats = ContactStats::default();
    }

    fn project(&mut self, _ctx: &SubstepContext, particles: &mut Particles) -> usize {
        if std::mem::take(&mut self.fresh) {
            self.prepare(particles);
        }
        // Particle pairs first, colliders last: a stack of layers pressed together must not
        // end the substep pushed into the ground, while a slight overlap between layers is
        // harmless and corrected next time.
        let (self_contacts, self_depth) = match &mut self.self_collision {
            Some(sc) => {
                sc.refresh(&particles.positions, &self.thickness);
                sc.solve(particles)
            }
            None => (0, 0.0),
        };
        let collider_contacts = self.resolve_colliders(particles);
        self.stats.collider_contacts = collider_contacts;
        self.stats.self_contacts = self_contacts;
        self.stats.max_self_depth = self.stats.max_self_depth.max(self_depth);
        collider_contacts + self_contacts
    }
}
