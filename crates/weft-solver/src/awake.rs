//! Keeps the pool's other workers awake through a run of short parallel passes.
//!
//! Between two of rayon's fork–joins an idle worker soon falls asleep, and the next pass pays
//! a futex wake (tens of µs on a virtual core): with the implicit method's twenty or so passes
//! a substep, a 0.1 ms per-particle pass took as long on two threads as on one; the explicit
//! stencil frame's pass a substep, 0.1 ms, lost a tenth of its frame to them; every frame of
//! the general loop (self-collision, cloth contact, bending outside the sweep) runs in it too,
//! up to 20 % quicker on two threads (`docs/performance-notes.md`). [`awake`] runs
//! a closure while one helper per other worker spins, running whatever rayon work is pending
//! (`rayon::yield_now`, as `domains/team.rs`'s helpers do), until the closure returns. Which
//! thread runs a job never changes what it computes: the bits stay the closure's own.
//!
//! A helper can be picked up by a thread that is itself waiting in a join, below work that
//! someone else waits for; spinning there until the closure ends could close a cycle (two
//! `weft experiments` runs, each waiting on work under the other's helper). So a helper
//! returns at once on a thread that is leading an `awake` of its own, and leaves after
//! [`IDLE`] without finding work: a cycle costs at most that, never a hang.

use std::cell::Cell;
use std::hint::spin_loop;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How long a helper spins without finding work before it leaves: far longer than the gap
/// between two passes of a substep (µs), far shorter than a frame.
const IDLE: Duration = Duration::from_millis(1);

thread_local! {
    /// How many `awake` closures this thread is running.
    static LEADING: Cell<u32> = const { Cell::new(0) };
}

/// Runs `f` with the pool's other workers spinning for work until it returns.
pub(crate) fn awake<R>(f: impl FnOnce() -> R) -> R {
    let threads = rayon::current_num_threads();
    if threads < 2 || rayon::current_thread_index().is_none() {
        return f();
    }
    let exit = AtomicBool::new(false);
    rayon::in_place_scope(|scope| {
        let exit = &exit;
        for _ in 1..threads {
            scope.spawn(move |_| help(exit));
        }
        let _lead = Lead::start(exit);
        f()
    })
}

/// A helper: runs pending rayon work until `exit`, or until [`IDLE`] passes without any.
fn help(exit: &AtomicBool) {
    if LEADING.with(Cell::get) > 0 {
        return;
    }
    let mut last = Instant::now();
    let mut spins = 0u32;
    while !exit.load(Ordering::Acquire) {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            last = Instant::now();
            continue;
        }
        spin_loop();
        spins = spins.wrapping_add(1);
        if spins % 64 == 0 && last.elapsed() > IDLE {
            return;
        }
    }
}

/// Marks this thread as leading while it lives; raises the exit flag when dropped, so the
/// helpers leave even when the caller unwinds.
struct Lead<'a>(&'a AtomicBool);

impl<'a> Lead<'a> {
    fn start(exit: &'a AtomicBool) -> Self {
        LEADING.with(|l| l.set(l.get() + 1));
        Self(exit)
    }
}

impl Drop for Lead<'_> {
    fn drop(&mut self) {
        LEADING.with(|l| l.set(l.get().saturating_sub(1)));
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

    #[test]
    fn two_scopes_at_once_on_a_busy_pool_both_finish() {
        // As `weft experiments` runs implicit runs side by side on a pool of their number.
        for threads in [2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let run = || {
                awake(|| {
                    (0..100u64)
                        .map(|k| (0..20_000u64).into_par_iter().map(|i| i ^ k).sum::<u64>())
                        .sum::<u64>()
                })
            };
            let want: u64 = (0..100u64)
                .map(|k| (0..20_000u64).map(|i| i ^ k).sum::<u64>())
                .sum();
            let got: Vec<u64> =
                pool.install(|| (0..threads).into_par_iter().map(|_| run()).collect());
            assert!(got.iter().all(|&g| g == want), "{threads} threads: {got:?}");
        }
    }
}
