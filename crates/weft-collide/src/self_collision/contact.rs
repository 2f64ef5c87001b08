//! One Jacobi sweep over self-collision contacts: find the touching pairs of a candidate
//! list, compute each one's corrections eight at a time, and move every particle by the mean
//! of its corrections (constraint averaging, Macklin et al. 2014, "Unified Particle Physics
//! for Real-Time Applications", §4.2, eq. 11 with ω = 1).
//!
//! Each correction is rounded to a multiple of q = 2⁻⁴⁰ m (0.9 pm) before it is summed: f64
//! sums of such multiples are exact while they stay below 2⁵³ q = 8192 m, so addition is
//! associative and order-free. A particle's move depends only on the set of its contacts, not
//! on the order of the list, on how it is split into tasks, or on the thread count.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use glam::DVec3;
use multiversion::multiversion;
use rayon::prelude::*;
use weft_solver::Particles;

use super::SelfCollision;
use super::list::PairList;
use crate::friction::Friction;

/// Adding and subtracting 1.5 · 2¹² rounds an f64 of magnitude below 2¹¹ to the nearest
/// multiple of 2⁻⁴⁰ (its unit in the last place is 2⁻⁴⁰ there): round-to-nearest by a "magic
/// number" (Muller et al., "Handbook of Floating-Point Arithmetic", 2018, §5.2.1 — Rust never
/// reassociates or contracts the two operations).
const ROUND: f64 = 1.5 * 4096.0;

/// `v` rounded to a multiple of 2⁻⁴⁰ (for |v| < 2¹¹ m; see [`ROUND`]).
#[inline(always)]
fn quantize(v: f64) -> f64 {
    (v + ROUND) - ROUND
}

/// Touching pairs gathered into one block before the contact kernel runs over them.
const BLOCK: usize = 64;

/// One particle's correction from one contact, a multiple of 2⁻⁴⁰ m per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Correction {
    i: u32,
    d: [f64; 3],
}

/// Particle ranges the corrections are binned by, at most: [`apply`] runs range by range.
const BINS: usize = 8;

/// A sweep's corrections, binned by particle range (bin k holds those of particles
/// k·2^shift..(k+1)·2^shift), so that each range can be applied on its own thread.
#[derive(Clone, Debug, Default)]
struct Bins {
    shift: u32,
    bins: Vec<Vec<Correction>>,
    contacts: usize,
}

impl Bins {
    /// log2 of the range size for `n` particles: a power of two, at most [`BINS`] ranges.
    fn shift_for(n: usize) -> u32 {
        n.div_ceil(BINS).max(1).next_power_of_two().trailing_zeros()
    }

    /// Empties the bins and sets their ranges for `n` particles.
    fn reset(&mut self, n: usize) {
        self.shift = Self::shift_for(n);
        self.bins
            .resize_with(n.div_ceil(1 << self.shift).max(1), Vec::new);
        self.bins.iter_mut().for_each(Vec::clear);
        self.contacts = 0;
    }

    /// Adds particle `i`'s correction `d` to its range's bin.
    #[inline(always)]
    fn push(&mut self, i: u32, d: [f64; 3]) {
        self.bins[(i >> self.shift) as usize].push(Correction { i, d });
    }
}

/// The particle state a sweep reads.
#[derive(Clone, Copy)]
struct State<'a> {
    /// Positions at the start of the sweep.
    pub x: &'a [DVec3],
    /// Positions at the start of the substep.
    pub prev: &'a [DVec3],
    /// Inverse masses.
    pub w: &'a [f64],
}

/// Listed pairs filtered at a time before their touching ones are gathered: the positions the
/// filter loaded are then still in the L1 cache when the gather loads them again.
const CHUNK: usize = 256;

