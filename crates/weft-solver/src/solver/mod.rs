//! The solver: one step loop shared by every method (the loop itself, fused and general, is
//! in `frame.rs`).
//!
//! Its modules:
//!
//! - `frame`: one frame of the step loop, fused or general, the same bits either way.
//! - `frame_springs`: the explicit mass-spring frame by stencil, one parallel pass a substep.

mod frame;
mod frame_springs;

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::DVec3;

use crate::awake::awake;
use crate::constraints::{ConstraintSet, Residual};
use crate::domains::{DomainStats, Domains};
use crate::driver::PinDriver;
use crate::error::{ParamError, SolverError};
use crate::forces::Forces;
use crate::hook::SubstepHook;
use crate::methods::SpringWork;
use crate::motion::KinematicPin;
use crate::params::{ClothParams, FamilyParams, GROUPS_PER_CLOTH, check_thickness};
use crate::particles::Particles;
use crate::settings::{Settings, within_bound};
use crate::stability::{StabilityBound, bound};
use weft_simd::SimdPath;

/// A cloth inside a solver: its particle range and its mesh in global particle indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Cloth {
    /// Name (unique names are the caller's business).
    pub name: String,
    /// Its particles in the solver's store.
    pub particles: Range<usize>,
    /// Triangles, in global particle indices.
    pub triangles: Vec<[u32; 3]>,
    /// Mesh edges (grid lines for grids), in global particle indices.
    pub edges: Vec<[u32; 2]>,
    /// Thickness (m): contacts keep particles this far from surfaces.
    pub thickness: f64,
    /// Grid resolution `(columns, rows)` when the cloth is a grid.
    pub grid: Option<(usize, usize)>,
}

/// What one frame did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Contacts reported by the hook in the last substep.
    pub contacts: usize,
    /// Conjugate-gradient iterations over the frame's substeps: implicit mass-spring's, and
    /// XPBD's bending or joint solves (see [`Solver::solves_jointly`]); 0 otherwise.
    pub cg_iterations: u32,
    /// The largest relative residual ‖b − A Δv‖/‖b‖ that implicit mass-spring's solves ended
    /// the frame's substeps at (at most `Settings::cg_tolerance` unless a solve hit
    /// `cg_max_iterations`); 0 under the other methods.
    pub cg_residual: f64,
}

/// A particle held by the user, dragged toward a target.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Grab {
    particle: usize,
    inv_mass: f64,
    from: DVec3,
    target: DVec3,
}

/// The cloth solver: particles, constraints, forces and the shared step loop.
#[derive(Clone, Debug)]
pub struct Solver {
    settings: Settings,
    forces: Forces,
    particles: Particles,
    cloths: Vec<Cloth>,
    all_triangles: Vec<[u32; 3]>,
    /// Each cloth's parameters as given.
    cloth_params: Vec<ClothParams>,
    /// Every cloth's parameter groups (see [`ClothParams::groups`]), as the constraints index
    /// them.
    params: Vec<FamilyParams>,
    constraints: ConstraintSet,
    pins: Vec<KinematicPin>,
    /// Driven pins: particles placed by a [`PinDriver`] at every substep's time.
    drivers: Vec<Arc<dyn PinDriver>>,
    /// Driven particles' velocities at the current substep's end (scratch).
    driven_velocities: Vec<(usize, DVec3)>,
    /// A driver's positions and velocities (scratch).
    driven: (Vec<DVec3>, Vec<DVec3>),
    grab: Option<Grab>,
    /// The distance constraints cut into domains (the parallel SIMD solve).
    domains: Domains,
    /// Pin and grab targets of the current substep (scratch).
    targets: Vec<(usize, DVec3)>,
    /// Pin and grab targets of every substep of a fused frame, worked out before it starts
    /// (scratch).
    frame_targets: Vec<Vec<(usize, DVec3)>>,
    accel: Vec<DVec3>,
    /// The spring methods' rows, warm start and scratch.
    spring_work: SpringWork,
    /// The explicit springs' stencil, when they form one (see `frame_springs.rs`).
    stencil: frame_springs::Stencil,
    time: f64,
    frame: u64,
    /// Raised by the caller to abandon the frame in progress (polled once per substep).
    stop: Option<Arc<AtomicBool>>,
    /// Stability bounds of each cloth and of the whole solver, computed when first asked for
    /// and cleared when parameters change.
    stability: std::sync::OnceLock<(Vec<StabilityBound>, StabilityBound)>,
    /// The particles as built (rest state), for the stability bounds.
    initial: Particles,
}

