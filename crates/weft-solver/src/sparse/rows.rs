//! `Rows`: which spring slots each particle's row of the explicit force pass sums, built once
//! from the constraint graph (compressed sparse rows of slots, each row in ascending slot order).
//!
//! A slot is one spring's share at one of its particles: a spring over `N` particles owns `N`
//! consecutive slots. A pass over the springs writes each slot's 3-vector (or block); a pass
//! over the rows then sums, for each particle, its slots in a fixed order. Each row is written
//! by one task and read from every slot's owner, so the sums are the same whatever the thread
//! count.

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
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

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
        let sums: Vec<DVec3> = (0..3).map(|i| rows.sum(i, &y, DVec3::ZERO)).collect();
        assert_eq!(sums, vec![DVec3::X, DVec3::ONE, DVec3::new(0.0, 1.0, 1.0)]);
    }
}
