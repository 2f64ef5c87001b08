//! Domain decomposition of the distance constraints for parallel, SIMD Gauss–Seidel.
//!
//! Particles are cut into contiguous index ranges of `size` particles (domains). A distance
//! constraint whose two particles lie in one domain is *interior*: each domain keeps its own
//! struct-of-arrays copy of its particles and projects its interior constraints colour by colour,
//! eight at a time, without touching any other domain — so domains run on any threads, in any
//! order, with no synchronisation. Constraints across domains (*links*, a few per cent on
//! meshes with local particle order) are projected in a fork–join tree over the domains, each
//! link once both its domains are done (see [`fork`]). The split
//! depends on `size` and the mesh only, never on the thread count: results are bit-identical
//! for 1, 2 or 64 threads.
//!
//! Inside a domain, constraints fall into conflict-free sets (see `Domain::order`), sorted by
//! particle index, so that on structured meshes eight consecutive constraints usually touch
//! eight consecutive particles (`Layout::Contiguous`, e.g. a row of vertical grid edges) or a
//! window of 15–31 consecutive ones (`Layout::Paired`, `Quad`, `Spaced`, `Strided`): those
//! chunks load and store with unit stride, and anything else is gathered lane by lane.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use std::ops::Range;

use glam::DVec3;
use multiversion::multiversion;
use rayon::prelude::*;

use crate::coloring::color;
use crate::constraints::lanes::{self, Coef, Coefs, Ends, LANES};
use crate::constraints::{Block, Distance, Rule};
use crate::forces::Forces;
use crate::params::FamilyParams;

/// How the eight constraints of a chunk reach their particles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Layout {
    /// p = p₀ + l and q = q₀ + l: two unit-stride loads per axis.
    Contiguous,
    /// p = p₀ + 2l and q = p + 1: one unit-stride load of 16 particles, de-interleaved.
    Paired,
    /// p = p₀ + (0, 1, 4, 5, 8, 9, 12, 13) and q = p + 2 (every other pair of a row's
    /// two-apart bending pairs): one unit-stride load of 16 particles, permuted.
    Quad,
    /// p = p₀ + 4l and q = p + 2 (two-apart bending pairs at every other vertex): one
    /// unit-stride load of 31 particles, permuted.
    Spaced,
    /// p = p₀ + 2l and q = q₀ + 2l with the two 15-particle windows apart: two unit-stride
    /// loads, even slots taken (a diagonal family on alternating-diagonal grids).
    Strided,
    /// Anything else: one load per lane.
    Gathered,
}

/// How a solver's distance constraints are laid out for the parallel SIMD solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DomainStats {
    /// Number of domains.
    pub domains: usize,
    /// Particles per domain.
    pub domain_size: usize,
    /// Constraints across domains, solved serially after them.
    pub links: usize,
    /// Interior constraints in chunks of 8 with unit-stride ends.
    pub contiguous: usize,
    /// Interior constraints in chunks of 8 loaded from 16-particle windows and permuted.
    pub strided: usize,
    /// Interior constraints in chunks of 8 loaded lane by lane.
    pub gathered: usize,
    /// Interior constraints solved one at a time (the tail of each colour).
    pub remainder: usize,
}

/// A full chunk of [`LANES`] constraints.
#[derive(Clone, Copy, Debug)]
struct Chunk {
    start: usize,
    layout: Layout,
    /// All lanes share one parameter group.
    uniform: bool,
}

/// Distance constraints as struct-of-arrays.
#[derive(Clone, Debug, Default)]
struct Pairs {
    p: Vec<u32>,
    q: Vec<u32>,
    rest: Vec<f64>,
    group: Vec<u32>,
    lambda: Vec<f64>,
}

impl Pairs {
    fn push(&mut self, p: u32, q: u32, rest: f64, group: u32) {
        self.p.push(p);
        self.q.push(q);
        self.rest.push(rest);
        self.group.push(group);
        self.lambda.push(0.0);
    }
}

/// One domain: its particles (struct-of-arrays, local indices) and interior constraints.
#[derive(Clone, Debug, Default)]
pub(crate) struct Domain {
    /// Global index of the first particle.
    start: usize,
    /// Positions per axis (m).
    x: [Vec<f64>; 3],
    /// Positions at the start of the substep per axis (m).
    prev: [Vec<f64>; 3],
    /// Velocities per axis (m/s).
    v: [Vec<f64>; 3],
    /// Inverse masses (1/kg).
    w: Vec<f64>,
    /// Interior constraints in local indices, sorted by colour, group and particle.
    pairs: Pairs,
    /// Range of each colour in `pairs`.
    colours: Vec<Range<usize>>,
    /// Full chunks of every colour, in order.
    chunks: Vec<Chunk>,
    /// For each colour: its range in `chunks` and where its scalar remainder starts.
    plan: Vec<(Range<usize>, usize)>,
}

/// A domain's share of the global particle arrays.
pub(crate) struct AosChunk<'a> {
    /// Positions.
    pub x: &'a [DVec3],
    /// Velocities.
    pub v: &'a [DVec3],
    /// Inverse masses.
    pub w: &'a [f64],
}

/// Per-substep inputs of the fused integration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Integration<'a> {
    /// Substep length (s).
    pub h: f64,
    /// External forces (gravity and linear wind drag; no aerodynamics).
    pub forces: &'a Forces,
    /// Kinematic pins as (global particle, position at the substep's end).
    pub pins: &'a [(usize, DVec3)],
}

impl Domain {
    fn len(&self) -> usize {
        self.w.len()
    }

    fn resize(&mut self, n: usize) {
        for a in 0..3 {
            self.x[a].resize(n, 0.0);
            self.prev[a].resize(n, 0.0);
            self.v[a].resize(n, 0.0);
        }
        self.w.resize(n, 0.0);
    }

