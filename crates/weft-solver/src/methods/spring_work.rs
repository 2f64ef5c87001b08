//! `SpringWork`: what the spring methods keep between substeps — the rows of the explicit
//! force pass (built once from the constraint graph), the implicit system's row sums, the last
//! velocity change (the implicit solve's warm start), the scratch vectors, and the iterations
//! the frame's solves took.

use glam::DVec3;

use crate::constraints::{ConstraintSet, RowSums, Springs};
use crate::sparse::{Outcome, PcgScratch, Rows, Sym3};

/// The spring methods' state and scratch, held by the solver (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct SpringWork {
    /// The rows of the explicit force pass and the spring counts they were built for.
    pub rows: Rows,
    counts: Option<[usize; 5]>,
    /// The spring counts and particle count the pass orders and the warm start are for.
    implicit_for: Option<([usize; 5], usize)>,
    /// The springs linearised at the current substep's state.
    pub springs: Springs,
    /// Each particle's right-hand side, A x₀ and diagonal block of A (the implicit system).
    pub sums: Vec<RowSums>,
    /// Each slot of the spring forces (scratch).
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
    /// The largest relative residual a solve of the frame so far ended at.
    pub worst: f64,
    /// The last solve's outcome.
    pub last: Outcome,
}

impl SpringWork {
    /// Builds the rows of the explicit force pass for `constraints` over `n` particles unless
    /// they are already built.
    pub fn ensure_rows(&mut self, constraints: &ConstraintSet, n: usize) {
        let counts = constraints.spring_counts();
        if self.counts != Some(counts) || self.rows.len() != n {
            self.rows = constraints.spring_rows(n);
            self.counts = Some(counts);
        }
    }

    /// Readies the implicit solve for `constraints` over `n` particles: when either changed
    /// since the last solve, the springs' pass orders are made anew and the warm start dropped.
    pub fn prepare_implicit(&mut self, constraints: &ConstraintSet, n: usize) {
        let now = (constraints.spring_counts(), n);
        if self.implicit_for != Some(now) {
            self.implicit_for = Some(now);
            self.springs.order(constraints, n);
            self.dv.clear();
        }
    }
}
