//! Spring forces by slots: each spring writes its force at each of its particles into its own
//! slots, in parallel, and each particle then sums its slots in ascending order
//! ([`crate::sparse::Rows`]). Slots are numbered spring by spring, block after block in the
//! order of the serial loop ([`ConstraintSet::spring_forces`]), so every particle's sum is
//! taken in that loop's order: the same bits, whatever the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::linear::slot_blocks;
use super::{Block, ConstraintSet, Shape};
use crate::params::FamilyParams;
use crate::sparse::Rows;

/// Springs one parallel task takes (as the linearisation's tasks, `linear.rs`).
const SPRINGS: usize = 512;

impl<const N: usize, S: Shape<N>> Block<N, S> {
    /// Writes each spring's force fᵢ = −(k C + c Ċ) ∇Cᵢ, with Ċ = Σ ∇Cⱼ·vⱼ, at its `N`
    /// particles into its `N` slots of `y` (zero for a disabled family or a degenerate shape).
    fn spring_force_slots(
        &self,
        x: &[DVec3],
        v: &[DVec3],
        params: &[FamilyParams],
        y: &mut [DVec3],
    ) {
        y.par_chunks_mut(SPRINGS * N)
            .enumerate()
            .for_each(|(c, y)| {
                let base = c * SPRINGS;
                for (j, slots) in y.chunks_exact_mut(N).enumerate() {
                    let s = base + j;
                    let idx = self.particles[s];
                    let p = &params[self.group[s] as usize];
                    let evaluated = p
                        .enabled
                        .then(|| self.shapes[s].evaluate(&idx.map(|i| x[i as usize])))
                        .flatten();
                    let Some((c, grad)) = evaluated else {
                        slots.fill(DVec3::ZERO);
                        continue;
                    };
                    let c_dot: f64 = (0..N).map(|k| grad[k].dot(v[idx[k] as usize])).sum();
                    let f = -(p.spring_stiffness * c + p.spring_damping * c_dot);
                    for k in 0..N {
                        slots[k] = grad[k] * f;
                    }
                }
            });
    }
}

/// Appends the particle of each of a block's slots.
fn owners<const N: usize, S>(block: &Block<N, S>, out: &mut Vec<u32>) {
    out.extend(block.particles.iter().flatten());
}

impl ConstraintSet {
    /// The rows of the explicit force pass over `n` particles: each particle's slots.
    pub(crate) fn spring_rows(&self, n: usize) -> Rows {
        let mut o = Vec::new();
        owners(&self.distance, &mut o);
        owners(&self.dihedral, &mut o);
        owners(&self.isometric, &mut o);
        owners(&self.tethers, &mut o);
        owners(&self.seams, &mut o);
        Rows::new(n, &o)
    }

    /// Writes every spring's force at each of its particles into its slots `y` (N), in the
    /// slot order of [`ConstraintSet::spring_rows`].
    pub(crate) fn spring_force_slots(
        &self,
        x: &[DVec3],
        v: &[DVec3],
        params: &[FamilyParams],
        y: &mut Vec<DVec3>,
    ) {
        let [y_d, y_b, y_i, y_t, y_s] = slot_blocks(self.spring_counts(), y);
        self.distance.spring_force_slots(x, v, params, y_d);
        self.dihedral.spring_force_slots(x, v, params, y_b);
        self.isometric.spring_force_slots(x, v, params, y_i);
        self.tethers.spring_force_slots(x, v, params, y_t);
        self.seams.spring_force_slots(x, v, &self.seam_params, y_s);
    }
}
