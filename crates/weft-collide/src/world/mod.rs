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
//!
//! Its modules:
//!
//! - `cloth`: turning mesh-level cloth contact on and off in a world, and what it did.
//! - `runs`: the contacts of a run of particles, as the solver's fused pass hands them over.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use glam::{DQuat, DVec3};
use rayon::prelude::*;
use weft_solver::{
    Contacts, ParticleContacts, ParticleRun, Particles, Solver, SubstepContext, SubstepHook,
};

use crate::analytic::WorldPose;
use crate::body::{BodyCollider, BodyPart, KinematicBody};
use crate::chunk::{CHUNK, moving_views};
use crate::closed_run::{Run, resolve_still, still_surface};
use crate::cloth_contact::ClothContact;
use crate::collider::{Collider, ColliderDesc};
use crate::error::{CollideError, ShapeError};
use crate::friction::Friction;
use crate::reach::{Bounds, Reach, Surface};
use crate::run_lists::RunLists;
use crate::self_collision::{Clamp, SelfCollision, SelfCollisionParams, SelfCollisionTimes};
use crate::trimesh::chunk_lists::ChunkLists;
use crate::trimesh::contact_grid::ContactGrid;
use crate::trimesh::deforming::MeshAnimation;
use crate::trimesh::frame::{MeshFrame, RunParticle};
use crate::trimesh::grid_contacts::GridParticles;
use crate::trimesh::grid_run::resolve_grid_run;

mod cloth;
mod runs;

/// What the last substep's contacts did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactStats {
    /// Particle–collider contacts (kinematic bodies included) resolved in the last projection.
    pub collider_contacts: usize,
    /// Particle–particle contacts resolved in the last projection.
    pub self_contacts: usize,
    /// Deepest particle–collider overlap with the thickness shell seen this substep (m).
    pub max_depth: f64,
    /// Deepest particle–particle overlap seen this substep (m).
    pub max_self_depth: f64,
    /// Particles stopped by continuous (swept) collision this substep.
    pub swept: usize,
    /// Particle–body contact planes found this substep (see [`CollisionWorld::add_body`]).
    pub body_planes: usize,
}

/// Colliders and self-collision for one solver; implements [`SubstepHook`].
#[derive(Clone, Debug)]
pub struct CollisionWorld {
    colliders: Vec<Collider>,
    /// Kinematic bodies (animated characters), each its own kind of collider.
    bodies: Vec<BodyCollider>,
    /// Simulated time at the end of the last substep (s).
    time: f64,
    thickness: Vec<f64>,
    self_collision: Option<SelfCollision>,
    /// Mesh-level cloth contact (`cloth_contact`), when on.
    cloth_contact: Option<ClothContact>,
    /// Per collider, its world AABB at the current pose grown by [`Self::search_margin`], or
    /// `None` if unbounded; refreshed every substep.
    bounds: Vec<Option<Bounds>>,
    /// Per collider, which particles it can touch at the current pose; refreshed every
    /// substep with `bounds`.
    reach: Vec<Reach>,
    /// Largest thickness of any particle (m).
    max_thickness: f64,
    fresh: bool,
    stats: ContactStats,
    /// Per chunk of [`CHUNK`] particles, the candidate lists of each triangle-mesh collider
    /// (the general loop's).
    mesh_lists: Vec<Vec<ChunkLists>>,
    /// The same per run of particles of the fused frame (one per solver domain).
    run_lists: RunLists,
    /// Per collider, the thickness its contact grid was last sought for, and for a still
    /// triangle mesh its grid (built at the first substep for the largest thickness) with the
    /// particles' state on the grid path (`None`: not a still mesh, or too large for a grid).
    mesh_grids: Vec<MeshGrid>,
    /// Triangle meshes go through parry's f32 queries, as before the f64 mesh path (kept
    /// for comparisons).
    parry_meshes: bool,
    /// The flag the self-collision's list build polls (see [`CollisionWorld::set_stop`]).
    stop: Option<Arc<AtomicBool>>,
}

