//! `SpringWork`: what the spring methods keep between substeps — the rows of the spring
//! operator (built once from the constraint graph; the explicit method sums its forces by
//! them too), the last velocity change (the implicit solve's warm start), the scratch vectors,
//! and the iterations the frame's solves took.

use glam::DVec3;

use crate::constraints::{ConstraintSet, SlotRhs, Springs};
use crate::sparse::{Outcome, PcgScratch, Rows, Sym3};

/// The spring methods' state and scratch, held by the solver (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct SpringWork {
    /// The rows of the spring operator and the spring counts they were built for.
    pub rows: Rows,
    counts: Option<[usize; 5]>,
    /// The springs linearised at the current substep's state.
    pub springs: Springs,
    /// Each slot's share of the right-hand side, of A x₀ and of A's diagonal.
    pub rhs: Vec<SlotRhs>,
    /// Each slot's share of a product, or of the spring forces (scratch).
    pub y: Vec<DVec3>,
    /// The inverse diagonal blocks of A (zero at filtered particles): the preconditioner.
    pub pinv: Vec<Sym3>,
    /// The residual (scratch).
    pub r: Vec<DVec3>,
    /// The last substep's velocity change Δv: the warm start.
    pub dv: Vec<DVec3>,
    /// Conjugate gradients' scratch.
    pub scratch: PcgScratch,
    /// Conjugate-gradient iterations over the frame so far.
    pub iterations: u32,
    /// The last solve's outcome.
    pub last: Outcome,
}

impl SpringWork {
    /// Builds the rows for `constraints` over `n` particles unless they are already built; a
    /// changed constraint set or particle count drops the warm start too.
    pub fn ensure_rows(&mut self, constraints: &ConstraintSet, n: usize) {
        let counts = constraints.spring_counts();
        if self.counts != Some(counts) || self.rows.len() != n {
            self.rows = constraints.spring_rows(n);
            self.counts = Some(counts);
            self.dv.clear();
        }
    }
}