    /// Copies positions, velocities and inverse masses in from the global arrays.
    pub fn load(&mut self, aos: &AosChunk<'_>) {
        for (i, (x, v)) in aos.x.iter().zip(aos.v).enumerate() {
            for a in 0..3 {
                self.x[a][i] = x[a];
                self.v[a][i] = v[a];
            }
        }
        self.w.copy_from_slice(aos.w);
    }

    /// Copies positions (and, when `prev` is given, previous positions) in.
    fn load_positions(&mut self, x: &[DVec3], prev: Option<&[DVec3]>, w: &[f64]) {
        for (i, p) in x.iter().enumerate() {
            for a in 0..3 {
                self.x[a][i] = p[a];
            }
        }
        if let Some(prev) = prev {
            for (i, p) in prev.iter().enumerate() {
                for a in 0..3 {
                    self.prev[a][i] = p[a];
                }
            }
        }
        self.w.copy_from_slice(w);
    }

    /// Copies positions back out.
    fn store_positions(&self, x: &mut [DVec3]) {
        for (i, p) in x.iter_mut().enumerate() {
            *p = DVec3::new(self.x[0][i], self.x[1][i], self.x[2][i]);
        }
    }

    /// Copies positions, previous positions and velocities back out.
    pub fn store(&self, x: &mut [DVec3], prev: &mut [DVec3], v: &mut [DVec3]) {
        for i in 0..self.len() {
            x[i] = DVec3::new(self.x[0][i], self.x[1][i], self.x[2][i]);
            prev[i] = DVec3::new(self.prev[0][i], self.prev[1][i], self.prev[2][i]);
            v[i] = DVec3::new(self.v[0][i], self.v[1][i], self.v[2][i]);
        }
    }

    /// The PBD velocity update v = (x − x_prev)/h, then global damping v ← v e^(−c h) of free
    /// particles when `keep` is given — the same arithmetic as the solver's general loop.
    pub fn finish_velocities(&mut self, finish: Finish) {
        let w = &self.w[..];
        for a in 0..3 {
            end_velocities(&self.x[a], &self.prev[a], &mut self.v[a], w, finish);
        }
    }

    /// Ends the previous substep when `finish` is given (v = (x − x_prev)/h, then damping
    /// v ← v·keep of free particles), then predicts with semi-implicit Euler, a = g + c_d (v_wind
    /// − v), and applies the pins — the same arithmetic, particle by particle, as the solver's
    /// general loop. Clears the multipliers when `lambda`.
    pub fn integrate(&mut self, step: &Integration<'_>, finish: Option<Finish>, lambda: bool) {
        advance(self, step, finish);
        let range = self.start..self.start + self.len();
        for &(i, p) in step.pins {
            if range.contains(&i) {
                for a in 0..3 {
                    self.x[a][i - self.start] = p[a];
                }
            }
        }
        if lambda {
            self.pairs.lambda.fill(0.0);
        }
    }

    /// One Gauss–Seidel sweep over the interior constraints, colour by colour.
    pub fn project(&mut self, coef: &[Coef], mode: Mode) {
        sweep(self, coef, mode);
    }
}

/// Which optional terms a sweep evaluates; both off gives the same bits as both on with
/// γ = 0 and α̃ = 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Mode {
    /// Some group has XPBD damping (γ > 0): read previous positions.
    pub damped: bool,
    /// Some group has compliance (α̃ > 0): keep multipliers.
    pub lambda: bool,
}

/// How a fused substep ends the previous one: 1/h and the damping factor, if any.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Finish {
    /// 1/h (1/s).
    pub inv_h: f64,
    /// Velocity factor e^(−c h) of global damping, if any.
    pub keep: Option<f64>,
}

/// One axis of the PBD velocity update v = (x − x_prev)/h, then global damping v ← v·keep of
/// free particles — the solver's general loop does the same arithmetic.
#[inline(always)]
fn end_velocities(x: &[f64], prev: &[f64], v: &mut [f64], w: &[f64], finish: Finish) {
    let (x, prev, v) = (&x[..w.len()], &prev[..w.len()], &mut v[..w.len()]);
    for i in 0..w.len() {
        v[i] = (x[i] - prev[i]) * finish.inv_h;
    }
    if let Some(keep) = finish.keep {
        for i in 0..w.len() {
            v[i] = if w[i] > 0.0 { v[i] * keep } else { v[i] };
        }
    }
}

/// The per-particle part of [`Domain::integrate`], compiled like [`sweep`].
#[multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512dq+avx2+fma",
    "x86_64+avx2+fma",
    "aarch64+neon"
))]
fn advance<'a>(dom: &mut Domain, step: &Integration<'a>, finish: Option<Finish>) {
    let h = step.h;
    let f = step.forces;
    let w = &dom.w[..];
    for a in 0..3 {
        let (g, wv, drag) = (f.gravity[a], f.wind.velocity[a], f.wind.drag);
        let (x, v, prev) = (&mut dom.x[a][..], &mut dom.v[a][..], &mut dom.prev[a][..]);
        let (x, v, prev) = (&mut x[..w.len()], &mut v[..w.len()], &mut prev[..w.len()]);
        if let Some(finish) = finish {
            end_velocities(x, prev, v, w, finish);
        }
        for i in 0..w.len() {
            prev[i] = x[i];
            let acc = g + drag * (wv - v[i]);
            let vi = v[i] + acc * h;
            let xi = x[i] + vi * h;
            let free = w[i] > 0.0;
            v[i] = if free { vi } else { v[i] };
            x[i] = if free { xi } else { x[i] };
        }
    }
}

