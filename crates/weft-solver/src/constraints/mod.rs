//! The constraint set: every cloth's constraints, coloured, in one block per shape.
//!
//! The module's parts:
//!
//! - `distance`: the distance constraint C = |p₀ − p₁| − d.
//! - `dihedral`: dihedral bending, C = θ − θ₀ across an interior edge.
//! - `isometric`: isometric bending, C = |Σᵢ kᵢ xᵢ| over an interior edge's four vertices.
//! - `tether`: long-range attachment, active only when stretched.
//! - `seam`: a seam whose rest length ramps to zero over a closing time, then holds.
//! - `block`: a coloured struct-of-arrays block of one shape and its projection.
//! - `linear`: springs linearised at the current state, for implicit mass-spring.
//! - `linear_rows`: the state a linearisation reads and the row sums it adds per particle.
//! - `lanes`: the distance projection over `L` lanes at once.
//! - `dihedral_lanes`: the dihedral projection over `L` lanes in explicit vectors.
//! - `isometric_lanes`: the isometric projection over `L` lanes in explicit vectors.
//! - `quad_lanes`: the four-particle shapes' lane kernels as one interface, with their frame
//!   constants.
//! - `quad_sweep`: the symmetric Gauss–Seidel sweep of a four-particle block through its lane
//!   kernel.
//! - `quad_cg`: XPBD's bending step, alone or with the distance constraints, by conjugate
//!   gradients where one sweep leaves it soft, and its residual.
//! - `spring_force`: spring forces by slots, each particle summing its own slots in order.
//! - `spring_stencil`: explicit distance springs on a grid as fixed index offsets, their
//!   forces in f32 lanes.
//! - `ray_stencil`: implicit distance springs on a grid by slot: their linearisation and
//!   products in f64 lanes; `ray_system`, the implicit system's rows and conjugate gradients
//!   in f64 lanes where they are all the springs.
//! - `parts`: contiguous particle ranges that let one colour be projected in parallel.

mod block;
mod dihedral;
mod dihedral_lanes;
mod distance;
mod isometric;
mod isometric_lanes;
pub(crate) mod lanes;
mod linear;
mod linear_rows;
#[cfg(test)]
pub(crate) use linear::tests as linear_tests;
mod parts;
mod quad_cg;
mod quad_lanes;
mod quad_sweep;
mod ray_stencil;
mod seam;
mod spring_force;
mod spring_stencil;
mod tether;

pub(crate) use block::{Block, BlockBuilder, Rule};
pub use dihedral::Dihedral;
pub use distance::Distance;
pub use isometric::Isometric;
pub(crate) use linear::Springs;
pub(crate) use linear_rows::{RowSums, State as LinearState};
pub(crate) use ray_stencil::SystemIo;
pub use seam::Seam;
pub(crate) use spring_stencil::{Mirror, Ring, SpringStencil, WIDEST};
pub use tether::Tether;

use glam::DVec3;

pub(crate) use quad_lanes::FrameConstants;

use crate::params::FamilyParams;
use weft_simd::SimdPath;

/// A constraint function C(p) over `N` particles with its gradient.
pub trait Shape<const N: usize>: Copy + Send + Sync {
    /// XPBD multipliers per constraint: 1 for a scalar C, 3 for a vector C (the isometric
    /// bending's, one per axis).
    const MULTIPLIERS: usize = 1;

    /// Returns C and ∇C at `p`, or `None` when the constraint is inactive or degenerate there.
    fn evaluate(&self, p: &[DVec3; N]) -> Option<(f64, [DVec3; N])>;

    /// The Hessian of C at `p` applied to `dp`, (∇²C) dp, where it has a closed form; zero
    /// otherwise (the implicit method then uses ∇C ∇Cᵀ alone).
    fn curvature_product(&self, _p: &[DVec3; N], _dp: &[DVec3; N]) -> [DVec3; N] {
        [DVec3::ZERO; N]
    }
}