/// Finds the pairs (`a[k]`, `b[k]`) closer than `target[k]` and adds their corrections to
/// `out` (reset for the particle count first); returns the deepest overlap (m).
#[multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512dq+avx2+fma",
    "x86_64+avx2+fma",
    "aarch64+neon"
))]
fn find_contacts<'a>(
    (a, b, target): (&[u32], &[u32], &[f64]),
    s: State<'a>,
    friction: Friction,
    out: &mut Bins,
) -> f64 {
    let mut deepest = [0.0f64; BLOCK];
    let mut block = Block::EMPTY;
    let mut hits = [0u32; CHUNK];
    for start in (0..a.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(a.len());
        // Most listed pairs do not touch: a branch-free filter first (a branch here would be
        // mispredicted for about every fourth pair of a dense fold).
        let mut n = 0;
        for (k, ((&i, &j), &t)) in a[start..end]
            .iter()
            .zip(&b[start..end])
            .zip(&target[start..end])
            .enumerate()
        {
            let d2 = (s.x[i as usize] - s.x[j as usize]).length_squared();
            hits[n] = (start + k) as u32;
            n += usize::from(d2 < t * t);
        }
        for &k in &hits[..n] {
            block.push(k as usize, (a, b, target), s);
            if block.len == BLOCK {
                block.contacts(friction, out, &mut deepest);
                block.len = 0;
            }
        }
    }
    if block.len > 0 {
        block.contacts(friction, out, &mut deepest);
    }
    deepest.into_iter().fold(0.0, f64::max)
}

/// The data of up to [`BLOCK`] touching pairs, one lane each, as struct-of-arrays; the lanes
/// from `len` on hold stale or no data and are computed but never used.
///
/// Gathering first and computing after, in separate loops, lets the kernel load whole
/// vectors: loading a vector just assembled from scalar stores stalls on every load (store
/// forwarding fails), which cost the kernel about half its time when it gathered eight pairs
/// at a time.
struct Block {
    len: usize,
    ia: [u32; BLOCK],
    ib: [u32; BLOCK],
    t: [f64; BLOCK],
    xa: [[f64; BLOCK]; 3],
    xb: [[f64; BLOCK]; 3],
    pa: [[f64; BLOCK]; 3],
    pb: [[f64; BLOCK]; 3],
    wa: [f64; BLOCK],
    wb: [f64; BLOCK],
}

impl Block {
    const EMPTY: Self = Self {
        len: 0,
        ia: [0; BLOCK],
        ib: [0; BLOCK],
        t: [0.0; BLOCK],
        xa: [[0.0; BLOCK]; 3],
        xb: [[0.0; BLOCK]; 3],
        pa: [[0.0; BLOCK]; 3],
        pb: [[0.0; BLOCK]; 3],
        wa: [0.0; BLOCK],
        wb: [0.0; BLOCK],
    };

    /// Loads pair `k` of the list into the next lane (the block must not be full).
    #[inline(always)]
    fn push(&mut self, k: usize, (a, b, target): (&[u32], &[u32], &[f64]), s: State<'_>) {
        let l = self.len;
        let (i, j) = (a[k], b[k]);
        (self.ia[l], self.ib[l], self.t[l]) = (i, j, target[k]);
        let (i, j) = (i as usize, j as usize);
        let (p, q, pp, pq) = (s.x[i], s.x[j], s.prev[i], s.prev[j]);
        for c in 0..3 {
            self.xa[c][l] = p[c];
            self.xb[c][l] = q[c];
            self.pa[c][l] = pp[c];
            self.pb[c][l] = pq[c];
        }
        self.wa[l] = s.w[i];
        self.wb[l] = s.w[j];
        self.len += 1;
    }