/// [`Domain::project`], compiled for the widest vector unit the CPU has (picked at run time;
/// every version does the same IEEE operations, so results do not depend on the CPU).
#[multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512dq+avx2+fma",
    "x86_64+avx2+fma",
    "aarch64+neon"
))]
fn sweep(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    match (mode.damped, mode.lambda) {
        (false, false) => sweep_with::<false, false>(dom, coef),
        (false, true) => sweep_with::<false, true>(dom, coef),
        (true, false) => sweep_with::<true, false>(dom, coef),
        (true, true) => sweep_with::<true, true>(dom, coef),
    }
}

#[inline(always)]
fn sweep_with<const DAMPED: bool, const LAMBDA: bool>(dom: &mut Domain, coef: &[Coef]) {
    let Domain {
        x,
        prev,
        w,
        pairs,
        chunks,
        plan,
        colours,
        ..
    } = dom;
    for (c, (chunk_range, tail)) in plan.iter().enumerate() {
        for chunk in &chunks[chunk_range.clone()] {
            project_chunk::<DAMPED, LAMBDA>(chunk, pairs, x, prev, w, coef);
        }
        for k in *tail..colours[c].end {
            let (p, q) = (pairs.p[k] as usize, pairs.q[k] as usize);
            let mut lambda = if LAMBDA { pairs.lambda[k] } else { 0.0 };
            let (xp, xq) = project_one::<DAMPED>(
                End::of(x, prev, w, p),
                End::of(x, prev, w, q),
                pairs.rest[k],
                coef[pairs.group[k] as usize],
                &mut lambda,
            );
            if LAMBDA {
                pairs.lambda[k] = lambda;
            }
            for a in 0..3 {
                x[a][p] = xp[a];
                x[a][q] = xq[a];
            }
        }
    }
}

/// Loads one end of a chunk: `idx` gives each lane's particle when gathered.
#[inline(always)]
fn gather(src: &[f64], idx: &[u32]) -> [f64; LANES] {
    std::array::from_fn(|l| src[idx[l] as usize])
}

#[inline(always)]
fn scatter(dst: &mut [f64], idx: &[u32], val: &[f64; LANES]) {
    for l in 0..LANES {
        dst[idx[l] as usize] = val[l];
    }
}

/// Both ends of a chunk from one array (positions, previous positions or inverse masses).
#[inline(always)]
fn load_ends<const LAYOUT: u8>(src: &[f64], p: &[u32], q: &[u32]) -> ([f64; LANES], [f64; LANES]) {
    match layout_of(LAYOUT) {
        Layout::Contiguous => {
            let (p0, q0) = (p[0] as usize, q[0] as usize);
            let mut a = [0.0; LANES];
            let mut b = [0.0; LANES];
            a.copy_from_slice(&src[p0..p0 + LANES]);
            b.copy_from_slice(&src[q0..q0 + LANES]);
            (a, b)
        }
        Layout::Paired => {
            let p0 = p[0] as usize;
            let s = &src[p0..p0 + 2 * LANES];
            (
                std::array::from_fn(|l| s[2 * l]),
                std::array::from_fn(|l| s[2 * l + 1]),
            )
        }
        Layout::Quad => {
            let p0 = p[0] as usize;
            let s = &src[p0..p0 + 2 * LANES];
            (
                std::array::from_fn(|l| s[QUAD[l]]),
                std::array::from_fn(|l| s[QUAD[l] + 2]),
            )
        }
        Layout::Spaced => {
            let p0 = p[0] as usize;
            let s = &src[p0..p0 + SPACED];
            (
                std::array::from_fn(|l| s[4 * l]),
                std::array::from_fn(|l| s[4 * l + 2]),
            )
        }
        Layout::Strided => {
            let (p0, q0) = (p[0] as usize, q[0] as usize);
            let (sp, sq) = (&src[p0..p0 + STRIDED], &src[q0..q0 + STRIDED]);
            (
                std::array::from_fn(|l| sp[2 * l]),
                std::array::from_fn(|l| sq[2 * l]),
            )
        }
        Layout::Gathered => (gather(src, p), gather(src, q)),
    }
}

/// Offsets of the first ends in a [`Layout::Quad`] chunk.
const QUAD: [usize; LANES] = [0, 1, 4, 5, 8, 9, 12, 13];

/// Window of a [`Layout::Spaced`] chunk: first ends at 0, 4, …, 28, second ends 2 further.
const SPACED: usize = 4 * LANES - 1;

/// Window of a [`Layout::Strided`] end: lanes at even offsets 0..=14.
const STRIDED: usize = 2 * LANES - 1;

#[inline(always)]
fn store_ends<const LAYOUT: u8>(
    dst: &mut [f64],
    p: &[u32],
    q: &[u32],
    a: &[f64; LANES],
    b: &[f64; LANES],
) {
    match layout_of(LAYOUT) {
        Layout::Contiguous => {
            let (p0, q0) = (p[0] as usize, q[0] as usize);
            dst[p0..p0 + LANES].copy_from_slice(a);
            dst[q0..q0 + LANES].copy_from_slice(b);
        }
        Layout::Paired => {
            let p0 = p[0] as usize;
            let s = &mut dst[p0..p0 + 2 * LANES];
            for l in 0..LANES {
                s[2 * l] = a[l];
                s[2 * l + 1] = b[l];
            }
        }
        Layout::Quad => {
            let p0 = p[0] as usize;
            let s = &mut dst[p0..p0 + 2 * LANES];
            for l in 0..LANES {
                s[QUAD[l]] = a[l];
                s[QUAD[l] + 2] = b[l];
            }
        }
        Layout::Spaced => {
            // Read, replace the chunk's slots, write back: the other slots (odd offsets) are
            // particles no lane of this chunk touches, so they keep their values.
            let p0 = p[0] as usize;
            let mut win = [0.0; SPACED];
            win.copy_from_slice(&dst[p0..p0 + SPACED]);
            for l in 0..LANES {
                win[4 * l] = a[l];
                win[4 * l + 2] = b[l];
            }
            dst[p0..p0 + SPACED].copy_from_slice(&win);
        }
        Layout::Strided => {
            let (p0, q0) = (p[0] as usize, q[0] as usize);
            for (start, v) in [(p0, a), (q0, b)] {
                // Read, replace the even slots, write the window back: the odd slots are
                // particles no other lane of this chunk touches, so they keep their values.
                let mut win = [0.0; STRIDED];
                win.copy_from_slice(&dst[start..start + STRIDED]);
                for l in 0..LANES {
                    win[2 * l] = v[l];
                }
                dst[start..start + STRIDED].copy_from_slice(&win);
            }
        }
        Layout::Gathered => {
            scatter(dst, p, a);
            scatter(dst, q, b);
        }
    }
}

