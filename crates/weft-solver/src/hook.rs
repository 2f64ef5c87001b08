//! The seam through which collisions (or anything else) act inside each substep.

use glam::DVec3;

use crate::method::Method;
use crate::particles::Particles;
use weft_simd::SimdPath;

/// Where in the step loop a hook is being called.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubstepContext {
    /// The running method.
    pub method: Method,
    /// Simulated time at the end of this substep (s).
    pub time: f64,
    /// Substep length h (s).
    pub h: f64,
    /// Substep number inside the frame, from 0.
    pub substep: u32,
    /// Simulated time at the end of the frame (s): the last substep's `time`, to the bit.
    pub frame_end: f64,
}

/// Acts on the particles inside every substep; the collision crate implements it.
///
/// Order in one substep: integrate (predict) → kinematic pins, driven pins
/// ([`crate::PinDriver`], evaluated at the substep's end time) and the grabbed particle placed
/// → [`SubstepHook::begin_substep`] → for each iteration: project constraints, then
/// [`SubstepHook::project`] → velocities from positions (driven pins: the driver's velocities)
/// → [`SubstepHook::end_substep`]. Mass-spring projects no constraints but still calls `project`
/// once, so contacts are handled by projection for every method.
///
/// A hook is `Send`: the whole frame, hook calls included, runs on one of rayon's threads.
pub trait SubstepHook: Send {
    /// After prediction: find contact candidates for this substep.
    fn begin_substep(&mut self, _ctx: &SubstepContext, _particles: &Particles) {}

    /// After each constraint sweep: move particles out of obstacles; returns the contact count.
    fn project(&mut self, _ctx: &SubstepContext, _particles: &mut Particles) -> usize {
        0
    }

    /// After velocities are derived from positions (and the global damping applied):
    /// velocity-level corrections.
    fn end_substep(&mut self, _ctx: &SubstepContext, _particles: &mut Particles) {}

    /// Whether the hook reads particle velocities (in `begin_substep` or `project`) or does
    /// anything in `end_substep`. One that does not lets the general loop leave each substep's
    /// velocity update to the next substep's integration pass (one pass over the particles
    /// instead of two): in between, the velocities are the last update's, and `end_substep` is
    /// called only after the frame's last substep. The default says it does.
    fn uses_velocities(&self) -> bool {
        true
    }

    /// Whether the hook does anything; an inactive hook lets the solver fuse a substep's phases.
    fn is_active(&self) -> bool {
        true
    }

    /// The hook's [`SubstepHook::project`] as per-particle contacts, when that is all it does
    /// (analytic colliders: each particle moved on its own, by its own position and previous
    /// position), so the solver may keep a frame fused: per substep it calls
    /// [`SubstepHook::begin_substep`] (with the particle store as it was at the frame's start:
    /// the hook must not read it), then after every projection pass
    /// [`ParticleContacts::resolve`] on each free particle inside the domains, then
    /// [`SubstepHook::fused_pass`] with the pass's totals; it never calls `project` or
    /// `end_substep` (which must do nothing). Same arithmetic, same order per particle, so the
    /// same bits as the general loop. `None` (the default): the general loop.
    fn particle_contacts(&self) -> Option<&dyn ParticleContacts> {
        None
    }

    /// After a fused pass of [`SubstepHook::particle_contacts`] (`fresh`: the substep's
    /// first): the pass's totals; returns the contact count, as [`SubstepHook::project`] does.
    fn fused_pass(&mut self, _fresh: bool, totals: Contacts) -> usize {
        totals.contacts
    }
}

/// Contacts that each particle resolves on its own (see [`SubstepHook::particle_contacts`]).
pub trait ParticleContacts: Sync {
    /// Moves free particle `i` (global index) at `x` out of obstacles; `prev` is its position
    /// at the substep's start, `fresh` marks the substep's first pass.
    fn resolve(&self, i: usize, x: &mut DVec3, prev: DVec3, fresh: bool) -> Contacts;

    /// [`Self::resolve`] on every free particle of `run` (nonzero inverse mass), in order:
    /// one call through a trait object per run of particles; inside it `resolve` is called
    /// directly, so an implementation's per-particle work can inline.
    fn resolve_run(&self, mut run: ParticleRun<'_>, fresh: bool) -> Contacts {
        run.each_free(|i, x, prev| self.resolve(i, x, prev, fresh))
    }
}

/// Consecutive particles in struct-of-arrays form, for [`ParticleContacts::resolve_run`].
pub struct ParticleRun<'a> {
    /// Global index of the first particle.
    pub start: usize,
    /// Positions per axis, moved in place.
    pub x: [&'a mut [f64]; 3],
    /// Positions at the substep's start, per axis.
    pub prev: [&'a [f64]; 3],
    /// Inverse masses; a pinned particle (0) is left alone.
    pub w: &'a [f64],
    /// The kernel path the solver runs on (a hook's own vector loops may follow it).
    pub path: SimdPath,
}

impl ParticleRun<'_> {
    /// Calls `f(i, x, prev)` on every free particle of the run in order (global index, position
    /// to move, position at the substep's start), stores the moved positions and merges what
    /// `f` returns. A run may be walked several times (one pass per collider, say).
    #[inline(always)]
    pub fn each_free(
        &mut self,
        mut f: impl FnMut(usize, &mut DVec3, DVec3) -> Contacts,
    ) -> Contacts {
        let ParticleRun {
            start, x, prev, w, ..
        } = self;
        let (start, prev, w) = (*start, *prev, *w);
        let mut total = Contacts::default();
        for (j, &wj) in w.iter().enumerate() {
            if wj == 0.0 {
                continue;
            }
            let mut p = DVec3::new(x[0][j], x[1][j], x[2][j]);
            let before = DVec3::new(prev[0][j], prev[1][j], prev[2][j]);
            total = total.merge(f(start + j, &mut p, before));
            for a in 0..3 {
                x[a][j] = p[a];
            }
        }
        total
    }
}

/// What per-particle contacts did: summed (counts) and maximised (depth) over particles.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Contacts {
    /// Contacts resolved.
    pub contacts: usize,
    /// Particles stopped by continuous (swept) collision.
    pub swept: usize,
    /// Deepest overlap (m).
    pub depth: f64,
}

impl Contacts {
    /// Both totals together (sums and maximum: independent of the order, so of the threads).
    pub fn merge(self, other: Self) -> Self {
        Self {
            contacts: self.contacts + other.contacts,
            swept: self.swept + other.swept,
            depth: self.depth.max(other.depth),
        }
    }
}

/// No hook: nothing but the cloth's own constraints.
impl SubstepHook for () {
    fn is_active(&self) -> bool {
        false
    }
}
