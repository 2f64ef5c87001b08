//! A team of threads kept for a whole fused frame, handing the domains' passes over with a
//! spin instead of a fork–join per pass.
//!
//! A `rayon::join` per pass left the second worker idle between passes long enough to fall
//! asleep, so every pass paid a futex wake: on two threads, a fifth of the frame's samples were
//! in the scheduler. A team cuts the fork–join tree (see [`fork`]) at the depth where it has one
//! subtree (a *slot*) per worker. Its helpers stay in a spin loop for the whole frame and claim
//! slots as the leader posts passes; the leader solves the links above the slots once every
//! slot is done, children before parents. Each slot is solved exactly as `fork` solves its
//! subtree, so a pass does the same arithmetic in the same order whoever claims which slot:
//! the same bits on any thread count. Claims never wait: a helper that starts late (or not at
//! all, in a pool busy with other work) leaves its slot to the leader.

use std::hint::spin_loop;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use glam::DVec3;
use rayon::prelude::*;

use super::Domains;
use super::domain::{AosChunk, Domain, Mode};
use super::tree::{Job, LinkSet, fork, solve_links};
use crate::constraints::lanes::Coef;
use crate::hook::{Contacts, ParticleContacts};

/// The low word of a posted pass that integrates nothing: a sweep only.
const PROJECT: u32 = u32::MAX;

/// Spins of the waiting leader between checks for a worker's panic.
const SPINS: u32 = 256;

/// One worker's share of the tree: a subtree's domains and the links of its internal nodes.
struct Slot {
    /// Global index of its first domain.
    first: usize,
    /// Its domains (moved out while the leader solves the links above the slots).
    doms: Vec<Domain>,
    /// How many domains it holds.
    count: usize,
    /// Links of the subtree's internal nodes, in preorder.
    links: Vec<LinkSet>,
    /// The number of the last pass solved on it.
    done: u64,
    /// Which half the next pass visits first (see `Job::reverse`).
    reverse: bool,
}

/// What the leader and its helpers share for a frame.
struct Board<'a, W> {
    slots: Vec<Mutex<Slot>>,
    /// The pass posted last: its number (high word) and the substep it integrates before the
    /// sweep, or [`PROJECT`] (low word). One word, so a helper never pairs a pass with another
    /// pass's work.
    posted: AtomicU64,
    /// Slots solved over every pass so far.
    solved: AtomicU64,
    /// Raised when the frame ends (or the leader unwinds).
    exit: AtomicBool,
    coef: &'a [Coef],
    mode: Mode,
    /// The particle store's positions, velocities and inverse masses.
    store: (&'a [DVec3], &'a [DVec3], &'a [f64]),
    /// Particles per domain.
    size: usize,
    /// Runs on each domain before its sweep in a pass that integrates substep `k`.
    work: &'a W,
}

/// Locks a slot; a poisoned lock means a worker panicked, and the leader panics with it.
fn lock(slot: &Mutex<Slot>) -> MutexGuard<'_, Slot> {
    slot.lock().unwrap_or_else(PoisonError::into_inner)
}

impl<W> Board<'_, W>
where
    W: Fn(u32, &mut Domain, &AosChunk<'_>) + Sync,
{
    /// Domain `index`'s particles in the store.
    fn chunk(&self, index: usize) -> AosChunk<'_> {
        let (x, v, w) = self.store;
        let r = index * self.size..((index + 1) * self.size).min(x.len());
        AosChunk {
            x: &x[r.clone()],
            v: &v[r.clone()],
            w: &w[r],
        }
    }

    /// Solves every slot of pass `pass` that nobody has claimed, starting from worker `me`'s.
    fn claim(&self, me: usize, pass: u64, code: u32) {
        let n = self.slots.len();
        for j in 0..n {
            let Ok(mut slot) = self.slots[(me + j) % n].try_lock() else {
                continue;
            };
            // A stale pass number (the leader has posted the next) finds `done` up to date.
            if slot.done < pass {
                self.solve(&mut slot, code);
                slot.done = pass;
                self.solved.fetch_add(1, Ordering::Release);
            }
        }
    }

    /// One pass over a slot: its subtree as [`fork`] solves it, on this thread.
    fn solve(&self, slot: &mut Slot, code: u32) {
        if code != PROJECT {
            for set in &mut slot.links {
                set.lambda.fill(0.0);
            }
        }
        let before = |d: &mut Domain, index: usize| {
            if code != PROJECT {
                (self.work)(code, d, &self.chunk(index));
            }
        };
        let reverse = slot.reverse;
        slot.reverse = !reverse;
        let job = Job {
            before: &before,
            coef: self.coef,
            mode: self.mode,
            reverse,
            // A team of one (one thread or one domain) forks inside its slot as the tree did.
            serial: self.slots.len() > 1,
        };
        let first = slot.first;
        let Slot { doms, links, .. } = slot;
        fork(doms, first, links, &job);
    }

    /// A helper's loop: claims slots as passes are posted until the frame ends. While it
    /// waits, it runs any other rayon work pending (the frame's parallel collision passes and
    /// the hook's own loops among it: the helper is one of the pool's threads), else spins.
    fn serve(&self, me: usize) {
        let mut seen = 0;
        while !self.exit.load(Ordering::Acquire) {
            let word = self.posted.load(Ordering::Acquire);
            let pass = word >> 32;
            if pass != seen {
                seen = pass;
                // The low word is the pass's code by construction.
                self.claim(me, pass, word as u32);
            } else if rayon::yield_now() != Some(rayon::Yield::Executed) {
                spin_loop();
            }
        }
    }
}