/// Rounds of re-query per particle and collider (a push out of one face of a mesh may land in
/// another); one for the closed-form shapes ([`Collider::one_push_clears`]).
const ROUNDS: usize = 3;

impl CollisionWorld {
    /// An empty world for `solver`'s particles, with each cloth's thickness.
    pub fn new(solver: &Solver) -> Self {
        let mut world = Self {
            colliders: Vec::new(),
            bodies: Vec::new(),
            time: solver.time(),
            thickness: Vec::new(),
            self_collision: None,
            cloth_contact: None,
            bounds: Vec::new(),
            reach: Vec::new(),
            max_thickness: 0.0,
            fresh: true,
            stats: ContactStats::default(),
            mesh_lists: Vec::new(),
            run_lists: RunLists::default(),
            mesh_grids: Vec::new(),
            parry_meshes: false,
            stop: None,
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
        self.max_thickness = self.thickness.iter().copied().fold(0.0, f64::max);
        self.mesh_lists.clear();
        self.run_lists.clear();
        self.mesh_grids.clear();
        if let Some(sc) = &mut self.self_collision {
            sc.invalidate();
        }
        if let Some(cc) = &mut self.cloth_contact {
            cc.set_thickness(&self.thickness);
        }
    }

    /// Builds and adds a collider; returns its index.
    pub fn add_collider(&mut self, desc: &ColliderDesc) -> Result<usize, ShapeError> {
        self.push(Collider::new(desc)?)
    }

    /// Builds and adds a deforming triangle-mesh collider: `desc`'s mesh (its vertices the
    /// rest shape), whose vertices `animation` sets at every substep (see
    /// [`MeshAnimation`]); returns its index.
    pub fn add_deforming_mesh(
        &mut self,
        desc: &ColliderDesc,
        animation: Arc<dyn MeshAnimation>,
    ) -> Result<usize, ShapeError> {
        self.push(Collider::deforming(desc, animation)?)
    }

    /// Adds a kinematic body (an animated character's round cones, capsules and spheres):
    /// its parts are evaluated at every substep's start and end time, particles are swept
    /// against them in each part's moving frame and kept a thickness outside them, with
    /// `friction` against the surface's own motion. Returns the body's index.
    pub fn add_body(
        &mut self,
        body: Arc<dyn KinematicBody>,
        friction: Friction,
    ) -> Result<usize, ShapeError> {
        friction.validate()?;
        let parts = body.part_count();
        if parts > usize::from(u16::MAX) {
            return Err(ShapeError::InvalidParameter {
                name: "body parts",
                value: parts as f64,
                expected: "at most 65535",
            });
        }
        self.bodies
            .push(BodyCollider::new(body, friction, self.time));
        Ok(self.bodies.len() - 1)
    }

    /// Number of kinematic bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Body `body`'s parts at the end of the last substep (at the time it was added, before
    /// any), or `None` if there is no such body. For drawing and logging.
    pub fn body_parts(&self, body: usize) -> Option<&[BodyPart]> {
        self.bodies.get(body).map(BodyCollider::parts)
    }

    /// Body `body`'s friction, or `None` if there is no such body.
    pub fn body_friction(&self, body: usize) -> Option<Friction> {
        self.bodies.get(body).map(BodyCollider::friction)
    }

    fn push(&mut self, c: Collider) -> Result<usize, ShapeError> {
        self.colliders.push(c);
        self.bounds.push(None);
        self.reach.push(Reach::Box(None));
        self.mesh_lists.clear();
        self.run_lists.clear();
        Ok(self.colliders.len() - 1)
    }

    /// Sends triangle meshes through parry's f32 projection and ray casts (`true`), as Weft
    /// did before its own mesh contacts, or through those (`false`, the default). For
    /// side-by-side comparisons; deforming meshes need the default.
    pub fn set_parry_meshes(&mut self, on: bool) {
        self.parry_meshes = on;
        self.mesh_lists.clear();
        self.run_lists.clear();
        self.mesh_grids.clear();
    }

    /// Candidate lists built so far for triangle-mesh contacts (all mesh colliders).
    pub fn mesh_list_builds(&self) -> u64 {
        self.sum_over_lists(|l| l.builds)
    }

    /// `count` summed over every chunk of candidate lists, of the general loop and the fused
    /// frame's runs.
    fn sum_over_lists(&self, count: impl Fn(&ChunkLists) -> u64 + Copy) -> u64 {
        let chunks: u64 = (self.mesh_lists.iter())
            .flat_map(|chunk| chunk.iter().map(count))
            .sum();
        chunks + self.run_lists.sum(count)
    }

    /// Triangles now listed for triangle-mesh contacts, over all particles and mesh
    /// colliders.
    pub fn mesh_list_entries(&self) -> usize {
        let chunks: usize = (self.mesh_lists.iter())
            .flat_map(|chunk| chunk.iter().map(ChunkLists::entries))
            .sum();
        chunks + self.run_lists.sum(|l| l.entries() as u64) as usize
    }

    /// Whether collider `c` goes through the world's own mesh contacts.
    fn own_mesh(&self, c: &Collider) -> bool {
        c.mesh().is_some() && (!self.parry_meshes || c.is_deforming())
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
        let mut sc = SelfCollision::new(solver, cloths, params)?;
        if let Some(flag) = &self.stop {
            sc.set_stop(Arc::clone(flag));
        }
        self.self_collision = Some(sc);
        Ok(())
    }

    /// A flag polled inside the work that can take seconds in one substep (building the
    /// self-collision's candidate list for a large thickness): once raised, that work stops
    /// at once, leaving the frame in progress to be abandoned (as [`Solver::set_stop`]
    /// does at the next substep).
    pub fn set_stop(&mut self, flag: Arc<AtomicBool>) {
        if let Some(sc) = &mut self.self_collision {
            sc.set_stop(Arc::clone(&flag));
        }
        self.stop = Some(flag);
    }

    /// Turns self-collision off.
    pub fn disable_self_collision(&mut self) {
        self.self_collision = None;
    }

    /// The distance self-collision keeps particles `a` and `b` apart, `None` inside when the
    /// pair is exempt (one cloth, within π/2 thickness at rest), or `None` when
    /// self-collision is off.
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

    /// Wall-clock time spent in each part of self-collision since it was turned on, or `None`
    /// when it is off.
    pub fn self_collision_times(&self) -> Option<SelfCollisionTimes> {
        self.self_collision.as_ref().map(SelfCollision::times)
    }

    /// Per-particle thickness (m).
    pub fn thickness(&self) -> &[f64] {
        &self.thickness
    }

    /// Statistics of the last substep.
    pub fn stats(&self) -> ContactStats {
        self.stats
    }

    /// How far outside a collider's AABB a particle may be and still be tested against it:
    /// three thicknesses (contacts are sought within two), plus 0.1 mm for the f32 AABB.
    fn search_margin(&self) -> f64 {
        3.0 * self.max_thickness + 1e-4
    }

    /// Continuous collision for fast particles: a particle whose substep path crosses a
    /// collider's surface is stopped a thickness before it. In parallel over particles.
    fn sweep(&mut self, p: &mut Particles) {
        self.stats.swept = 0;
        if self.colliders.is_empty() {
            return;
        }
        let own: Vec<bool> = self.colliders.iter().map(|c| self.own_mesh(c)).collect();
        let parry = self.parry_meshes;
        let (colliders, bounds, thickness) = (&self.colliders, &self.bounds, &self.thickness);
        let (positions, prev, inv) = moving_views(p);
        // As `sweep_run`: eight particles' paths measured together, and only a block holding
        // a long path walked one by one.
        self.stats.swept += (positions.par_chunks_mut(CHUNK).enumerate())
            .map(|(k, xs)| {
                let base = k * CHUNK;
                let mut swept = 0;
                let mut j = 0;
                while j < xs.len() {
                    if j % BLOCK == 0 && j + BLOCK <= xs.len() {
                        let long = (j..j + BLOCK).fold(false, |any, m| {
                            let i = base + m;
                            let free = inv[i] != 0.0;
                            any | (free & !short_path(xs[m], prev[i], thickness[i]))
                        });
                        if !long {
                            j += BLOCK;
                            continue;
                        }
                    }
                    let i = base + j;
                    if inv[i] != 0.0 {
                        let own = |k: usize| own[k];
                        swept += sweep_one(
                            colliders,
                            bounds,
                            own,
                            parry,
                            prev[i],
                            &mut xs[j],
                            thickness[i],
                        );
                    }
                    j += 1;
                }
                swept
            })
            .sum::<usize>();
    }

    /// Builds the contact grid of every still triangle mesh of ours that has none for the
    /// largest thickness (a mesh too large for one keeps the per-particle lists).
    fn build_grids(&mut self) {
        if self.mesh_grids.len() != self.colliders.len() {
            self.mesh_grids = vec![(0.0, None); self.colliders.len()];
        }
        let (reach, n) = (self.max_thickness, self.thickness.len());
        for (k, c) in self.colliders.iter().enumerate() {
            let still_mesh = self.own_mesh(c) && !c.is_deforming();
            let (sought, grid) = &mut self.mesh_grids[k];
            if still_mesh && *sought < reach {
                *sought = reach;
                *grid = c
                    .mesh()
                    .and_then(|m| ContactGrid::new(m, reach))
                    .map(|g| (Arc::new(g), GridParticles::new(n)));
            }
        }
    }

    /// Collider `k`'s contact grid and its particles' state, if it has one.
    fn grid(&self, k: usize) -> Option<GridRef<'_>> {
        grid_at(&self.mesh_grids, k)
    }