/// The layout a `const` layout number stands for (const generics take no enums on stable).
#[inline(always)]
const fn layout_of(n: u8) -> Layout {
    match n {
        0 => Layout::Contiguous,
        1 => Layout::Paired,
        2 => Layout::Quad,
        3 => Layout::Strided,
        4 => Layout::Spaced,
        _ => Layout::Gathered,
    }
}

#[inline(always)]
fn project_chunk<const DAMPED: bool, const LAMBDA: bool>(
    chunk: &Chunk,
    pairs: &mut Pairs,
    x: &mut [Vec<f64>; 3],
    prev: &[Vec<f64>; 3],
    w: &[f64],
    coef: &[Coef],
) {
    // One specialised body per layout keeps every lane array in registers (a layout
    // switch inside the per-axis loops made the compiler spill them and reload with
    // masked loads, which cannot forward from the stores).
    match chunk.layout {
        Layout::Contiguous => project_laid_out::<DAMPED, LAMBDA, 0>(chunk, pairs, x, prev, w, coef),
        Layout::Paired => project_laid_out::<DAMPED, LAMBDA, 1>(chunk, pairs, x, prev, w, coef),
        Layout::Quad => project_laid_out::<DAMPED, LAMBDA, 2>(chunk, pairs, x, prev, w, coef),
        Layout::Strided => project_laid_out::<DAMPED, LAMBDA, 3>(chunk, pairs, x, prev, w, coef),
        Layout::Spaced => project_laid_out::<DAMPED, LAMBDA, 4>(chunk, pairs, x, prev, w, coef),
        Layout::Gathered => project_laid_out::<DAMPED, LAMBDA, 5>(chunk, pairs, x, prev, w, coef),
    }
}

#[inline(always)]
fn project_laid_out<const DAMPED: bool, const LAMBDA: bool, const LAYOUT: u8>(
    chunk: &Chunk,
    pairs: &mut Pairs,
    x: &mut [Vec<f64>; 3],
    prev: &[Vec<f64>; 3],
    w: &[f64],
    coef: &[Coef],
) {
    let r = chunk.start..chunk.start + LANES;
    let (p, q) = (&pairs.p[r.clone()], &pairs.q[r.clone()]);
    let mut e = Ends {
        p: [[0.0; LANES]; 3],
        q: [[0.0; LANES]; 3],
    };
    let [x0, x1, x2] = x;
    (e.p[0], e.q[0]) = load_ends::<LAYOUT>(x0, p, q);
    (e.p[1], e.q[1]) = load_ends::<LAYOUT>(x1, p, q);
    (e.p[2], e.q[2]) = load_ends::<LAYOUT>(x2, p, q);
    let pr = if DAMPED {
        let mut pr = e;
        for a in 0..3 {
            (pr.p[a], pr.q[a]) = load_ends::<LAYOUT>(&prev[a], p, q);
        }
        pr
    } else {
        e
    };
    let (wp, wq) = load_ends::<LAYOUT>(w, p, q);
    let mut rest = [0.0; LANES];
    rest.copy_from_slice(&pairs.rest[r.clone()]);
    let groups = &pairs.group[r.clone()];
    let k = if chunk.uniform {
        Coefs::splat(coef[groups[0] as usize])
    } else {
        Coefs::from_fn(|l| coef[groups[l] as usize])
    };
    let mut lambda = [0.0; LANES];
    if LAMBDA {
        lambda.copy_from_slice(&pairs.lambda[r.clone()]);
    }
    lanes::project::<LANES, DAMPED>(&mut e, &pr, &wp, &wq, &rest, &k, &mut lambda);
    if LAMBDA {
        pairs.lambda[r].copy_from_slice(&lambda);
    }
    store_ends::<LAYOUT>(x0, p, q, &e.p[0], &e.q[0]);
    store_ends::<LAYOUT>(x1, p, q, &e.p[1], &e.q[1]);
    store_ends::<LAYOUT>(x2, p, q, &e.p[2], &e.q[2]);
}

/// Constraints whose particles lie in different domains, for one node of the fork–join tree.
#[derive(Clone, Debug, Default)]
struct LinkSet {
    /// Domain and local index of each end.
    ends: Vec<[(u32, u32); 2]>,
    rest: Vec<f64>,
    group: Vec<u32>,
    lambda: Vec<f64>,
}