impl Solver {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn assemble(
        settings: Settings,
        forces: Forces,
        particles: Particles,
        cloths: Vec<Cloth>,
        cloth_params: Vec<ClothParams>,
        constraints: ConstraintSet,
        pins: Vec<KinematicPin>,
        scratch: Vec<DVec3>,
    ) -> Self {
        let all_triangles = cloths
            .iter()
            .flat_map(|c| c.triangles.iter().copied())
            .collect();
        let domains = Domains::new(
            &constraints.distance,
            particles.len(),
            settings.domain_size,
            SimdPath::resolve(settings.simd),
        );
        Self {
            settings,
            forces,
            domains,
            targets: Vec::new(),
            frame_targets: Vec::new(),
            initial: particles.clone(),
            particles,
            cloths,
            all_triangles,
            params: crate::params::expand(&cloth_params, settings.iterations),
            cloth_params,
            constraints,
            pins,
            drivers: Vec::new(),
            driven_velocities: Vec::new(),
            driven: (Vec::new(), Vec::new()),
            grab: None,
            accel: scratch,
            spring_work: SpringWork::default(),
            stencil: frame_springs::Stencil::default(),
            time: 0.0,
            frame: 0,
            stop: None,
            stability: std::sync::OnceLock::new(),
        }
    }

    /// A flag polled once per substep: once raised, the frame in progress stops at the next
    /// substep and [`Solver::step_with`] returns [`SolverError::Interrupted`]. The solver never
    /// lowers it; what raises it (a signal, a button) is the caller's business.
    pub fn set_stop(&mut self, flag: Arc<AtomicBool>) {
        self.stop = Some(flag);
    }