/// C = |p₀ − p₁| − `rest` and its gradient (n, −n), n = (p₀ − p₁)/|p₀ − p₁| (Müller et al.
/// 2007, eq. 9); `None` below `min_len`, where the direction is undefined.
#[inline]
pub(crate) fn distance_evaluate(
    p: &[DVec3; 2],
    rest: f64,
    min_len: f64,
) -> Option<(f64, [DVec3; 2])> {
    let d = p[0] - p[1];
    let len = d.length();
    if len < min_len {
        return None;
    }
    let n = d / len;
    Some((len - rest, [n, -n]))
}

/// (∇²C) dp of a distance C = |p₀ − p₁| − d: with n = (p₀ − p₁)/|p₀ − p₁|, the block
/// ∂²C/∂p₀² = (I − n nᵀ)/|p₀ − p₁| and the others ± the same.
#[inline]
pub(crate) fn distance_curvature(p: &[DVec3; 2], dp: &[DVec3; 2]) -> [DVec3; 2] {
    let d = p[0] - p[1];
    let len = d.length();
    if len < 1e-9 {
        return [DVec3::ZERO; 2];
    }
    let n = d / len;
    let r = dp[0] - dp[1];
    let h = (r - n * n.dot(r)) / len;
    [h, -h]
}

/// Every constraint of a solver: distance-like pairs, dihedral and isometric bending
/// quadruples, tethers and seams.
#[derive(Clone, Debug, Default)]
pub struct ConstraintSet {
    /// Stretch, shear and bend-distance constraints.
    pub(crate) distance: Block<2, Distance>,
    /// Dihedral bending constraints.
    pub(crate) dihedral: Block<4, Dihedral>,
    /// Isometric bending constraints.
    pub(crate) isometric: Block<4, Isometric>,
    /// Long-range attachments.
    pub(crate) tethers: Block<2, Tether>,
    /// Seams being sewn or held closed; their group indexes `seam_params`.
    pub(crate) seams: Block<2, Seam>,
    /// Parameters of each set of seams (one per [`crate::SolverBuilder::add_seams`]).
    pub(crate) seam_params: Vec<FamilyParams>,
    /// Whether the isometric block is soft per substep this frame, so that its sweep runs
    /// forward only (see [`Block::project_symmetric_lanes`]).
    pub(crate) isometric_forward: bool,
    /// The isometric block's frame constants (see [`FrameConstants`]).
    pub(crate) isometric_constants: FrameConstants<isometric_lanes::Prepared>,
    /// The substep of the last XPBD frame (s); 0 before any.
    pub(crate) xpbd_h: f64,
    /// Which constraints XPBD solves by conjugate gradients this frame (see `quad_cg`).
    pub(crate) plan: quad_cg::Plan,
    /// The conjugate gradients' scratch, every block under its own id (`quad_cg::*_ROWS`).
    pub(crate) cg: quad_cg::CgScratch,
}

/// Max and root-mean-square of |C| over a set of constraints.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Residual {
    /// Largest |C|.
    pub max: f64,
    /// Root mean square of C.
    pub rms: f64,
    /// Number of constraints measured.
    pub count: usize,
}

impl ConstraintSet {
    /// Number of constraints of every shape.
    pub fn len(&self) -> usize {
        self.distance.len()
            + self.dihedral.len()
            + self.isometric.len()
            + self.tethers.len()
            + self.seams.len()
    }

    /// Whether there is no constraint.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of colours in each block (distance, dihedral, isometric, tether).
    pub fn color_counts(&self) -> [usize; 4] {
        [
            self.distance.color_count(),
            self.dihedral.color_count(),
            self.isometric.color_count(),
            self.tethers.color_count(),
        ]
    }

    /// Number of seam constraints.
    pub fn seam_count(&self) -> usize {
        self.seams.len()
    }

    /// Sets every seam's rest length for time `t` (s).
    pub(crate) fn set_seam_time(&mut self, t: f64) {
        for s in &mut self.seams.shapes {
            s.set_time(t);
        }
    }