/// The distance constraints cut into domains, plus the links between them.
#[derive(Clone, Debug, Default)]
pub(crate) struct Domains {
    /// Particles per domain (the last may hold fewer).
    size: usize,
    /// The domains, in particle order.
    list: Vec<Domain>,
    /// Links of each internal node of the fork–join tree over the domains, in preorder (a
    /// node, then its left subtree, then its right one, so every subtree is one sub-slice).
    links: Vec<LinkSet>,
    /// Multiplier-step coefficients per parameter group, refreshed every frame.
    coef: Vec<Coef>,
    /// Which optional terms the coefficients need.
    mode: Mode,
}

impl Domains {
    /// Cuts `block` (coloured distance constraints over `n` particles) into domains of `size`.
    pub fn new(block: &Block<2, Distance>, n: usize, size: usize) -> Self {
        let size = size.clamp(LANES, n.max(LANES)).next_multiple_of(LANES);
        let count = n.div_ceil(size).max(1);
        let mut list: Vec<Domain> = (0..count)
            .map(|d| {
                let mut dom = Domain {
                    start: d * size,
                    ..Domain::default()
                };
                dom.resize(size.min(n - (d * size).min(n)));
                dom
            })
            .collect();
        let mut links = vec![LinkSet::default(); count - 1];
        let locate = |i: u32| ((i as usize / size) as u32, (i as usize % size) as u32);
        let mut interior: Vec<Vec<Interior>> = vec![Vec::new(); count];
        for k in block.colors.iter().flat_map(|c| c.clone()) {
            let [p, q] = block.particles[k];
            let (dp, dq) = (locate(p), locate(q));
            let (rest, group) = (block.shapes[k].rest, block.group[k]);
            if dp.0 == dq.0 {
                // C and its corrections are symmetric in the two ends: store p < q.
                let (p, q) = (dp.1.min(dq.1), dp.1.max(dq.1));
                interior[dp.0 as usize].push(Interior { p, q, rest, group });
            } else {
                let set = &mut links[tree_node(dp.0 as usize, dq.0 as usize, count)];
                set.ends.push([dp, dq]);
                set.rest.push(rest);
                set.group.push(group);
                set.lambda.push(0.0);
            }
        }
        for (dom, cons) in list.iter_mut().zip(interior) {
            dom.order(cons);
        }
        Self {
            size,
            list,
            links,
            coef: Vec::new(),
            mode: Mode::default(),
        }
    }

    /// How the distance constraints were laid out.
    pub fn stats(&self) -> DomainStats {
        let mut s = DomainStats {
            domains: self.list.len(),
            domain_size: self.size,
            links: self.links.iter().map(|l| l.rest.len()).sum(),
            ..DomainStats::default()
        };
        for d in &self.list {
            for c in &d.chunks {
                match c.layout {
                    Layout::Contiguous => s.contiguous += LANES,
                    Layout::Paired | Layout::Quad | Layout::Spaced | Layout::Strided => {
                        s.strided += LANES
                    }
                    Layout::Gathered => s.gathered += LANES,
                }
            }
            for ((_, tail), colour) in d.plan.iter().zip(&d.colours) {
                s.remainder += colour.end - tail;
            }
        }
        s
    }

    /// Which optional terms the current coefficients need.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Sets the per-group coefficients for `rule` (with every group's parameters).
    pub fn prepare(&mut self, params: &[FamilyParams], rule: Rule) {
        self.coef.clear();
        self.mode = Mode::default();
        for p in params {
            let c = match (p.enabled, rule) {
                (false, _) => Coef {
                    k: 0.0,
                    alpha: 1.0,
                    gamma: 0.0,
                },
                (true, Rule::Xpbd { h }) => Coef {
                    k: 1.0,
                    alpha: p.compliance / (h * h),
                    gamma: p.compliance * p.damping / h,
                },
                (true, Rule::Pbd) => Coef {
                    k: p.pbd_stiffness,
                    alpha: 0.0,
                    gamma: 0.0,
                },
            };
            if p.enabled {
                self.mode.damped |= c.gamma > 0.0;
                self.mode.lambda |= c.alpha > 0.0;
            }
            self.coef.push(c);
        }
    }

    /// Projects every domain and link once; coefficients from [`Self::prepare`].
    pub fn project(&mut self) {
        self.project_with(|_, _| {});
    }