    /// Pushes particles out of colliders to surface + thickness, with Coulomb friction. In
    /// parallel over fixed chunks of particles; each particle meets the colliders in their
    /// order. Triangle meshes go through each particle's candidate list (`trimesh/`), held
    /// per chunk, so the results do not depend on the thread count.
    fn resolve_colliders(&mut self, p: &mut Particles, fresh: bool) -> (usize, usize) {
        if self.colliders.is_empty() {
            return (0, 0);
        }
        let own: Vec<bool> = self.colliders.iter().map(|c| self.own_mesh(c)).collect();
        let meshes = own.iter().filter(|&&o| o).count();
        let chunks = p.len().div_ceil(CHUNK);
        if self.mesh_lists.len() != chunks
            || self.mesh_lists.first().is_some_and(|c| c.len() != meshes)
        {
            self.mesh_lists = (0..chunks)
                .map(|k| vec![ChunkLists::new(CHUNK.min(p.len() - k * CHUNK)); meshes])
                .collect();
        }
        let frames: Vec<Option<(MeshFrame<'_>, Option<GridRef<'_>>)>> = self
            .colliders
            .iter()
            .zip(&own)
            .enumerate()
            .map(|(k, (c, &own))| {
                let frame = mesh_frame(c, fresh).filter(|_| own)?;
                Some((frame, grid_at(&self.mesh_grids, k)))
            })
            .collect();
        let parry = self.parry_meshes;
        let (colliders, reach, thickness) = (&self.colliders, &self.reach, &self.thickness);
        let (positions, prev, inv) = moving_views(p);
        let (contacts, deepest, swept) = positions
            .par_chunks_mut(CHUNK)
            .zip(self.mesh_lists.par_iter_mut())
            .enumerate()
            .map(|(k, (xs, lists))| {
                lists.iter_mut().for_each(ChunkLists::tidy);
                let (mut contacts, mut deepest, mut swept) = (0, 0.0f64, 0);
                for (j, x) in xs.iter_mut().enumerate() {
                    let i = k * CHUNK + j;
                    if inv[i] == 0.0 {
                        continue;
                    }
                    let mut slot = 0;
                    for ((c, reach), frame) in colliders.iter().zip(reach).zip(&frames) {
                        if let Some((frame, grid)) = frame {
                            let o = match grid {
                                Some(grid) => {
                                    frame.resolve_in_grid(*grid, i, prev[i], x, thickness[i])
                                }
                                None => frame.resolve(RunParticle::new(
                                    &mut lists[slot],
                                    j,
                                    prev[i],
                                    x,
                                    thickness[i],
                                )),
                            };
                            slot += 1;
                            contacts += o.contacts;
                            deepest = deepest.max(o.depth);
                            swept += o.swept;
                        } else if reach.may_touch(*x, thickness[i]) {
                            // Cheap reject: out of the collider's reach.
                            let (n, depth) = resolve_one(c, parry, prev[i], x, thickness[i]);
                            contacts += n;
                            deepest = deepest.max(depth);
                        }
                    }
                }
                (contacts, deepest, swept)
            })
            .reduce(|| (0, 0.0, 0), |a, b| (a.0 + b.0, a.1.max(b.1), a.2 + b.2));
        self.stats.max_depth = self.stats.max_depth.max(deepest);
        (contacts, swept)
    }
}

