//! The candidate lists of triangle meshes that keep per-particle lists (deforming meshes, and
//! still meshes too large for a contact grid), kept per run of particles when the solver's
//! fused frame resolves contacts inside its domains: each domain hands the world the same run
//! (first particle, length) at every pass, and locks the lists of that run alone.

use std::sync::{Arc, Mutex, MutexGuard};

use crate::trimesh::chunk_lists::ChunkLists;

/// One run's lists: one [`ChunkLists`] per mesh with lists, indexed from the run's start.
type Lists = Arc<Mutex<Vec<ChunkLists>>>;

/// A run: its first particle, its length, and the meshes it keeps lists for.
type Run = (usize, usize, usize);

/// The lists of every run seen.
#[derive(Debug, Default)]
pub(crate) struct RunLists(Mutex<Vec<(Run, Lists)>>);

/// A poisoned lock (a panic elsewhere while it was held) still holds valid lists: a list is
/// rebuilt whenever it does not cover its particle, so a half-updated one is only slower.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl RunLists {
    /// The lists of the run of `len` particles from `start`, for `meshes` meshes (new ones,
    /// all to be built, the first time the run is seen). The runs of one solver's domains do
    /// not overlap: a new run drops those it overlaps, left from domains since rebuilt.
    pub fn lock(&self, start: usize, len: usize, meshes: usize) -> OwnedLists {
        let key = (start, len, meshes);
        let mut runs = lock(&self.0);
        if let Some((_, l)) = runs.iter().find(|(k, _)| *k == key) {
            return OwnedLists(l.clone());
        }
        let end = start + len;
        runs.retain(|((s, l, _), _)| s + l <= start || end <= *s);
        let l = Arc::new(Mutex::new(vec![ChunkLists::new(len); meshes]));
        runs.push((key, l.clone()));
        OwnedLists(l)
    }

    /// The lists of a run holding particle `i` (for `meshes` meshes) and that run's first
    /// particle: a domain's run if one is kept, else a run of `i` alone.
    pub fn lock_holding(&self, i: usize, meshes: usize) -> (OwnedLists, usize) {
        let found = lock(&self.0).iter().find_map(|((s, l, m), lists)| {
            ((*s..s + l).contains(&i) && *m == meshes).then(|| (lists.clone(), *s))
        });
        match found {
            Some((lists, start)) => (OwnedLists(lists), start),
            None => (self.lock(i, 1, meshes), i),
        }
    }

    /// Forgets every run's lists.
    pub fn clear(&mut self) {
        lock(&self.0).clear();
    }

    /// Runs whose lists are kept.
    #[cfg(test)]
    fn runs(&self) -> Vec<(usize, usize)> {
        lock(&self.0)
            .iter()
            .map(|((s, l, _), _)| (*s, *l))
            .collect()
    }

    /// `f` summed over every run's lists.
    pub fn sum(&self, f: impl Fn(&ChunkLists) -> u64) -> u64 {
        lock(&self.0)
            .iter()
            .map(|(_, l)| lock(l).iter().map(&f).sum::<u64>())
            .sum()
    }
}

/// A run's lists, to lock for the run's pass.
pub(crate) struct OwnedLists(Lists);

impl OwnedLists {
    /// The lists, locked (one domain's pass at a time holds them), compacted once half
    /// stale.
    pub fn get(&self) -> MutexGuard<'_, Vec<ChunkLists>> {
        let mut g = lock(&self.0);
        g.iter_mut().for_each(ChunkLists::tidy);
        g
    }
}

impl Clone for RunLists {
    fn clone(&self) -> Self {
        let runs = lock(&self.0)
            .iter()
            .map(|(key, l)| (*key, Arc::new(Mutex::new(lock(l).clone()))))
            .collect();
        Self(Mutex::new(runs))
    }
}

#[cfg(test)]
mod tests {
    use super::RunLists;

    /// A run is found again with its lists; a run of new domains drops the old ones it
    /// overlaps and keeps the others.
    #[test]
    fn runs_keep_their_lists_until_new_domains_overlap_them() {
        let runs = RunLists::default();
        for (start, len) in [(0, 100), (100, 100), (200, 50)] {
            let owned = runs.lock(start, len, 2);
            owned.get()[1].builds = start as u64 + 1;
        }
        assert_eq!(runs.sum(|l| l.builds), 1 + 101 + 201);
        assert_eq!(runs.lock(100, 100, 2).get()[1].builds, 101, "found again");
        // A domain from 50 to 150 replaces the first two.
        runs.lock(50, 100, 2);
        assert_eq!(runs.runs(), vec![(200, 50), (50, 100)]);
        assert_eq!(runs.sum(|l| l.builds), 201);
        // One particle's call finds the run holding it; a particle in none gets its own.
        assert_eq!(runs.lock_holding(120, 2).1, 50);
        assert_eq!(runs.lock_holding(300, 2).1, 300);
        assert_eq!(runs.runs(), vec![(200, 50), (50, 100), (300, 1)]);
        // Another mesh count: new lists for the run.
        assert_eq!(runs.lock(200, 50, 3).get().len(), 3);
        assert_eq!(runs.sum(|l| l.builds), 0);
    }
}
