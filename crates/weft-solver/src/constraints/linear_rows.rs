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
    /// Adds a term read with weight `a`: b and A x₀ scaled by a, the diagonal block by a².
    #[inline(always)]
    pub(super) fn add(&mut self, a: f64, b: DVec3, ax: DVec3, d: Sym3) {
        self.b += b * a;
        self.ax += ax * a;
        self.d = self.d.add(d.scale(a * a));
    }
}