    /// The corrections of the block's pairs, lane by lane: the contact is the distance
    /// constraint C = |xa − xb| − target ≥ 0 projected with mass weights (Müller et al. 2007,
    /// eq. 9–10), then position-based Coulomb friction on the relative tangential
    /// displacement over the substep ([`Friction::correction`], Macklin et al. 2014, eq. 24).
    /// Every step is a loop over all lanes with selects instead of branches, so that it
    /// compiles to vector instructions; a pair's result does not depend on its lane or on the
    /// other pairs of the block. Lanes where neither particle can move, or the two coincide,
    /// are dropped; the others are appended to `out`.
    #[inline(always)]
    fn contacts(&self, friction: Friction, out: &mut Bins, deepest: &mut [f64; BLOCK]) {
        let (xa, xb, pa, pb) = (&self.xa, &self.xb, &self.pa, &self.pb);
        let mut d = [[0.0; BLOCK]; 3];
        let mut d2 = [0.0; BLOCK];
        for c in 0..3 {
            for l in 0..BLOCK {
                d[c][l] = xa[c][l] - xb[c][l];
                d2[l] += d[c][l] * d[c][l];
            }
        }
        let mut depth = [0.0; BLOCK];
        let mut valid = [false; BLOCK];
        let mut fa = [0.0; BLOCK];
        let mut fb = [0.0; BLOCK];
        let mut n = [[0.0; BLOCK]; 3];
        for l in 0..BLOCK {
            let dist = d2[l].sqrt();
            let sum = self.wa[l] + self.wb[l];
            valid[l] = sum > 0.0 && dist > 1e-9;
            let inv_dist = if valid[l] { 1.0 / dist } else { 0.0 };
            let inv_sum = if valid[l] { 1.0 / sum } else { 0.0 };
            depth[l] = self.t[l] - dist;
            fa[l] = self.wa[l] * inv_sum;
            fb[l] = self.wb[l] * inv_sum;
            for c in 0..3 {
                n[c][l] = d[c][l] * inv_dist;
            }
        }
        // Normal push: Δxa = +n depth wa / (wa + wb), Δxb = −n depth wb / (wa + wb).
        let mut da = [[0.0; BLOCK]; 3];
        let mut db = [[0.0; BLOCK]; 3];
        let mut dot = [0.0; BLOCK];
        let mut rel = [[0.0; BLOCK]; 3];
        for c in 0..3 {
            for l in 0..BLOCK {
                da[c][l] = n[c][l] * (depth[l] * fa[l]);
                db[c][l] = -n[c][l] * (depth[l] * fb[l]);
                rel[c][l] = (xa[c][l] + da[c][l] - pa[c][l]) - (xb[c][l] + db[c][l] - pb[c][l]);
                dot[l] += n[c][l] * rel[c][l];
            }
        }
        let mut tangential = [[0.0; BLOCK]; 3];
        let mut slip2 = [0.0; BLOCK];
        for c in 0..3 {
            for l in 0..BLOCK {
                tangential[c][l] = rel[c][l] - n[c][l] * dot[l];
                slip2[l] += tangential[c][l] * tangential[c][l];
            }
        }
        // Friction::correction as a factor on the tangential slip: 1 when static, the dynamic
        // reduction μk d / |slip| (at most 1) otherwise, 0 without slip.
        let (mu_s, mu_k) = (friction.static_coefficient, friction.dynamic_coefficient);
        let mut factor = [0.0; BLOCK];
        for l in 0..BLOCK {
            let slip = slip2[l].sqrt();
            let dynamic = (mu_k * depth[l] / slip).min(1.0);
            let f = if slip < mu_s * depth[l] { 1.0 } else { dynamic };
            factor[l] = if depth[l] <= 0.0 || slip <= 0.0 {
                0.0
            } else {
                f
            };
        }
        for c in 0..3 {
            for l in 0..BLOCK {
                let corr = tangential[c][l] * factor[l];
                da[c][l] = quantize(da[c][l] - corr * fa[l]);
                db[c][l] = quantize(db[c][l] + corr * fb[l]);
            }
        }
        for l in 0..self.len {
            if valid[l] {
                out.push(self.ia[l], [da[0][l], da[1][l], da[2][l]]);
                out.push(self.ib[l], [db[0][l], db[1][l], db[2][l]]);
                out.contacts += 1;
                deepest[l] = deepest[l].max(depth[l]);
            }
        }
    }
}