    /// Runs `before` on every domain, then projects every domain and link once, all in one
    /// fork–join tree over the domains (see [`fork`]).
    pub fn project_after<F>(&mut self, x: &[DVec3], v: &[DVec3], w: &[f64], before: F)
    where
        F: Fn(&mut Domain, &AosChunk<'_>) + Sync,
    {
        let size = self.size;
        let n = x.len();
        self.project_with(|d, index| {
            let r = index * size..((index + 1) * size).min(n);
            let aos = AosChunk {
                x: &x[r.clone()],
                v: &v[r.clone()],
                w: &w[r],
            };
            before(d, &aos);
        });
    }

    fn project_with<F>(&mut self, before: F)
    where
        F: Fn(&mut Domain, usize) + Sync,
    {
        let Self {
            list,
            links,
            coef,
            mode,
            ..
        } = self;
        let job = Job {
            before: &before,
            coef,
            mode: *mode,
        };
        fork(list, 0, links, &job);
    }

    /// Clears the link multipliers (the domains clear theirs when integrating).
    pub fn reset_link_multipliers(&mut self) {
        for set in &mut self.links {
            set.lambda.fill(0.0);
        }
    }

    /// One sweep on global arrays: copy in, project domains and links, copy positions out.
    /// `prev` is needed only for XPBD damping. Clears every multiplier first when `fresh`.
    pub fn project_global(&mut self, x: &mut [DVec3], prev: &[DVec3], w: &[f64], fresh: bool) {
        let size = self.size;
        let damped = self.mode.damped;
        self.list
            .par_iter_mut()
            .zip(x.par_chunks(size))
            .zip(prev.par_chunks(size))
            .zip(w.par_chunks(size))
            .for_each(|(((d, x), prev), w)| {
                d.load_positions(x, damped.then_some(prev), w);
                if fresh {
                    d.pairs.lambda.fill(0.0);
                }
            });
        if fresh {
            self.reset_link_multipliers();
        }
        self.project();
        self.list
            .par_iter_mut()
            .zip(x.par_chunks_mut(size))
            .for_each(|(d, x)| d.store_positions(x));
    }

    /// Ends a fused frame: velocity update and damping, then copies the state back out.
    pub fn finish(
        &mut self,
        inv_h: f64,
        keep: Option<f64>,
        x: &mut [DVec3],
        prev: &mut [DVec3],
        v: &mut [DVec3],
    ) {
        let size = self.size;
        self.list
            .par_iter_mut()
            .zip(x.par_chunks_mut(size))
            .zip(prev.par_chunks_mut(size))
            .zip(v.par_chunks_mut(size))
            .for_each(|(((d, x), prev), v)| {
                d.finish_velocities(Finish { inv_h, keep });
                d.store(x, prev, v);
            });
    }
}

/// The preorder index of the internal node of the fork–join tree over `count` domains that
/// first separates domains `a` and `b` (the node where a link between them is solved).
fn tree_node(a: usize, b: usize, count: usize) -> usize {
    let (a, b) = (a.min(b), a.max(b));
    let (mut lo, mut hi, mut node) = (0, count, 0);
    loop {
        let mid = lo + (hi - lo) / 2;
        if a < mid && b >= mid {
            return node;
        }
        if b < mid {
            node += 1;
            hi = mid;
        } else {
            node += mid - lo;
            lo = mid;
        }
    }
}

/// What every leaf and node of the fork–join tree needs.
struct Job<'a, F> {
    before: &'a F,
    coef: &'a [Coef],
    mode: Mode,
}