    /// Whether the stop flag is raised.
    fn stopping(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// The particle store (read-only: only the step loop and its hook move particles).
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// Mutable particle store, for tools that set up states (e.g. initial velocities).
    pub fn particles_mut(&mut self) -> &mut Particles {
        &mut self.particles
    }

    /// The cloths.
    pub fn cloths(&self) -> &[Cloth] {
        &self.cloths
    }

    /// The particle pairs each seam joins (global indices): once sewn, the two sides of a
    /// seam are one vertex of the cloth.
    pub fn seam_pairs(&self) -> &[[u32; 2]] {
        &self.constraints.seams.particles
    }

    /// The index of the cloth called `name`.
    pub fn cloth_index(&self, name: &str) -> Option<usize> {
        self.cloths.iter().position(|c| c.name == name)
    }

    /// The constraint set.
    pub fn constraints(&self) -> &ConstraintSet {
        &self.constraints
    }

    /// The kernel path the constraint sweep runs on (see [`Settings::simd`]).
    pub fn simd_path(&self) -> SimdPath {
        self.domains.path()
    }

    /// How the distance constraints are cut into domains and SIMD chunks.
    pub fn domain_stats(&self) -> DomainStats {
        self.domains.stats()
    }

    /// Whether the last frame swept the isometric bending forward only (every hinge soft per
    /// substep, α/h² ≥ Σ w|∇C|²) rather than forward and backward.
    pub fn bending_forward_only(&self) -> bool {
        self.constraints.isometric_forward
    }

    /// Current settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Changes settings (method, time step, substeps, iterations) from the next frame on.
    pub fn set_settings(&mut self, settings: Settings) -> Result<(), ParamError> {
        settings.validate()?;
        if settings.domain_size != self.settings.domain_size {
            self.domains = Domains::new(
                &self.constraints.distance,
                self.particles.len(),
                settings.domain_size,
                SimdPath::resolve(settings.simd),
            );
        } else if settings.simd != self.settings.simd {
            self.domains.set_path(SimdPath::resolve(settings.simd));
        }
        if settings.method.is_explicit() != self.settings.method.is_explicit() {
            // Only an explicit method's bound estimates the highest mode.
            self.stability = std::sync::OnceLock::new();
        }
        let iterations_changed = settings.iterations != self.settings.iterations;
        self.settings = settings;
        if iterations_changed {
            // PBD's stiffness across the grain depends on the iteration count.
            self.params = crate::params::expand(&self.cloth_params, settings.iterations);
        }
        Ok(())
    }

    /// Current forces.
    pub fn forces(&self) -> &Forces {
        &self.forces
    }

    /// Changes forces from the next frame on.
    pub fn set_forces(&mut self, forces: Forces) -> Result<(), ParamError> {
        forces.validate()?;
        self.forces = forces;
        Ok(())
    }

    /// The family parameters of cloth `cloth`, if it exists.
    pub fn cloth_params(&self, cloth: usize) -> Option<ClothParams> {
        self.cloth_params.get(cloth).copied()
    }

    fn check_cloth(&self, cloth: usize) -> Result<(), ParamError> {
        if cloth < self.cloths.len() {
            Ok(())
        } else {
            Err(ParamError {
                name: "cloth".into(),
                value: cloth as f64,
                expected: "an existing cloth index",
            })
        }
    }

    /// Changes the family parameters of cloth `cloth` from the next frame on.
    pub fn set_cloth_params(
        &mut self,
        cloth: usize,
        params: ClothParams,
    ) -> Result<(), ParamError> {
        self.check_cloth(cloth)?;
        params.validate()?;
        let base = cloth * GROUPS_PER_CLOTH;
        self.params[base..base + GROUPS_PER_CLOTH]
            .copy_from_slice(&params.groups(self.settings.iterations));
        self.cloth_params[cloth] = params;
        self.stability = std::sync::OnceLock::new();
        Ok(())
    }

    /// Changes the thickness of cloth `cloth`.
    pub fn set_thickness(&mut self, cloth: usize, thickness: f64) -> Result<(), ParamError> {
        self.check_cloth(cloth)?;
        check_thickness(thickness)?;
        self.cloths[cloth].thickness = thickness;
        Ok(())
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Frames stepped so far.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The explicit-spring stability bound of cloth `cloth` (see [`StabilityBound`]),
    /// linearised at its rest state with the current spring parameters; it limits the substep
    /// of [`Method::MassSpring`](crate::Method::MassSpring) only. Under another method the
    /// highest mode is not estimated (150 passes over the constraints, seconds on a 1024²
    /// cloth): its fields repeat Gershgorin's bound, which is sure.
    pub fn stability(&self, cloth: usize) -> Option<StabilityBound> {
        self.stability_all().0.get(cloth).copied()
    }

    /// Every cloth's bound and the whole solver's, computed once per parameter change.
    fn stability_all(&self) -> &(Vec<StabilityBound>, StabilityBound) {
        self.stability.get_or_init(|| {
            let mode = self.settings.method.is_explicit();
            let of = |range: Range<usize>| {
                bound(
                    &self.constraints,
                    &self.initial.positions,
                    &self.initial.inv_masses,
                    &self.params,
                    range,
                    mode,
                )
            };
            let cloths: Vec<StabilityBound> = self
                .cloths
                .iter()
                .map(|c| of(c.particles.clone()))
                .collect();
            // Every constraint lies within one cloth, so the springs' matrix is one block per
            // cloth: its row sums and highest mode are the cloths' largest.
            let whole = (cloths.iter()).fold(StabilityBound::default(), |a, b| StabilityBound {
                omega: a.omega.max(b.omega),
                gamma: a.gamma.max(b.gamma),
                mode_omega: a.mode_omega.max(b.mode_omega),
                mode_gamma: if b.mode_omega > a.mode_omega {
                    b.mode_gamma
                } else {
                    a.mode_gamma
                },
            });
            (cloths, whole)
        })
    }

    /// |C| over the distance-like constraints at the current positions (m).
    pub fn residual(&self) -> Residual {
        self.constraints
            .distance_residual(&self.particles.positions)
    }

    /// How far XPBD's last substep left the bending hinges from their equation, relative to
    /// their compliance term (‖C + α̃ λ + γ ∇C·Δx‖ / ‖α̃ λ‖; 0 converged, 1 a hinge acting
    /// about twice as soft as its compliance); `None` under the other methods or without a
    /// bent hinge.
    pub fn bending_residual(&self) -> Option<f64> {
        let p = &self.particles;
        (self.constraints).bending_residual(&p.positions, &p.prev_positions, &self.params)
    }

    /// The distance between the two vertices of every seam pair (m), in the order they were
    /// added (see [`crate::SolverBuilder::add_seams`]).
    pub fn seam_gaps(&self) -> Vec<f64> {
        self.constraints.seam_gaps(&self.particles.positions)
    }

    /// Holds particle `i` (inverse mass 0) where it is, until [`Solver::release`].
    pub fn grab(&mut self, i: usize) -> Result<(), SolverError> {
        if i >= self.particles.len() {
            return Err(SolverError::NoSuchParticle {
                index: i,
                count: self.particles.len(),
            });
        }
        self.release();
        let x = self.particles.positions[i];
        self.grab = Some(Grab {
            particle: i,
            inv_mass: self.particles.inv_masses[i],
            from: x,
            target: x,
        });
        self.particles.inv_masses[i] = 0.0;
        Ok(())
    }

    /// Moves the held particle toward `target` over the next frame's substeps.
    pub fn drag_to(&mut self, target: DVec3) {
        if let Some(g) = &mut self.grab
            && target.is_finite()
        {
            g.target = target;
        }
    }

    /// The held particle and its target, if any.
    pub fn grabbed(&self) -> Option<(usize, DVec3)> {
        self.grab.map(|g| (g.particle, g.target))
    }

    /// Lets the held particle go: its mass comes back and it keeps its drag velocity.
    pub fn release(&mut self) {
        if let Some(g) = self.grab.take() {
            self.particles.inv_masses[g.particle] = g.inv_mass;
        }
    }

    /// Adds driven pins: `driver`'s particles get inverse mass 0 and are placed, from now on, at
    /// the driver's positions and velocities for the current time and then, in every substep,
    /// for the substep's end time (after the prediction, before the hook's
    /// [`SubstepHook::begin_substep`]; see [`crate::driver`]). Returns the driver's index.
    ///
    /// Fails, changing nothing, if a particle does not exist or appears twice.
    pub fn add_pin_driver(&mut self, driver: Arc<dyn PinDriver>) -> Result<usize, SolverError> {
        let count = self.particles.len();
        let mut seen = vec![false; count];
        for &i in driver.particles() {
            let i = i as usize;
            if i >= count {
                return Err(SolverError::NoSuchParticle { index: i, count });
            }
            if std::mem::replace(&mut seen[i], true) {
                return Err(SolverError::DrivenTwice { particle: i });
            }
        }
        let n = driver.particles().len();
        let (mut x, mut v) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        driver.drive(self.time, &mut x, &mut v);
        let p = &mut self.particles;
        for (k, &i) in driver.particles().iter().enumerate() {
            let i = i as usize;
            p.inv_masses[i] = 0.0;
            p.positions[i] = x[k];
            p.prev_positions[i] = x[k];
            p.velocities[i] = v[k];
        }
        self.drivers.push(driver);
        Ok(self.drivers.len() - 1)
    }

    /// The pin drivers, in the order they were added.
    pub fn pin_drivers(&self) -> &[Arc<dyn PinDriver>] {
        &self.drivers
    }

    /// Advances one frame of Δt with no hook.
    pub fn step(&mut self) -> Result<StepStats, SolverError> {
        self.step_with(&mut ())
    }

    /// Advances one frame of Δt: `substeps` substeps of the shared loop, calling `hook` inside.
    ///
    /// When nothing needs the particle store between the phases of a substep (no active hook, or
    /// one whose contacts are per particle ([`SubstepHook::particle_contacts`]), no
    /// aerodynamics, only distance constraints, a position-based method), the frame runs fused:
    /// each domain integrates, pins and projects its own particles, on a team of threads kept
    /// for the whole frame that hands each pass over with a spin, and resolves its particles'
    /// contacts in one parallel region per iteration. That path does the same arithmetic in
    /// the same order as the general loop, so both give the same bits. The general loop runs
    /// with the pool's other workers spinning for work between its passes (`crate::awake`).
    ///
    /// The frame runs on one of rayon's threads (`rayon::scope`, inline when called from one):
    /// its parallel loops then start from inside the pool, and the calling thread is handed
    /// off to and woken once per frame, not once per loop (tens of µs each on a virtual core).
    pub fn step_with(&mut self, hook: &mut dyn SubstepHook) -> Result<StepStats, SolverError> {
        let s = self.settings;
        let strategy = s.method.strategy();
        let rule = strategy.rule(s.h());
        let springs = s.method.is_explicit() && !hook.is_active() && self.stencil_ready();
        let done = rayon::scope(|_| match rule {
            Some(rule)
                if self.fusable() && (!hook.is_active() || hook.particle_contacts().is_some()) =>
            {
                self.frame_fused(rule, hook)
            }
            None if springs => awake(|| self.frame_springs()),
            _ => awake(|| self.frame_general(hook)),
        });
        let frame::Frame {
            stats,
            whole,
            within,
        } = done;
        if !whole {
            // Stopped inside the frame: the state is part of a frame; time and frame stay.
            return Err(SolverError::Interrupted { frame: self.frame });
        }
        if let Some(g) = &mut self.grab {
            g.from = g.target;
        }
        self.time += s.dt;
        let frame = self.frame;
        self.frame += 1;
        if !within {
            self.check_divergence(frame)?;
        }
        Ok(stats)
    }

    /// Whether the last XPBD frame solved its distance and bending constraints together by
    /// conjugate gradients (bending stiff per substep on a system of at most
    /// 20,000 rows; see `constraints/quad_cg.rs`) rather than sweeping the distances.
    pub fn solves_jointly(&self) -> bool {
        self.constraints.solves_jointly()
    }

    /// Whether a frame of this solver runs fused (integration, sweep and contacts inside the
    /// domains' parallel regions) when its hook allows it; false when a constraint family or
    /// force that only the general loop handles is present (dihedral, isometric, tethers,
    /// seams, aerodynamics).
    pub fn runs_fused(&self) -> bool {
        self.fusable()
    }

    /// Whether an explicit mass-spring frame of this solver takes its spring forces by
    /// stencil, in f32 lanes inside one parallel pass per substep, when no hook is at work:
    /// [`Solver::runs_fused`]'s conditions, on springs that join each particle to the ones a
    /// few fixed index offsets away (a grid; see `frame_springs.rs`).
    pub fn runs_springs_by_stencil(&mut self) -> bool {
        self.stencil_ready()
    }

    /// Whether a frame can run fused (see [`Solver::step_with`]).
    fn fusable(&self) -> bool {
        self.forces.wind.aero.is_none()
            && self.constraints.dihedral.len() == 0
            && self.constraints.isometric.len() == 0
            && self.constraints.tethers.len() == 0
            && self.constraints.seams.len() == 0
    }

    fn check_divergence(&self, frame: u64) -> Result<(), SolverError> {
        let bound = self.settings.divergence_bound;
        match self
            .particles
            .positions
            .iter()
            .position(|&x| !within_bound(x, bound))
        {
            Some(particle) => Err(SolverError::Diverged {
                method: self.settings.method,
                frame,
                particle,
                position: self.particles.positions[particle],
                bound,
                h: self.settings.h(),
                stability: self.stability_all().1,
            }),
            None => Ok(()),
        }
    }
}