/// One particle range of [`apply`]: its index, and its positions, sums and counts.
type Range<'a> = (usize, ((&'a mut [DVec3], &'a mut [DVec3]), &'a mut [u32]));

/// Below this many contacts [`apply`] runs on one thread.
const SERIAL_CONTACTS: usize = 2048;

/// Moves every particle with a contact in `found` (per list, its corrections) by the
/// mean of its corrections, and returns the number of contacts; `sums` and `counts` (one per
/// particle, zero on entry) are scratch and zero again on return.
///
/// Particle range by particle range, each range reading only its own bin of every list, so
/// the ranges run on rayon's threads without sharing a particle.
fn apply(found: &[Bins], positions: &mut [DVec3], sums: &mut [DVec3], counts: &mut [u32]) -> usize {
    let contacts: usize = found.iter().map(|b| b.contacts).sum();
    if contacts == 0 {
        return 0;
    }
    // The ranges every list was binned by (reset for this particle count).
    let span = 1 << Bins::shift_for(positions.len());
    let range = |(k, ((xs, ss), cs)): Range<'_>| {
        let start = k * span;
        for bins in found {
            for c in &bins.bins[k] {
                let j = c.i as usize - start;
                cs[j] += 1;
                ss[j] += DVec3::from_array(c.d);
            }
        }
        for ((x, sum), count) in xs.iter_mut().zip(ss.iter_mut()).zip(cs.iter_mut()) {
            if *count > 0 {
                *x += *sum / f64::from(*count);
                *sum = DVec3::ZERO;
                *count = 0;
            }
        }
    };
    // Below SERIAL_CONTACTS the ranges are not split among threads: all run on this one.
    let serial = if contacts < SERIAL_CONTACTS {
        usize::MAX
    } else {
        1
    };
    positions
        .par_chunks_mut(span)
        .zip(sums.par_chunks_mut(span))
        .zip(counts.par_chunks_mut(span))
        .enumerate()
        .with_min_len(serial)
        .for_each(range);
    contacts
}

/// Below this many listed pairs a sweep runs on one thread.
const SERIAL_PAIRS: usize = 4096;

/// Scratch of a sweep: per list, the corrections of its touching pairs binned by particle
/// range; per particle, the exact sum of its corrections and their count (zero between
/// sweeps).
#[derive(Clone, Debug)]
pub(super) struct Sweep {
    contacts: Vec<Bins>,
    sums: Vec<DVec3>,
    counts: Vec<u32>,
}

impl Sweep {
    /// Scratch for `n` particles.
    pub(super) fn new(n: usize) -> Self {
        Self {
            contacts: Vec::new(),
            sums: vec![DVec3::ZERO; n],
            counts: vec![0; n],
        }
    }
}