/// Raises the exit flag when dropped, so helpers leave even when the leader unwinds.
struct Exit<'a>(&'a AtomicBool);

impl Drop for Exit<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// The leader's handle on a frame's team (see [`Domains::team`]).
pub(crate) struct Team<'t, 'a, W> {
    board: &'t Board<'a, W>,
    /// Links of the tree's nodes above the slots, in preorder.
    upper: Vec<LinkSet>,
    /// Passes posted so far.
    pass: u64,
    /// Every slot's domains, in order, while the links above the slots are solved.
    gathered: Vec<Domain>,
}

impl<W> Team<'_, '_, W>
where
    W: Fn(u32, &mut Domain, &AosChunk<'_>) + Sync,
{
    /// Clears every link multiplier, runs the frame's work for substep `k` on every domain,
    /// then projects every domain and link once.
    pub fn integrate_and_project(&mut self, k: u32) {
        debug_assert!(k != PROJECT);
        self.pass(k);
    }

    /// Projects every domain and link once more.
    pub fn project(&mut self) {
        self.pass(PROJECT);
    }

    fn pass(&mut self, code: u32) {
        let board = self.board;
        self.pass += 1;
        if code != PROJECT {
            for set in &mut self.upper {
                set.lambda.fill(0.0);
            }
        }
        board
            .posted
            .store((self.pass << 32) | u64::from(code), Ordering::Release);
        board.claim(0, self.pass, code);
        let all = self.pass * board.slots.len() as u64;
        let mut spins = 0;
        while board.solved.load(Ordering::Acquire) < all {
            spins += 1;
            if spins % SPINS == 0 {
                assert!(
                    !board.slots.iter().any(Mutex::is_poisoned),
                    "a worker of the domain team panicked"
                );
            }
            spin_loop();
        }
        if self.upper.is_empty() {
            return;
        }
        for slot in &board.slots {
            self.gathered.append(&mut lock(slot).doms);
        }
        solve_upper(
            &mut self.gathered,
            0,
            &mut self.upper,
            board.slots.len(),
            board.coef,
            board.mode,
        );
        let mut back = self.gathered.drain(..);
        for slot in &board.slots {
            let mut slot = lock(slot);
            let count = slot.count;
            slot.doms.extend(back.by_ref().take(count));
        }
    }

    /// Resolves every free particle's contacts with `contacts`, domain by domain in parallel;
    /// returns the totals (sums and a maximum: the same whatever the order).
    pub fn collide(&mut self, contacts: &dyn ParticleContacts, fresh: bool) -> Contacts {
        self.board
            .slots
            .par_iter()
            .map(|slot| {
                (lock(slot).doms.par_iter_mut())
                    .map(|d| d.collide(contacts, fresh))
                    .reduce(Contacts::default, Contacts::merge)
            })
            .reduce(Contacts::default, Contacts::merge)
    }
}

/// Solves the links of the nodes above the slots (`upper`, in preorder, over `slots` slots)
/// once every slot is done: children before parents, as [`fork`] does.
fn solve_upper(
    doms: &mut [Domain],
    first: usize,
    upper: &mut [LinkSet],
    slots: usize,
    coef: &[Coef],
    mode: Mode,
) {
    let Some((own, below)) = upper.split_first_mut() else {
        return;
    };
    let mid = doms.len() / 2;
    let (left_links, right_links) = below.split_at_mut(slots / 2 - 1);
    let (left, right) = doms.split_at_mut(mid);
    solve_upper(left, first, left_links, slots / 2, coef, mode);
    solve_upper(right, first + mid, right_links, slots / 2, coef, mode);
    solve_links(doms, first, own, coef, mode);
}

/// Cuts the tree over domains `lo..hi` (whose preorder starts at node `node`) into `slots`
/// subtrees: each slot's domains and node range into `out`, the nodes above them into `upper`.
fn carve(
    lo: usize,
    hi: usize,
    node: usize,
    slots: usize,
    out: &mut Vec<(Range<usize>, Range<usize>)>,
    upper: &mut Vec<usize>,
) {
    if slots == 1 {
        out.push((lo..hi, node..node + (hi - lo).saturating_sub(1)));
        return;
    }
    upper.push(node);
    let mid = lo + (hi - lo) / 2;
    carve(lo, mid, node + 1, slots / 2, out, upper);
    carve(mid, hi, node + 1 + (mid - lo - 1), slots / 2, out, upper);
}

/// Where a node's links go while a team holds them.
#[derive(Clone, Copy)]
enum Owner {
    Slot(usize),
    Upper,
}

impl Domains {
    /// Runs `body` with a team of workers over the domains: one per rayon thread, at most one
    /// per domain, a power of two.
    /// `work(k, domain, particles)` runs on each domain before its sweep in a pass that
    /// integrates substep `k`, with the domain's particles in the store (`x`, `v`, `w`).
    /// Coefficients from [`Domains::prepare`].
    pub fn team<W, R>(
        &mut self,
        x: &[DVec3],
        v: &[DVec3],
        w: &[f64],
        work: &W,
        body: impl FnOnce(&mut Team<'_, '_, W>) -> R,
    ) -> R
    where
        W: Fn(u32, &mut Domain, &AosChunk<'_>) + Sync,
    {
        let count = self.list.len();
        let workers = rayon::current_num_threads().min(count).max(1);
        let slots = 1 << workers.ilog2();
        let (mut out, mut upper_nodes) = (Vec::new(), Vec::new());
        carve(0, count, 0, slots, &mut out, &mut upper_nodes);
        let mut owner = vec![Owner::Upper; self.links.len()];
        let mut slot_links: Vec<Vec<LinkSet>> = vec![Vec::new(); slots];
        let mut upper = Vec::new();
        for (j, (_, nodes)) in out.iter().enumerate() {
            owner[nodes.clone()].fill(Owner::Slot(j));
        }
        for (set, &o) in std::mem::take(&mut self.links).into_iter().zip(&owner) {
            match o {
                Owner::Slot(j) => slot_links[j].push(set),
                Owner::Upper => upper.push(set),
            }
        }
        let mut doms = std::mem::take(&mut self.list).into_iter();
        let slots: Vec<Mutex<Slot>> = (out.iter().zip(slot_links))
            .map(|((range, _), links)| {
                Mutex::new(Slot {
                    first: range.start,
                    doms: doms.by_ref().take(range.len()).collect(),
                    count: range.len(),
                    links,
                    done: 0,
                    reverse: false,
                })
            })
            .collect();
        let board = Board {
            slots,
            posted: AtomicU64::new(0),
            solved: AtomicU64::new(0),
            exit: AtomicBool::new(false),
            coef: &self.coef,
            mode: self.mode,
            store: (x, v, w),
            size: self.size,
            work,
        };
        let (result, upper) = rayon::in_place_scope(|scope| {
            let board = &board;
            for me in 1..board.slots.len() {
                scope.spawn(move |_| board.serve(me));
            }
            let _exit = Exit(&board.exit);
            let mut team = Team {
                board,
                upper,
                pass: 0,
                gathered: Vec::with_capacity(count),
            };
            let result = body(&mut team);
            (result, team.upper)
        });
        let slots: Vec<Slot> = (board.slots.into_iter())
            .map(|s| s.into_inner().unwrap_or_else(PoisonError::into_inner))
            .collect();
        let mut slot_links: Vec<_> = Vec::with_capacity(slots.len());
        for slot in slots {
            self.list.extend(slot.doms);
            slot_links.push(slot.links.into_iter());
        }
        let mut upper = upper.into_iter();
        for o in owner {
            let set = match o {
                Owner::Slot(j) => slot_links[j].next(),
                Owner::Upper => upper.next(),
            };
            self.links.extend(set);
        }
        result
    }
}
