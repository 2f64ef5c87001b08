//! `SpringWork`: what the spring methods keep between substeps — the rows of the explicit
//! force pass and the terms of the implicit operator (each built once from the constraint
//! graph), the last velocity change (the implicit solve's warm start), the scratch vectors,
//! and the iterations the frame's solves took.

use glam::DVec3;

use crate::constraints::{ConstraintSet, Springs, TermRhs};
use crate::sparse::{Outcome, PcgScratch, Rows, Sym3, Terms};

/// The spring methods' state and scratch, held by the solver (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct SpringWork {
    /// The rows of the explicit force pass and the spring counts they were built for.
    pub rows: Rows,
    counts: Option<[usize; 5]>,
    /// The terms of the implicit operator and the spring counts they were built for.
    pub terms: Terms,
    term_counts: Option<[usize; 5]>,
    /// The springs linearised at the current substep's state.
    pub springs: Springs,
    /// Each term's share of the right-hand side, of A x₀ and of A's diagonal.
    pub rhs: Vec<TermRhs>,
    /// Each term of a product, or each slot of the spring forces (scratch).
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

    /// Builds the terms of the implicit operator for `constraints` over `n` particles unless
    /// they are already built; a changed constraint set or particle count drops the warm start
    /// too.
    pub fn ensure_terms(&mut self, constraints: &ConstraintSet, n: usize) {
        let counts = constraints.spring_counts();
        if self.term_counts != Some(counts) || self.terms.len() != n {
            self.terms = constraints.spring_terms(n);
            self.term_counts = Some(counts);
            self.dv.clear();
        }
    }
}