/// Collider `k`'s contact grid and its particles' state in `grids`, if it has one.
fn grid_at(grids: &[MeshGrid], k: usize) -> Option<GridRef<'_>> {
    grids
        .get(k)
        .and_then(|(_, g)| g.as_ref())
        .map(|(grid, state)| (&**grid, state))
}

/// Triangle-mesh collider `c` as every particle sees it in this projection.
fn mesh_frame(c: &Collider, fresh: bool) -> Option<MeshFrame<'_>> {
    let geometry = c.mesh()?;
    let (pose, prev_pose, still) = c.poses64();
    let identity = |q: &WorldPose| q.translation == DVec3::ZERO && q.rotation == DQuat::IDENTITY;
    Some(MeshFrame {
        geometry,
        pose,
        prev_pose,
        identity: identity(pose) && identity(prev_pose),
        still,
        fresh,
        friction: c.friction(),
    })
}

/// A collider's contact-grid slot: the thickness a grid was last sought for, and the grid of a
/// still triangle mesh with its particles' state on the grid path.
type MeshGrid = (f64, Option<(Arc<ContactGrid>, GridParticles)>);

/// A still mesh's contact grid and its particles' state, as the grid path takes them.
type GridRef<'a> = (&'a ContactGrid, &'a GridParticles);

