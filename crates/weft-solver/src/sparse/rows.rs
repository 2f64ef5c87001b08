//! `Rows`: which spring slots each particle's row of the spring operator sums, built once from
//! the constraint graph (compressed sparse rows of slots, each row in ascending slot order).
//!
//! A slot is one spring's share at one of its particles: a spring over `N` particles owns `N`
//! consecutive slots. A pass over the springs writes each slot's 3-vector (or block); a pass
//! over the rows then sums, for each particle, its slots in a fixed order. Each row is written
//! by one task and read from every slot's owner, so the sums are the same whatever the thread
//! count.

use glam::DVec3;
use rayon::prelude::*;

use crate::chunk::CHUNK;

/// The slots of every particle's row (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Rows {
    /// Row i's slots are `slots[start[i] .. start[i + 1]]`.
    start: Vec<u32>,
    slots: Vec<u32>,
}

impl Rows {
    /// Rows of `n` particles from the particle of each slot, `owners[slot]` (a counting sort:
    /// each row lists its slots in ascending order).
    pub fn new(n: usize, owners: &[u32]) -> Self {
        let mut start = vec![0u32; n + 1];
        for &p in owners {
            start[p as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut slots = vec![0u32; owners.len()];
        for (slot, &p) in owners.iter().enumerate() {
            let at = &mut fill[p as usize];
            slots[*at as usize] = slot as u32;
            *at += 1;
        }
        Self { start, slots }
    }

    /// Number of rows (particles).
    pub fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Number of slots.
    #[cfg(test)]
    pub fn slot_count(&self) -> usize {
        self.slots.len()
    }

    /// The slots of row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[u32] {
        &self.slots[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Σ of row `i`'s slot values `y`, in ascending slot order.
    #[inline]
    pub fn sum<T: Copy + std::ops::Add<Output = T>>(&self, i: usize, y: &[T], zero: T) -> T {
        self.row(i).iter().fold(zero, |s, &k| s + y[k as usize])
    }

    /// `out[i] = f(i, Σ slots of row i in y)` for every row, in parallel chunks; returns the
    /// chunks' partial sums of `g(i, out[i])`, added in chunk order.
    pub fn gather<F, G>(&self, y: &[DVec3], out: &mut [DVec3], f: F, g: G) -> f64
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
                    *o = f(i, self.sum(i, y, DVec3::ZERO));
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
    fn rows_list_each_particles_slots_in_order() {
        // Two springs (0, 2) and (2, 1): slots 0..4 owned by 0, 2, 2, 1.
        let rows = Rows::new(3, &[0, 2, 2, 1]);
        assert_eq!(rows.len(), 3);
        assert_eq!(rows.slot_count(), 4);
        assert_eq!(rows.row(0), &[0]);
        assert_eq!(rows.row(1), &[3]);
        assert_eq!(rows.row(2), &[1, 2]);
        let y = [DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
        let mut out = vec![DVec3::ZERO; 3];
        let total = rows.gather(&y, &mut out, |_, s| s * 2.0, |_, o| o.x + o.y + o.z);
        assert_eq!(
            out,
            vec![DVec3::X * 2.0, DVec3::ONE * 2.0, DVec3::new(0.0, 2.0, 2.0)]
        );
        assert_eq!(total, 2.0 + 6.0 + 4.0);
    }
}
