//! Keeps the pool's other workers awake through a run of short parallel passes.
//!
//! Between two of rayon's fork–joins an idle worker soon falls asleep, and the next pass pays
//! a futex wake (tens of µs on a virtual core): with the implicit method's twenty or so passes
//! a substep, a 0.1 ms per-particle pass took as long on two threads as on one. [`awake`] runs
//! a closure while one helper per other worker spins, running whatever rayon work is pending
//! (`rayon::yield_now`, as `domains/team.rs`'s helpers do), until the closure returns. A helper
//! that starts on the caller's own thread (a caller waiting in a join may pop one from its
//! deque) returns at once, so the caller never spins in one. Which thread runs a job never
//! changes what it computes: the bits stay the closure's own.

use std::hint::spin_loop;
use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `f` with the pool's other workers spinning for work until it returns.
pub(crate) fn awake<R>(f: impl FnOnce() -> R) -> R {
    let threads = rayon::current_num_threads();
    let leader = rayon::current_thread_index();
    if threads < 2 || leader.is_none() {
        return f();
    }
    let exit = AtomicBool::new(false);
    rayon::in_place_scope(|scope| {
        let exit = &exit;
        for _ in 1..threads {
            scope.spawn(move |_| {
                if rayon::current_thread_index() == leader {
                    return;
                }
                while !exit.load(Ordering::Acquire) {
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        spin_loop();
                    }
                }
            });
        }
        let _exit = Exit(exit);
        f()
    })
}

/// Raises the exit flag when dropped, so the helpers leave even when the caller unwinds.
struct Exit<'a>(&'a AtomicBool);

impl Drop for Exit<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn the_closure_runs_once_with_its_parallel_passes_and_the_helpers_leave() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("pool");
        let sums: Vec<u64> = pool.install(|| {
            awake(|| {
                (0..200)
                    .map(|k| (0..10_000u64).into_par_iter().map(|i| i * k).sum())
                    .collect()
            })
        });
        assert_eq!(sums.len(), 200);
        for (k, s) in sums.iter().enumerate() {
            assert_eq!(*s, 10_000 * 9_999 / 2 * k as u64);
        }
        // Outside a pool, or on one thread, the closure simply runs.
        assert_eq!(awake(|| 7), 7);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("pool");
        assert_eq!(one.install(|| awake(|| 8)), 8);
    }
}