/// A triangle mesh of ours as a pass sees it, with its grid if it has one (else it keeps
/// candidate lists).
type MeshOf<'a> = (MeshFrame<'a>, Option<GridRef<'a>>);

/// How many of the meshes in `frames` keep candidate lists (have no grid).
fn listed(frames: &[Option<MeshOf<'_>>]) -> usize {
    frames.iter().flatten().filter(|(_, g)| g.is_none()).count()
}

/// Particles whose paths a sweep pass measures together before walking any one by one.
const BLOCK: usize = 8;

/// Sweeps one particle's substep path `from → x` against every collider; returns how many
/// stopped it. A path shorter than half the thickness (most) leaves here, inlined, before
/// `x`'s address is taken: the call's vector loads would wait on the caller's scalar stores.
#[inline(always)]
fn sweep_one(
    colliders: &[Collider],
    bounds: &[Option<Bounds>],
    own: impl Fn(usize) -> bool,
    parry: bool,
    from: DVec3,
    x: &mut DVec3,
    r: f64,
) -> usize {
    if short_path(*x, from, r) {
        return 0;
    }
    sweep_path(colliders, bounds, own, parry, from, x, r)
}

/// Whether the path `from → x` of a particle of thickness `r` is shorter than half the
/// thickness, so no sweep is due (false for a path that is not a number).
#[inline(always)]
fn short_path(x: DVec3, from: DVec3, r: f64) -> bool {
    let slow = 0.5 * r.max(1e-6);
    (x - from).length_squared() <= slow * slow
}

/// [`sweep_one`] for a path of half the thickness or longer.
fn sweep_path(
    colliders: &[Collider],
    bounds: &[Option<Bounds>],
    own: impl Fn(usize) -> bool,
    parry: bool,
    from: DVec3,
    x: &mut DVec3,
    r: f64,
) -> usize {
    let step = (*x - from).length();
    let mut swept = 0;
    for (k, (c, b)) in colliders.iter().zip(bounds).enumerate() {
        if own(k) {
            continue; // swept in its own contacts
        }
        // Cheap reject: a path whose box misses the collider's (grown) box cannot cross it.
        if let Some((lo, hi)) = b
            && (from.min(*x).cmpgt(*hi).any() || from.max(*x).cmplt(*lo).any())
        {
            continue;
        }
        // Only a path that starts outside the surface can tunnel through it.
        let outside = query(c, parry, from, step + r).is_none_or(|s| s.distance >= 0.0);
        if !outside {
            continue;
        }
        let hit = if parry && c.mesh().is_some() {
            c.parry_sweep(from, *x)
        } else {
            c.sweep(from, *x)
        };
        if let Some((toi, n)) = hit {
            let hit = from + (*x - from) * toi;
            *x = hit + n * r;
            swept += 1;
        }
    }
    swept
}

/// Pushes one particle out of one collider to surface + `r`, with friction against the
/// surface's motion; returns the contacts resolved and the deepest overlap.
pub(crate) fn resolve_one(
    c: &Collider,
    parry: bool,
    prev: DVec3,
    x: &mut DVec3,
    r: f64,
) -> (usize, f64) {
    let friction = c.friction();
    let (mut contacts, mut deepest) = (0, 0.0f64);
    // A closed-form shape reports any point inside it, so only a surface nearer than r can
    // overlap the shell (depth = r − distance > 0). A mesh reports points behind its surface
    // only within the search distance, so it searches 2r to catch particles pushed deep.
    let (rounds, reach) = if c.one_push_clears() {
        (1, r)
    } else {
        (ROUNDS, 2.0 * r)
    };
    for _ in 0..rounds {
        let Some(s) = query(c, parry, *x, reach) else {
            break;
        };
        let depth = r - s.distance;
        if depth <= 1e-6 * r.max(1e-3) {
            break;
        }
        *x += s.normal * depth;
        // Relative tangential displacement over the substep against the surface's own
        // motion there (Macklin et al. 2014, eq. 24).
        let rel = (*x - prev) - c.displacement_at(s.point);
        let tangential = rel - s.normal * s.normal.dot(rel);
        *x -= friction.correction(tangential, depth);
        contacts += 1;
        deepest = deepest.max(depth);
    }
    (contacts, deepest)
}

/// [`Collider::closest`], or parry's for a mesh when `parry` is set.
fn query(c: &Collider, parry: bool, x: DVec3, max_dist: f64) -> Option<crate::SurfacePoint> {
    if parry && c.mesh().is_some() {
        c.parry_closest(x, max_dist)
    } else {
        c.closest(x, max_dist)
    }
}

impl SubstepHook for CollisionWorld {
    /// Contacts read positions and previous positions alone; `end_substep` does nothing
    /// but cloth contact's continuous check, which must run after every substep.
    fn uses_velocities(&self) -> bool {
        self.cloth_contact.is_some()
    }

    /// A world with no collider and no self-collision does nothing, so the solver may fuse.
    fn is_active(&self) -> bool {
        !self.colliders.is_empty()
            || !self.bodies.is_empty()
            || self.self_collision.is_some()
            || self.cloth_contact.is_some()
    }

    fn begin_substep(&mut self, ctx: &SubstepContext, particles: &Particles) {
        if let Some(cc) = &mut self.cloth_contact {
            cc.begin_substep(particles);
        }
        self.build_grids();
        let t0 = ctx.time - ctx.h;
        let margin = self.search_margin();
        for ((c, b), reach) in (self.colliders.iter_mut())
            .zip(&mut self.bounds)
            .zip(&mut self.reach)
        {
            c.set_time_in_frame(t0, ctx.time, ctx.frame_end);
            *b = c.world_aabb(0.0).map(|a| {
                let m = DVec3::splat(margin);
                (a.mins.as_dvec3() - m, a.maxs.as_dvec3() + m)
            });
            *reach = Reach::of(c, *b);
        }
        let reach = 2.0 * self.max_thickness;
        for b in &mut self.bodies {
            b.set_time(t0, ctx.time, reach);
        }
        self.time = ctx.time;
        self.fresh = true;
        self.stats = ContactStats::default();
    }

    /// Closed-form colliders only (no mesh, no self-collision): each particle's sweep and
    /// push-out read that particle alone, so the solver may run them inside its domains.
    fn particle_contacts(&self) -> Option<&dyn ParticleContacts> {
        // Kinematic bodies run a pass of their own (`BodyCollider::contact`): a world with one
        // keeps the general loop.
        // Triangle meshes of ours join: on a contact grid the particle state is kept per
        // particle, and the others' lists per run (`RunLists`). Those through parry keep the
        // general loop.
        let per_particle = self.self_collision.is_none()
            && self.cloth_contact.is_none()
            && self.bodies.is_empty()
            && !self.colliders.is_empty()
            && (self.colliders.iter()).all(|c| c.mesh().is_none() || self.own_mesh(c));
        per_particle.then_some(self as &dyn ParticleContacts)
    }

    /// The statistics [`SubstepHook::project`] keeps, from a fused pass's totals.
    fn fused_pass(&mut self, fresh: bool, totals: Contacts) -> usize {
        if fresh {
            self.fresh = false;
            self.stats.swept = 0;
        }
        // A mesh sweeps the path since its last projection in every pass.
        self.stats.swept += totals.swept;
        self.stats.collider_contacts = totals.contacts;
        self.stats.self_contacts = 0;
        self.stats.max_depth = self.stats.max_depth.max(totals.depth);
        totals.contacts
    }

    fn project(&mut self, _ctx: &SubstepContext, particles: &mut Particles) -> usize {
        // Once per substep, before the first projection: the colliders' sweep, then the
        // self-collision's clamp (a move back along a swept path stays clear of colliders).
        // Bodies come last, in one pass per body: each particle's sweep (first projection
        // only), contact planes and projection.
        let fresh = std::mem::take(&mut self.fresh);
        if fresh {
            self.sweep(particles);
        }
        // Particle pairs first, colliders last: a stack of layers pressed together must not
        // end the substep pushed into the ground, while a slight overlap between layers is
        // harmless and corrected next time.
        let (self_contacts, self_depth) = match &mut self.self_collision {
            Some(sc) => {
                let clamp = fresh.then_some(Clamp {
                    prev: &particles.prev_positions,
                    w: &particles.inv_masses,
                });
                sc.refresh(&mut particles.positions, &self.thickness, clamp);
                sc.solve(particles)
            }
            None => (0, 0.0),
        };
        // Cloth contact weighs the particles the colliders move (see `cloth_contact`).
        if let Some(cc) = &mut self.cloth_contact {
            cc.before_colliders(particles);
        }
        let (mut collider_contacts, swept) = self.resolve_colliders(particles, fresh);
        for b in &mut self.bodies {
            let c = b.contact(particles, &self.thickness, fresh);
            collider_contacts += c.contacts;
            self.stats.max_depth = self.stats.max_depth.max(c.deepest);
            self.stats.swept += c.swept;
            if fresh {
                self.stats.body_planes += c.planes;
            }
        }
        // Cloth contact last: the layers' proximity has the last word in each projection (a
        // layer pushed slightly into a collider comes out at the next one), and the substep's
        // continuous check (`end_substep`) judges the result.
        let (self_contacts, self_depth) = match &mut self.cloth_contact {
            Some(cc) => {
                let (n, depth) = cc.project(particles);
                (self_contacts + n, self_depth.max(depth))
            }
            None => (self_contacts, self_depth),
        };
        self.stats.swept += swept;
        self.stats.collider_contacts = collider_contacts;
        self.stats.self_contacts = self_contacts;
        self.stats.max_self_depth = self.stats.max_self_depth.max(self_depth);
        collider_contacts + self_contacts
    }

    /// Cloth contact's continuous check over the substep's motion, and its fail-safe.
    fn end_substep(&mut self, _ctx: &SubstepContext, particles: &mut Particles) {
        if let Some(cc) = &mut self.cloth_contact {
            cc.end_substep(particles);
        }
    }
}
