//! What a linearisation of the springs reads and what it adds to each particle's row of the
//! implicit system (Baraff & Witkin 1998, eq. 6): shared by the general passes (`linear.rs`)
//! and the stencil (`ray_stencil.rs`).

use glam::DVec3;

use crate::sparse::Sym3;

/// What the linearisation needs besides the springs: the state, the substep and the warm start.
#[derive(Clone, Copy)]
pub(crate) struct State<'a> {
    /// Positions.
    pub x: &'a [DVec3],
    /// Velocities.
    pub v: &'a [DVec3],
    /// The substep h.
    pub h: f64,
    /// The warm start x₀ of Δv, if any.
    pub x0: Option<&'a [DVec3]>,
}

/// A particle's row of A − M and of the right-hand side, summed over its springs: what the
/// linearisation adds to each particle (the caller starts each row with M's share).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RowSums {
    /// b = h f − h² K v (Baraff & Witkin eq. 6).
    pub b: DVec3,
    /// A x₀ for the warm start x₀.
    pub ax: DVec3,
    /// A's diagonal block.
    pub d: Sym3,
}

impl RowSums {
    /// M's share of a particle's row, M = 1/w (zero where w = 0): b = h M a_ext, M x₀ and M.
    /// The springs' shares are added to it.
    #[inline(always)]
    pub(crate) fn of_mass(w: f64, accel: DVec3, x0: DVec3, h: f64) -> Self {
        let m = if w > 0.0 { 1.0 / w } else { 0.0 };
        Self {
            b: accel * (m * h),
            ax: x0 * m,
            d: Sym3::scaled_identity(m),
        }
    }

    /// From the whole row, the particle's residual r = b − A x₀ and block-Jacobi inverse;
    /// zeros, and x₀ = 0, where w = 0 (Baraff & Witkin's filter). Returns b·b (0 filtered).
    #[inline(always)]
    pub(crate) fn finish(&self, w: f64, r: &mut DVec3, pinv: &mut Sym3, x0: &mut DVec3) -> f64 {
        if w <= 0.0 {
            (*r, *pinv, *x0) = (DVec3::ZERO, Sym3::default(), DVec3::ZERO);
            return 0.0;
        }
        *r = self.b - self.ax;
        *pinv = self.d.inverse();
        self.b.dot(self.b)
    }

    /// Adds a term read with weight `a`: b and A x₀ scaled by a, the diagonal block by a².
    #[inline(always)]
    pub(super) fn add(&mut self, a: f64, b: DVec3, ax: DVec3, d: Sym3) {
        self.b += b * a;
        self.ax += ax * a;
        self.d = self.d.add(d.scale(a * a));
    }
}
