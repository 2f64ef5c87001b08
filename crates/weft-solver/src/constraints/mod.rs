//! The constraint set: every cloth's constraints, coloured, in one block per shape.

mod block;
mod dihedral;
mod distance;
pub(crate) mod lanes;
mod linear;
mod tether;

pub(crate) use block::{Block, BlockBuilder, Rule};
pub use dihedral::Dihedral;
pub use distance::Distance;
pub(crate) use linear::Springs;
pub use tether::Tether;

use glam::DVec3;

use crate::params::FamilyParams;

/// A constraint function C(p) over `N` particles with its gradient.
pub trait Shape<const N: usize>: Copy + Send + Sync {
    /// Returns C and ∇C at `p`, or `None` when the constraint is inactive or degenerate there.
    fn evaluate(&self, p: &[DVec3; N]) -> Option<(f64, [DVec3; N])>;

    /// The Hessian of C at `p` applied to `dp`, (∇²C) dp, where it has a closed form; zero
    /// otherwise (the implicit method then uses ∇C ∇Cᵀ alone).
    fn curvature_product(&self, _p: &[DVec3; N], _dp: &[DVec3; N]) -> [DVec3; N] {
        [DVec3::ZERO; N]
    }
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

/// Every constraint of a solver: distance-like pairs, dihedral quadruples and tethers.
#[derive(Clone, Debug, Default)]
pub struct ConstraintSet {
    /// Stretch, shear and bend-distance constraints.
    pub(crate) distance: Block<2, Distance>,
    /// Dihedral bending constraints.
    pub(crate) dihedral: Block<4, Dihedral>,
    /// Long-range attachments.
    pub(crate) tethers: Block<2, Tether>,
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
        self.distance.len() + self.dihedral.len() + self.tethers.len()
    }

    /// Whether there is no constraint.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of colours in each block (distance, dihedral, tether).
    pub fn color_counts(&self) -> [usize; 3] {
        [
            self.distance.color_count(),
            self.dihedral.color_count(),
            self.tethers.color_count(),
        ]
    }

    /// Clears the XPBD multipliers (at the start of each substep).
    pub(crate) fn reset_multipliers(&mut self) {
        // The distance constraints' multipliers live in `Domains`, which clears its own.
        self.dihedral.reset_multipliers();
        self.tethers.reset_multipliers();
    }

    /// One Gauss–Seidel sweep over the dihedral and tether constraints, colour by colour, the
    /// dihedrals' symmetric (forward, then backward); the distance constraints are solved by
    /// [`crate::domains::Domains`].
    pub(crate) fn project_others(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
    ) {
        self.dihedral.project_symmetric(x, prev, w, params, rule);
        self.tethers.project(x, prev, w, params, rule);
    }

    /// Adds spring forces −(k C + c Ċ) ∇C of every constraint to `forces` (N).
    pub(crate) fn spring_forces(
        &self,
        x: &[DVec3],
        v: &[DVec3],
        params: &[FamilyParams],
        forces: &mut [DVec3],
    ) {
        self.distance.spring_forces(x, v, params, forces);
        self.dihedral.spring_forces(x, v, params, forces);
        self.tethers.spring_forces(x, v, params, forces);
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