/// Solves `doms` (domains `first..`) with their `links` (the subtree's internal nodes, in
/// preorder): the two halves in parallel (`rayon::join`), then the links between them.
///
/// A leaf runs `before` and its own interior constraints. The tree's shape depends only on
/// the number of domains, so the order of every link relative to every domain is fixed: the
/// result does not depend on the thread count. Links are solved where both their domains are
/// finished, so most of them run in parallel too; only the root's are solved alone.
fn fork<F>(doms: &mut [Domain], first: usize, links: &mut [LinkSet], job: &Job<'_, F>)
where
    F: Fn(&mut Domain, usize) + Sync,
{
    if let [d] = doms {
        (job.before)(d, first);
        d.project(job.coef, job.mode);
        return;
    }
    let mid = doms.len() / 2;
    let Some((own, below)) = links.split_first_mut() else {
        return;
    };
    let (left_links, right_links) = below.split_at_mut(mid - 1);
    let (left, right) = doms.split_at_mut(mid);
    rayon::join(
        || fork(left, first, left_links, job),
        || fork(right, first + mid, right_links, job),
    );
    if job.mode.damped {
        project_links::<true>(doms, first, own, job.coef);
    } else {
        project_links::<false>(doms, first, own, job.coef);
    }
}

/// Projects one node's links serially, in colour order.
fn project_links<const DAMPED: bool>(
    list: &mut [Domain],
    first: usize,
    links: &mut LinkSet,
    coef: &[Coef],
) {
    for k in 0..links.rest.len() {
        let [(dp, ip), (dq, iq)] = links.ends[k];
        let (dp, ip) = (dp as usize - first, ip as usize);
        let (dq, iq) = (dq as usize - first, iq as usize);
        let end = |d: &Domain, i| End::of(&d.x, &d.prev, &d.w, i);
        let (xp, xq) = project_one::<DAMPED>(
            end(&list[dp], ip),
            end(&list[dq], iq),
            links.rest[k],
            coef[links.group[k] as usize],
            &mut links.lambda[k],
        );
        for a in 0..3 {
            list[dp].x[a][ip] = xp[a];
            list[dq].x[a][iq] = xq[a];
        }
    }
}

/// One end of a single constraint: position, previous position and inverse mass.
#[derive(Clone, Copy, Debug)]
struct End {
    x: [f64; 3],
    prev: [f64; 3],
    w: f64,
}

impl End {
    /// Particle `i` of struct-of-arrays state.
    #[inline(always)]
    fn of(x: &[Vec<f64>; 3], prev: &[Vec<f64>; 3], w: &[f64], i: usize) -> Self {
        Self {
            x: [x[0][i], x[1][i], x[2][i]],
            prev: [prev[0][i], prev[1][i], prev[2][i]],
            w: w[i],
        }
    }
}

/// Projects one constraint with the one-lane kernel (a colour's remainder, or a link);
/// returns the two new positions. `prev` is read only when `DAMPED`.
#[inline(always)]
fn project_one<const DAMPED: bool>(
    p: End,
    q: End,
    rest: f64,
    coef: Coef,
    lambda: &mut f64,
) -> ([f64; 3], [f64; 3]) {
    let mut e = Ends {
        p: p.x.map(|v| [v]),
        q: q.x.map(|v| [v]),
    };
    let pr = Ends {
        p: p.prev.map(|v| [v]),
        q: q.prev.map(|v| [v]),
    };
    let mut l = [*lambda];
    lanes::project::<1, DAMPED>(
        &mut e,
        &pr,
        &[p.w],
        &[q.w],
        &[rest],
        &Coefs::splat(coef),
        &mut l,
    );
    *lambda = l[0];
    (e.p.map(|[v]| v), e.q.map(|[v]| v))
}

/// An interior constraint before ordering (local indices, p < q).
#[derive(Clone, Copy, Debug)]
struct Interior {
    p: u32,
    q: u32,
    rest: f64,
    group: u32,
}

/// Classes (group, q − p) with at least this many constraints get the structured order.
const MIN_CLASS: usize = 8 * LANES;

impl Domain {
    /// Orders the interior constraints into independent sets ("colours") that chunk well.
    ///
    /// Constraints of one parameter group and one index offset d = q − p (a grid's rows,
    /// columns or diagonals) split into two sets by the parity of ⌊p/d⌋: inside a set no two
    /// constraints share a particle (p and p' = p ± d never have the same parity of ⌊p/d⌋), and
    /// sorted by p their ends mostly run with unit stride (d ≥ 8) or pairwise (d = 1). Smaller
    /// classes (irregular meshes) are coloured greedily. The order is a valid Gauss–Seidel
    /// order and depends only on the mesh and the domain size.
    fn order(&mut self, mut cons: Vec<Interior>) {
        cons.sort_by_key(|c| (c.group, c.q - c.p, c.p));
        let mut rest: Vec<Interior> = Vec::new();
        let mut sets: Vec<Vec<Interior>> = Vec::new();
        for class in cons.chunk_by(|a, b| (a.group, a.q - a.p) == (b.group, b.q - b.p)) {
            if class.len() < MIN_CLASS {
                rest.extend_from_slice(class);
                continue;
            }
            let d = class[0].q - class[0].p;
            // A repeated pair (a mesh may give the same bending pair twice) would share both
            // particles with its twin: the repeats go to the greedy colouring.
            let mut even = Vec::new();
            let mut odd = Vec::new();
            for (k, c) in class.iter().enumerate() {
                if k > 0 && class[k - 1].p == c.p {
                    rest.push(*c);
                } else if (c.p / d) % 2 == 0 {
                    even.push(*c);
                } else {
                    odd.push(*c);
                }
            }
            sets.extend([even, odd].into_iter().filter(|s| !s.is_empty()));
        }
        let pairs: Vec<[u32; 2]> = rest.iter().map(|c| [c.p, c.q]).collect();
        let colours = color(&pairs, &vec![true; self.len()]);
        let mut by_colour: Vec<Vec<Interior>> = Vec::new();
        for (c, colour) in rest.iter().zip(colours) {
            let colour = colour as usize;
            if by_colour.len() <= colour {
                by_colour.resize(colour + 1, Vec::new());
            }
            by_colour[colour].push(*c);
        }
        sets.extend(by_colour);
        for set in sets {
            let begin = self.pairs.p.len();
            for c in set {
                self.pairs.push(c.p, c.q, c.rest, c.group);
            }
            self.colours.push(begin..self.pairs.p.len());
        }
        self.plan_chunks();
    }

    /// Splits every colour into full chunks of [`LANES`] (classified by layout) and a remainder.
    fn plan_chunks(&mut self) {
        for c in 0..self.colours.len() {
            let colour = self.colours[c].clone();
            // Greedy scan in particle order: eight constraints that fit a unit-stride layout
            // make a chunk; a constraint that starts no such chunk (a run's ragged end, say at
            // the end of a grid row) waits for the gathered chunks at the end of the set.
            let mut order = Vec::with_capacity(colour.len());
            let mut leftovers = Vec::new();
            let mut layouts = Vec::new();
            let mut k = colour.start;
            while k < colour.end {
                if k + LANES <= colour.end
                    && let Some(layout) =
                        structured_layout(&self.pairs.p[k..k + LANES], &self.pairs.q[k..k + LANES])
                {
                    order.extend(k..k + LANES);
                    layouts.push(layout);
                    k += LANES;
                } else {
                    leftovers.push(k);
                    k += 1;
                }
            }
            order.extend(leftovers);
            let pairs = &mut self.pairs;
            let take = |v: &Vec<u32>| order.iter().map(|&k| v[k]).collect::<Vec<u32>>();
            let (p, q, group) = (take(&pairs.p), take(&pairs.q), take(&pairs.group));
            let rest: Vec<f64> = order.iter().map(|&k| pairs.rest[k]).collect();
            pairs.p[colour.clone()].copy_from_slice(&p);
            pairs.q[colour.clone()].copy_from_slice(&q);
            pairs.group[colour.clone()].copy_from_slice(&group);
            pairs.rest[colour.clone()].copy_from_slice(&rest);
            let first = self.chunks.len();
            let mut k = colour.start;
            let structured = layouts.into_iter().map(Some);
            for layout in structured.chain(std::iter::repeat(None)) {
                if k + LANES > colour.end {
                    break;
                }
                let g = &pairs.group[k..k + LANES];
                self.chunks.push(Chunk {
                    start: k,
                    layout: layout.unwrap_or(Layout::Gathered),
                    uniform: g.iter().all(|&x| x == g[0]),
                });
                k += LANES;
            }
            self.plan.push((first..self.chunks.len(), k));
        }
    }
}

/// The unit-stride layout eight independent constraints fit, if any.
fn structured_layout(p: &[u32], q: &[u32]) -> Option<Layout> {
    let all = |f: &dyn Fn(usize) -> bool| (0..LANES).all(f);
    if all(&|l| p[l] == p[0] + l as u32 && q[l] == q[0] + l as u32) {
        Some(Layout::Contiguous)
    } else if all(&|l| p[l] == p[0] + 2 * l as u32 && q[l] == p[l] + 1) {
        Some(Layout::Paired)
    } else if all(&|l| p[l] == p[0] + QUAD[l] as u32 && q[l] == p[l] + 2) {
        Some(Layout::Quad)
    } else if all(&|l| p[l] == p[0] + 4 * l as u32 && q[l] == p[l] + 2) {
        Some(Layout::Spaced)
    } else if all(&|l| p[l] == p[0] + 2 * l as u32 && q[l] == q[0] + 2 * l as u32)
        && p[0].abs_diff(q[0]) as usize >= STRIDED
    {
        Some(Layout::Strided)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ClothMesh, ClothParams, Family, Forces, GridDesc, Mass, Settings, SolverBuilder};

    /// An `n` × `n` grid with stretch, shear and bend-distance; `shuffle` renumbers its
    /// particles pseudo-randomly, so that index offsets stop being regular (the greedy path).
    fn block(n: usize, shuffle: bool) -> (Block<2, Distance>, usize) {
        let grid = GridDesc {
            resolution: (n, n),
            ..GridDesc::default()
        }
        .build()
        .expect("valid grid");
        let n = grid.positions.len();
        let perm: Vec<u32> = if shuffle {
            (0..n as u64)
                .map(|i| ((i * 7919 + 13) % n as u64) as u32)
                .collect()
        } else {
            (0..n as u32).collect()
        };
        let mut positions = vec![DVec3::ZERO; n];
        for (i, &j) in perm.iter().enumerate() {
            positions[j as usize] = grid.positions[i];
        }
        let triangles = grid
            .triangles
            .iter()
            .map(|t| t.map(|i| perm[i as usize]))
            .collect();
        let mesh = ClothMesh::from_triangles(positions, triangles, Mass::Total(1.0), vec![])
            .expect("valid mesh");
        let params = ClothParams::default().edit(Family::BendDistance, |p| p.enabled = true);
        let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("valid");
        b.add_cloth("c", &mesh, params, 0.0).expect("valid");
        (b.build().constraints().distance.clone(), n)
    }

    /// Preorder list of the internal nodes' (lo, mid, hi) over `lo..hi`, as `fork` walks them.
    fn nodes(lo: usize, hi: usize, out: &mut Vec<(usize, usize, usize)>) {
        if hi - lo < 2 {
            return;
        }
        let mid = lo + (hi - lo) / 2;
        out.push((lo, mid, hi));
        nodes(lo, mid, out);
        nodes(mid, hi, out);
    }

    #[test]
    fn a_link_goes_to_the_tree_node_that_splits_its_two_domains() {
        for count in 1..24 {
            let mut list = Vec::new();
            nodes(0, count, &mut list);
            assert_eq!(list.len(), count - 1);
            for a in 0..count {
                for b in a + 1..count {
                    let (lo, mid, hi) = list[tree_node(b, a, count)];
                    assert!(
                        lo <= a && a < mid && mid <= b && b < hi,
                        "{a} {b} of {count}"
                    );
                }
            }
        }
    }

    fn global(d: &Domain, k: usize) -> (u32, u32) {
        let s = d.start as u32;
        (s + d.pairs.p[k], s + d.pairs.q[k])
    }

    #[test]
    fn every_constraint_is_solved_once_and_no_set_shares_a_particle() {
        for shuffle in [false, true] {
            let (block, n) = block(30, shuffle);
            let domains = Domains::new(&block, n, 200);
            assert!(domains.list.len() > 3);
            let mut seen: Vec<(u32, u32)> = Vec::new();
            for d in &domains.list {
                for colour in &d.colours {
                    let mut used: Vec<u32> = colour
                        .clone()
                        .flat_map(|k| {
                            let (p, q) = global(d, k);
                            [p, q]
                        })
                        .collect();
                    let len = used.len();
                    used.sort_unstable();
                    used.dedup();
                    assert_eq!(
                        used.len(),
                        len,
                        "a set shares a particle (shuffle {shuffle})"
                    );
                    seen.extend(colour.clone().map(|k| global(d, k)));
                }
            }
            let size = domains.size as u32;
            for [(dp, ip), (dq, iq)] in domains.links.iter().flat_map(|l| &l.ends) {
                assert_ne!(dp, dq);
                let (p, q) = (dp * size + ip, dq * size + iq);
                seen.push((p.min(q), p.max(q)));
            }
            let mut expected: Vec<(u32, u32)> = block
                .particles
                .iter()
                .map(|&[p, q]| (p.min(q), p.max(q)))
                .collect();
            expected.sort_unstable();
            seen.sort_unstable();
            assert_eq!(seen, expected, "shuffle {shuffle}");
        }
    }

    #[test]
    fn chunk_layouts_match_their_lanes_and_grids_mostly_load_with_unit_stride() {
        // Rows of 32 split into whole chunks (a row of 30 leaves a ragged end of 6 per row).
        let (block, n) = block(32, false);
        let domains = Domains::new(&block, n, 4096);
        for d in &domains.list {
            for c in &d.chunks {
                let (p, q) = (&d.pairs.p[c.start..], &d.pairs.q[c.start..]);
                for l in 0..LANES {
                    let (ep, eq) = match c.layout {
                        Layout::Contiguous => (p[0] + l as u32, q[0] + l as u32),
                        Layout::Paired => (p[0] + 2 * l as u32, p[0] + 2 * l as u32 + 1),
                        Layout::Quad => (p[0] + QUAD[l] as u32, p[0] + QUAD[l] as u32 + 2),
                        Layout::Strided => (p[0] + 2 * l as u32, q[0] + 2 * l as u32),
                        Layout::Spaced => (p[0] + 4 * l as u32, p[0] + 4 * l as u32 + 2),
                        Layout::Gathered => (p[l], q[l]),
                    };
                    assert_eq!((p[l], q[l]), (ep, eq), "{:?}", c.layout);
                }
            }
        }
        let s = domains.stats();
        let structured = s.contiguous + s.strided;
        assert!(
            structured as f64 > 0.7 * block.len() as f64,
            "{s:?} of {}",
            block.len()
        );
    }
}