    /// The distance between the two vertices of every seam pair (m), in the order the pairs
    /// were added.
    pub fn seam_gaps(&self, x: &[DVec3]) -> Vec<f64> {
        let mut out: Vec<(u32, f64)> = self
            .seams
            .particles
            .iter()
            .zip(&self.seams.order)
            .map(|(p, &k)| (k, x[p[0] as usize].distance(x[p[1] as usize])))
            .collect();
        out.sort_unstable_by_key(|&(k, _)| k);
        out.into_iter().map(|(_, d)| d).collect()
    }

    /// Decides, once per frame, how the bending blocks sweep under `rule` with inverse masses
    /// `w` and parameters `params`: the isometric block forward only when it is soft per
    /// substep ([`Block::soft_per_substep`]).
    ///
    /// Under XPBD, a bending block whose mean s/α̃ at `x` exceeds [`quad_cg::CG_ABOVE`] and
    /// that has at most [`quad_cg::CG_MAX_ROWS`] rows is solved by conjugate gradients instead
    /// of swept; where either block's exceeds [`quad_cg::JOINT_ABOVE`] and the whole system
    /// has at most [`quad_cg::JOINT_MAX_ROWS`] rows, both blocks are solved together with the
    /// distance constraints ([`quad_cg::Plan`]).
    pub(crate) fn prepare_sweeps(
        &mut self,
        x: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
    ) {
        self.xpbd_h = 0.0;
        self.plan = quad_cg::Plan::default();
        if let Rule::Xpbd { h } = rule {
            self.xpbd_h = h;
            let rows = [self.dihedral.len(), 3 * self.isometric.len()];
            let (dihedral, isometric) = (&self.dihedral, &self.isometric);
            self.plan = quad_cg::Plan::new(rows, self.distance.len(), |k| match k {
                0 => dihedral.mean_stiffness_ratio(x, w, params, h),
                _ => isometric.mean_stiffness_ratio(x, w, params, h),
            });
        }
        self.isometric_forward = self.isometric.soft_per_substep(w, params, rule);
        self.isometric
            .prepare_constants(&mut self.isometric_constants, w, params, rule);
    }

    /// How far the bending constraints are from XPBD's equation C + α̃ λ + γ ∇C·Δx = 0 with
    /// the last substep's multipliers: ‖C + α̃ λ + γ ∇C·Δx‖ / ‖α̃ λ‖ over every enabled hinge
    /// at `x` (previous positions `prev`), i.e. roughly how much softer than its compliance
    /// the bending acts (0 converged; `None` before an XPBD substep or without bending
    /// force).
    pub fn bending_residual(
        &self,
        x: &[DVec3],
        prev: &[DVec3],
        params: &[FamilyParams],
    ) -> Option<f64> {
        let h = self.xpbd_h;
        if h <= 0.0 {
            return None;
        }
        let d = self.dihedral.residual_sums(x, prev, params, h);
        let i = self.isometric.residual_sums(x, prev, params, h);
        let reference = d.reference + i.reference;
        (reference > 0.0).then(|| ((d.residual + i.residual) / reference).sqrt())
    }

    /// Clears the XPBD multipliers (at the start of each substep).
    pub(crate) fn reset_multipliers(&mut self) {
        // The sweep's distance multipliers live in `Domains`, which clears its own; these are
        // the joint solve's.
        if self.plan.joint {
            self.distance.reset_multipliers();
        }
        self.dihedral.reset_multipliers();
        self.isometric.reset_multipliers();
        self.tethers.reset_multipliers();
        self.seams.reset_multipliers();
    }

