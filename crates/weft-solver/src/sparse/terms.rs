//! `Terms`: which terms of the implicit spring operator each particle's row reads, and with
//! what weight, built once from the constraint graph (compressed sparse rows of entries, each
//! row in the order the entries were given).
//!
//! A term is one 3-vector a pass over the springs writes: a rank-one spring writes one, read by
//! each of its particles with that particle's weight; a spring without that form writes one per
//! particle, read with weight 1 (see `constraints/linear.rs`). A pass over the rows then sums,
//! for each particle, its weighted terms in a fixed order. Each row is written by one task, so
//! the sums are the same whatever the thread count.

use glam::DVec3;
use rayon::prelude::*;

use crate::chunk::CHUNK;

/// One term read by one particle, with its weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Entry {
    /// The particle whose row reads the term.
    pub particle: u32,
    /// The term's index.
    pub term: u32,
    /// The weight the particle reads it with.
    pub coef: f64,
}

/// A row's reference to a term: its index and weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Read {
    /// The term's index.
    pub term: u32,
    /// The weight.
    pub coef: f64,
}

/// The weighted terms of every particle's row (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Terms {
    /// Row i's reads are `reads[start[i] .. start[i + 1]]`.
    start: Vec<u32>,
    reads: Vec<Read>,
}

impl Terms {
    /// Rows of `n` particles from `entries` (a counting sort: each row keeps its entries in the
    /// order given).
    pub fn new(n: usize, entries: &[Entry]) -> Self {
        let mut start = vec![0u32; n + 1];
        for e in entries {
            start[e.particle as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut reads = vec![Read { term: 0, coef: 0.0 }; entries.len()];
        for e in entries {
            let at = &mut fill[e.particle as usize];
            reads[*at as usize] = Read {
                term: e.term,
                coef: e.coef,
            };
            *at += 1;
        }
        Self { start, reads }
    }

    /// Number of rows (particles).
    pub fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// The reads of row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[Read] {
        &self.reads[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Σ coef · t[term] over row `i`, in the row's order.
    #[inline]
    pub fn sum(&self, i: usize, t: &[DVec3]) -> DVec3 {
        (self.row(i).iter()).fold(DVec3::ZERO, |s, r| s + t[r.term as usize] * r.coef)
    }

    /// `out[i] = f(i, row i's sum of t)` for every row, in parallel chunks; returns the chunks'
    /// partial sums of `g(i, out[i])`, added in chunk order.
    pub fn gather<F, G>(&self, t: &[DVec3], out: &mut [DVec3], f: F, g: G) -> f64
    where
        F: Fn(usize, DVec3) -> DVec3 + Sync,
        G: Fn(usize, DVec3) -> f64 + Sync,
    {
        let partials: Vec<f64> = out
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, out)| {
                let base = c * CHUNK;
                let mut acc = 0.0;
                for (j, o) in out.iter_mut().enumerate() {
                    let i = base + j;
                    *o = f(i, self.sum(i, t));
                    acc += g(i, *o);
                }
                acc
            })
            .collect();
        partials.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_read_their_terms_with_their_weights() {
        // A pair spring (0, 2) as term 0 with weights (1, −1); an outer spring (2, 1) as terms
        // 1 and 2.
        let e = |particle, term, coef| Entry {
            particle,
            term,
            coef,
        };
        let terms = Terms::new(
            3,
            &[e(0, 0, 1.0), e(2, 0, -1.0), e(2, 1, 1.0), e(1, 2, 1.0)],
        );
        assert_eq!(terms.len(), 3);
        assert_eq!(terms.row(1), &[Read { term: 2, coef: 1.0 }]);
        assert_eq!(
            terms.row(2),
            &[
                Read {
                    term: 0,
                    coef: -1.0
                },
                Read { term: 1, coef: 1.0 }
            ]
        );
        let t = [DVec3::X, DVec3::Y, DVec3::Z];
        let mut out = vec![DVec3::ZERO; 3];
        let total = terms.gather(&t, &mut out, |_, s| s * 2.0, |_, o| o.x + o.y + o.z);
        assert_eq!(
            out,
            vec![DVec3::X * 2.0, DVec3::Z * 2.0, DVec3::new(-2.0, 2.0, 0.0)]
        );
        assert_eq!(total, 2.0 + 2.0 + 0.0);
    }
}
