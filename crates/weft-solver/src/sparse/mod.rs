//! Sparse linear algebra for the spring methods: the rows of the explicit force pass, vectors
//! summed deterministically in parallel, 3×3 symmetric blocks, and preconditioned conjugate
//! gradients.
//!
//! Every parallel loop here is split into fixed chunks of particles or springs, and every sum
//! across chunks is taken in chunk order on one thread: the bits never depend on the thread
//! count.
//!
//! Its modules:
//!
//! - `pcg`: preconditioned conjugate gradients on a filtered system (Baraff & Witkin's variant).
//! - `rows`: `Rows`: which spring slots each particle's row of the explicit force pass sums.
//! - `sym3`: `Sym3`: a symmetric 3×3 block stored as its distinct entries.
//! - `vector`: per-particle vector passes in parallel chunks, with sums taken in chunk order.

pub(crate) mod pcg;
pub(crate) mod rows;
pub(crate) mod sym3;
pub(crate) mod vector;

pub(crate) use pcg::{
    CgLimits, CgPasses, Operator, Outcome, PcgScratch, in_chunk_order, iterate, solve,
};
pub(crate) use rows::Rows;
pub(crate) use sym3::Sym3;