    /// One Gauss–Seidel sweep over the bending, tether and seam constraints, colour by colour,
    /// the bending blocks' symmetric (forward, then backward) through their lane kernels on
    /// kernel path `path`; the distance constraints are solved by [`crate::domains::Domains`],
    /// except in a frame solved jointly ([`Self::solves_jointly`]), where they are solved here
    /// with the bending.
    pub(crate) fn project_others(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
        path: SimdPath,
    ) {
        let h = self.xpbd_h;
        self.cg.substep_iterations = 0;
        if self.plan.joint {
            let cg = &mut self.cg;
            cg.begin(x.len());
            let at = quad_cg::Linearised {
                x,
                prev,
                w,
                params,
                h,
            };
            self.distance.gather_rows(quad_cg::DISTANCE_ROWS, &at, cg);
            self.dihedral.gather_rows(quad_cg::DIHEDRAL_ROWS, &at, cg);
            self.isometric.gather_rows(quad_cg::ISOMETRIC_ROWS, &at, cg);
            cg.solve();
            self.distance.apply_rows(quad_cg::DISTANCE_ROWS, x, cg);
            self.dihedral.apply_rows(quad_cg::DIHEDRAL_ROWS, x, cg);
            self.isometric.apply_rows(quad_cg::ISOMETRIC_ROWS, x, cg);
        } else {
            let none = FrameConstants::default();
            if self.plan.bending[0] {
                self.dihedral
                    .solve_cg(x, prev, w, params, h, quad_cg::DIHEDRAL_ROWS, &mut self.cg);
            } else {
                self.dihedral
                    .project_symmetric_lanes(x, prev, w, params, rule, path, false, &none);
            }
            if self.plan.bending[1] {
                self.isometric.solve_cg(
                    x,
                    prev,
                    w,
                    params,
                    h,
                    quad_cg::ISOMETRIC_ROWS,
                    &mut self.cg,
                );
            } else {
                let forward = self.isometric_forward;
                let constants = &self.isometric_constants;
                self.isometric
                    .project_symmetric_lanes(x, prev, w, params, rule, path, forward, constants);
            }
        }
        self.tethers.project(x, prev, w, params, rule);
        self.seams.project(x, prev, w, &self.seam_params, rule);
    }

    /// Whether this frame's distance and bending constraints are solved together by
    /// conjugate gradients (see `quad_cg`), so that the domains' sweep is skipped.
    pub(crate) fn solves_jointly(&self) -> bool {
        self.plan.joint
    }

    /// Conjugate-gradient iterations of the last substep's solves.
    pub(crate) fn cg_iterations(&self) -> usize {
        self.cg.substep_iterations
    }

    /// One more sweep over the closed seams alone (rest length 0, at most
    /// [`Seam::HOLD_GAP`] open), after the substep's last contact pass: friction by position
    /// undoes any tangential motion smaller than μ times the contact depth, the seam's own
    /// pull included, so a seam lying on a body would stay open by that much. A wider seam is
    /// left to the contacts: it may be caught across a limb, and must not be pulled through.
    pub(crate) fn hold_seams(&mut self, x: &mut [DVec3], prev: &[DVec3], w: &[f64], rule: Rule) {
        self.seams
            .project_where(x, prev, w, &self.seam_params, rule, |s, p| {
                s.rest == 0.0 && p[0].distance(p[1]) <= Seam::HOLD_GAP
            });
    }

    /// Adds spring forces −(k C + c Ċ) ∇C of every constraint to `forces` (N): the serial loop
    /// that [`ConstraintSet::spring_force_slots`] must match bit for bit.
    #[cfg(test)]
    pub(crate) fn spring_forces(
        &self,
        x: &[DVec3],
        v: &[DVec3],
        params: &[FamilyParams],
        forces: &mut [DVec3],
    ) {
        self.distance.spring_forces(x, v, params, forces);
        self.dihedral.spring_forces(x, v, params, forces);
        self.isometric.spring_forces(x, v, params, forces);
        self.tethers.spring_forces(x, v, params, forces);
        self.seams.spring_forces(x, v, &self.seam_params, forces);
    }

    /// |C| over distance-like constraints (stretch, shear, bend-distance) and active tethers (m).
    pub fn distance_residual(&self, x: &[DVec3]) -> Residual {
        let mut r = Residual::default();
        let mut sum = 0.0f64;
        for c in self.distance.residuals(x).chain(self.tethers.residuals(x)) {
            r.max = r.max.max(c.abs());
            sum += c * c;
            r.count += 1;
        }
        if r.count > 0 {
            r.rms = (sum / r.count as f64).sqrt();
        }
        r
    }
}