impl SelfCollision {
    /// One Jacobi sweep over the touching pairs (see the module doc); returns the number of
    /// contacts and the deepest overlap (m). Call [`SelfCollision::refresh`] first.
    pub(crate) fn solve(&mut self, p: &mut Particles) -> (usize, f64) {
        let start = Instant::now();
        let lists: Vec<&PairList> = self.list.pairs.iter().chain([&self.list.extra]).collect();
        self.sweep
            .contacts
            .resize_with(lists.len(), Default::default);
        let friction = self.params.friction;
        let state = State {
            x: &p.positions,
            prev: &p.prev_positions,
            w: &p.inv_masses,
        };
        let n = p.positions.len();
        let find = |(list, out): (&&PairList, &mut Bins)| {
            out.reset(n);
            find_contacts((&list.a, &list.b, &list.target), state, friction, out)
        };
        // A few thousand pairs take less time than waking another thread: below that, the
        // lists are not split among threads.
        let total: usize = lists.iter().map(|l| l.len()).sum();
        let serial = if total < SERIAL_PAIRS { usize::MAX } else { 1 };
        let deepest = lists
            .par_iter()
            .zip(self.sweep.contacts.par_iter_mut())
            .with_min_len(serial)
            .map(find)
            .reduce(|| 0.0, f64::max);
        let found = Instant::now();
        self.tally.times.find += found - start;
        self.sweep.sums.resize(n, DVec3::ZERO);
        self.sweep.counts.resize(n, 0);
        let contacts = apply(
            &self.sweep.contacts,
            &mut p.positions,
            &mut self.sweep.sums,
            &mut self.sweep.counts,
        );
        self.tally.times.apply += found.elapsed();
        (contacts, deepest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rand;

    /// Sweeps the pairs (`a`, `b`, target) once and returns the new positions.
    fn sweep(pairs: &[(u32, u32, f64)], x: &[DVec3], prev: &[DVec3], w: &[f64]) -> Vec<DVec3> {
        let (a, b, t): (Vec<u32>, Vec<u32>, Vec<f64>) = (
            pairs.iter().map(|p| p.0).collect(),
            pairs.iter().map(|p| p.1).collect(),
            pairs.iter().map(|p| p.2).collect(),
        );
        let state = State { x, prev, w };
        let mut out = Bins::default();
        out.reset(x.len());
        find_contacts((&a, &b, &t), state, Friction::NONE, &mut out);
        let mut x = x.to_vec();
        let mut sums = vec![DVec3::ZERO; x.len()];
        let mut counts = vec![0; x.len()];
        apply(&[out], &mut x, &mut sums, &mut counts);
        assert!(sums.iter().all(|s| *s == DVec3::ZERO) && counts.iter().all(|&c| c == 0));
        x
    }

    #[test]
    fn an_overlapping_pair_is_pushed_to_its_target_by_inverse_mass() {
        // Particle 1 is three times as heavy: it moves a quarter of the overlap.
        let x = vec![DVec3::ZERO, DVec3::new(0.006, 0.0, 0.0)];
        let w = [3.0, 1.0];
        let after = sweep(&[(0, 1, 0.01)], &x, &x, &w);
        assert!((after[0].x - -0.003).abs() < 1e-12, "{after:?}");
        assert!((after[1].x - 0.007).abs() < 1e-12, "{after:?}");
        assert!((after[0].distance(after[1]) - 0.01).abs() < 1e-12);
        // Not touching: nothing moves.
        assert_eq!(sweep(&[(0, 1, 0.005)], &x, &x, &w), x);
    }

    #[test]
    fn a_particle_with_two_contacts_moves_by_their_mean() {
        // Particle 0 overlaps two pinned particles, by 2 mm on the left and 4 mm below.
        let x = vec![
            DVec3::ZERO,
            DVec3::new(-0.008, 0.0, 0.0),
            DVec3::new(0.0, -0.006, 0.0),
        ];
        let w = [1.0, 0.0, 0.0];
        let after = sweep(&[(0, 1, 0.01), (0, 2, 0.01)], &x, &x, &w);
        let expected = DVec3::new(0.002, 0.004, 0.0) / 2.0;
        assert!((after[0] - expected).length() < 1e-12, "{after:?}");
        assert_eq!(&after[1..], &x[1..], "pinned particles moved");
    }

    #[test]
    fn result_does_not_depend_on_pair_order_nor_on_the_vector_path() {
        // A clump of 40 particles, all pairs listed (many more than one lane chunk touch).
        let mut seed = 11;
        let n = 40;
        let x: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rand(&mut seed), rand(&mut seed), rand(&mut seed)) * 0.02)
            .collect();
        let prev: Vec<DVec3> = x
            .iter()
            .map(|p| *p + DVec3::new(rand(&mut seed), rand(&mut seed), 0.0) * 1e-3)
            .collect();
        let w: Vec<f64> = (0..n)
            .map(|i| {
                if i % 7 == 0 {
                    0.0
                } else {
                    1.0 + (i % 3) as f64
                }
            })
            .collect();
        let mut pairs: Vec<(u32, u32, f64)> = (0..n as u32)
            .flat_map(|a| (a + 1..n as u32).map(move |b| (a, b, 0.015)))
            .collect();
        let state = State {
            x: &x,
            prev: &prev,
            w: &w,
        };
        let friction = Friction::new(0.3, 0.2);
        let run = |pairs: &[(u32, u32, f64)]| {
            let (a, b, t): (Vec<u32>, Vec<u32>, Vec<f64>) = (
                pairs.iter().map(|p| p.0).collect(),
                pairs.iter().map(|p| p.1).collect(),
                pairs.iter().map(|p| p.2).collect(),
            );
            let mut out = Bins::default();
            out.reset(n);
            find_contacts((&a, &b, &t), state, friction, &mut out);
            let mut moved = x.clone();
            let (mut sums, mut counts) = (vec![DVec3::ZERO; n], vec![0; n]);
            let found = [out];
            apply(&found, &mut moved, &mut sums, &mut counts);
            let [out] = found;
            (moved, out)
        };
        let (first, all) = run(&pairs);
        assert!(all.contacts > 100, "only {} contacts", all.contacts);
        // The corrections of each pair alone (in a block of its own) are those it gets among
        // the others, bit for bit.
        let sorted = |bins: &Bins| -> Vec<Correction> {
            let mut c: Vec<Correction> = bins.bins.iter().flatten().copied().collect();
            c.sort_by_key(|c| (c.i, c.d.map(f64::to_bits)));
            c
        };
        let mut alone = Vec::new();
        for &pair in &pairs {
            let found = run(&[pair]).1;
            assert!(found.contacts <= 1);
            alone.extend(sorted(&found));
        }
        alone.sort_by_key(|c| (c.i, c.d.map(f64::to_bits)));
        assert_eq!(alone, sorted(&all));
        // Each bin holds its own particle range, and there are several.
        assert!(all.bins.len() > 1);
        for (k, bin) in all.bins.iter().enumerate() {
            assert!(bin.iter().all(|c| (c.i >> all.shift) as usize == k));
        }
        // Reversed and shuffled lists, split in two: the same bits.
        pairs.reverse();
        assert_eq!(run(&pairs).0, first, "reversed");
        let mut k = 5;
        for i in (1..pairs.len()).rev() {
            k = (k * 1_103_515_245 + 12_345) % 2_147_483_648;
            pairs.swap(i, k % (i + 1));
        }
        assert_eq!(run(&pairs).0, first, "shuffled");
        // It is not a trivial sweep: particles moved.
        assert!(first.iter().zip(&x).filter(|(a, b)| a != b).count() > n / 2);
    }

    #[test]
    fn quantized_corrections_sum_exactly_in_any_order() {
        let mut seed = 5;
        let values: Vec<f64> = (0..1000)
            .map(|_| quantize(rand(&mut seed) * 0.01))
            .collect();
        let forward = values.iter().fold(0.0, |s, v| s + v);
        let backward = values.iter().rev().fold(0.0, |s, v| s + v);
        let strided = (0..7)
            .map(|k| values.iter().skip(k).step_by(7).fold(0.0, |s, v| s + v))
            .fold(0.0, |s, v| s + v);
        assert_eq!(forward.to_bits(), backward.to_bits());
        assert_eq!(forward.to_bits(), strided.to_bits());
        // Unquantized, the same sums differ in the last bits (the test can fail).
        let raw: Vec<f64> = (0..1000).map(|_| rand(&mut seed) * 0.01).collect();
        let f = raw.iter().fold(0.0, |s, v| s + v);
        let b = raw.iter().rev().fold(0.0, |s, v| s + v);
        assert_ne!(f.to_bits(), b.to_bits());
        // Quantization moves a value by at most half a quantum.
        let v = 0.123_456_789_012_345;
        assert!((quantize(v) - v).abs() <= 0.5 / (1u64 << 40) as f64);
    }
}
