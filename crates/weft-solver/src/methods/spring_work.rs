//! `SpringWork`: what the spring methods keep between substeps — the rows of the explicit
//! force pass (built once from the constraint graph), the implicit system's row sums, the last
//! two velocity changes (the implicit solve's warm start), the scratch vectors, and the
//! iterations the frame's solves took.

use glam::DVec3;
use rayon::prelude::*;

use crate::chunk::CHUNK;
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
    /// The velocity change Δv: the last substep's, then the next solve's start and solution.
    pub dv: Vec<DVec3>,
    /// The Δv of the substep before the last (while `dv` holds the last's), then the last's.
    dv_before: Vec<DVec3>,
    /// How many solves in a row (up to 2) reached their tolerance.
    converged: u8,
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
            self.dv_before.clear();
        }
    }

    /// Sets `dv` to the next implicit solve's start over `n` particles: zero on the first
    /// solve (returns false, cold); after two solves that reached their tolerance the last two
    /// extrapolated, Δvₖ₋₁ + (Δvₖ₋₁ − Δvₖ₋₂), Δv changing smoothly from substep to substep (on
    /// the 128² reference 25 iterations a frame against 30 from the last Δv); else the last Δv.
    /// Extrapolated from capped solves, their errors compound (k = 10⁷ N/m at one substep a
    /// frame, 200 iterations each: an edge stretched 10 cm, not 0.1 mm).
    pub fn warm_start(&mut self, n: usize) -> bool {
        if self.dv.len() != n {
            self.dv.clear();
            self.dv.resize(n, DVec3::ZERO);
            self.dv_before.clear();
            self.converged = 0;
            return false;
        }
        if self.converged < 2 || self.dv_before.len() != n {
            self.dv_before.clone_from(&self.dv);
            return true;
        }
        self.dv_before
            .par_chunks_mut(CHUNK)
            .zip(self.dv.par_chunks(CHUNK))
            .for_each(|(before, last)| {
                for (b, l) in before.iter_mut().zip(last) {
                    *b = *l + (*l - *b);
                }
            });
        std::mem::swap(&mut self.dv, &mut self.dv_before);
        true
    }

    /// Records a solve's outcome, and whether it reached `tolerance`.
    pub fn solved(&mut self, outcome: Outcome, tolerance: f64) {
        self.iterations += outcome.iterations;
        self.worst = self.worst.max(outcome.residual);
        self.last = outcome;
        self.converged = match outcome.residual <= tolerance {
            true => (self.converged + 1).min(2),
            false => 0,
        };
    }
}
