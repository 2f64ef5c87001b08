//! The implicit method's distance springs as a stencil: on a grid every spring joins a particle
//! i to i + o for one of a few offsets o (see `spring_stencil.rs`), so each particle's row of
//! the linear system, and of each product with it, is a sum over the same slots, read with unit
//! stride in f64 lanes, `L` particles at a time (eight on AVX-512), with no scatter.
//!
//! Each spring is linearised at its lower end (the slots of positive offset): its ray (g, κ)
//! and its share b of the right-hand side, by the arithmetic of `linear.rs`'s `linearize_ray`
//! (Baraff & Witkin 1998, eq. 6). The particles go in chunks, and each chunk linearises the
//! springs it reads into a window of its own: those of its lower ends and of the widest offset
//! before them, which the chunk before also linearises, to the same bits. A chunk's terms are
//! then summed while they are still in cache, with no pass between, and no chunk reads
//! another's. A particle sums over its slots in slot order, with u = pᵢ − pᵢ₊ₒ for slot
//! offset o: the product term g (g·u) + κ u, the diagonal block g gᵀ + κ I and ±b (+ at the
//! lower end, − at the upper). Seen from the upper end u is negated exactly, so a spring gives
//! its two particles exactly opposite terms. Every sum is a particle's own, in slot order: the
//! same bits on every thread count and lane width.

use glam::DVec3;
use pulp::Simd;
use rayon::prelude::*;
use weft_simd::{LaneKernel, Ops, SimdPath, V3, load_at, on_path, store, store3};

use super::linear_rows::{RowSums, State};
use super::spring_stencil::slots_of;
use super::{Block, Distance};
use crate::chunk::CHUNK;
use crate::params::FamilyParams;
use crate::sparse::Sym3;

#[path = "ray_system.rs"]
mod system;
use system::ChunkVectors;
pub(crate) use system::SystemIo;

/// The widest lane group (AVX-512's f64 lanes): the stride and the margins are its multiples.
const WIDE: usize = 8;

/// Arrays per positive slot: its springs' g (3 axes), κ and b (3 axes), at their lower end.
const TERMS: usize = 7;

/// Below this length (m) a spring has no direction and gives nothing (`RankOne::value`).
const MIN_LEN: f64 = 1e-9;

/// The distance springs of a grid by slot, and the lanes they are computed in.
#[derive(Clone, Debug)]
pub(crate) struct RayStencil {
    geo: Geometry,
    lanes: Lanes,
}

/// Which spring each particle has in each slot.
#[derive(Clone, Debug)]
struct Geometry {
    /// `n` rounded up to [`WIDE`].
    stride: usize,
    /// Padding before and after the particles in every array: the widest offset and a group.
    margin: usize,
    /// Each slot's offset o (its spring joins i and i + o), ascending.
    offsets: Vec<isize>,
    /// Each slot's spring: the index of its positive slot.
    spring_of: Vec<usize>,
    /// The positive slots' (offset, parameter group), ascending.
    positive: Vec<(isize, u32)>,
    /// The lower ends a chunk's window holds before its first particle: the widest offset,
    /// rounded up to [`WIDE`].
    halo: usize,
    /// Rest length of positive slot k's spring at its lower end i, `rest[k][margin + i]`;
    /// negative where there is none.
    rest: Vec<Vec<f64>>,
}

/// A chunk's window: each terms array over the window's lower ends.
type Window = Vec<Vec<f64>>;

/// The state per axis, padded by the margin (zero there), and the springs' terms by chunk.
#[derive(Clone, Debug, Default)]
struct Lanes {
    /// Positions.
    x: [Vec<f64>; 3],
    /// Velocities.
    v: [Vec<f64>; 3],
    /// The vector a product multiplies (or the warm start).
    p: [Vec<f64>; 3],
    /// Chunk c's window: positive slot k's terms in `windows[c][k * TERMS ..]` (g per axis, κ,
    /// b per axis) at the lower ends from `c · CHUNK − halo` (see [`Geometry::window_from`]).
    windows: Vec<Window>,
    /// Each positive slot's stiffness k, damping c and whether its family is enabled (1 or 0),
    /// as last loaded.
    coef: Vec<[f64; 3]>,
    /// The substep h, as last loaded.
    h: f64,
    /// Each chunk's vectors of the implicit solve (`ray_system.rs`).
    chunks: Vec<ChunkVectors>,
}

impl RayStencil {
    /// The stencil of `block`'s springs over `n` particles, or `None` when they form none (see
    /// [`slots_of`]) or two springs of one group join the same two particles.
    pub fn build(block: &Block<2, Distance>, n: usize) -> Option<Self> {
        let slots = slots_of(block)?;
        let positive: Vec<(isize, u32)> = slots.iter().copied().filter(|s| s.0 > 0).collect();
        let spring_of = (slots.iter())
            .map(|&(o, g)| positive.binary_search(&(o.abs(), g)).ok())
            .collect::<Option<Vec<usize>>>()?;
        let widest = slots.iter().map(|s| s.0.unsigned_abs()).max().unwrap_or(0);
        let stride = n.next_multiple_of(WIDE);
        let margin = (widest + WIDE).next_multiple_of(WIDE);
        let len = stride + 2 * margin;
        let mut rest = vec![vec![-1.0; len]; positive.len()];
        let springs = block.particles.iter().zip(&block.group);
        for ((&[p, q], &group), shape) in springs.zip(&block.shapes) {
            let (low, high) = (p.min(q) as usize, p.max(q) as usize);
            if high >= n {
                return None;
            }
            let k = positive
                .binary_search(&((high - low) as isize, group))
                .ok()?;
            let r = &mut rest[k][margin + low];
            if *r >= 0.0 {
                return None;
            }
            *r = shape.rest;
        }
        let halo = widest.next_multiple_of(WIDE);
        let chunk_len = |c: usize| CHUNK.min(stride - c * CHUNK);
        let chunks = stride.div_ceil(CHUNK);
        let windows = (0..chunks)
            .map(|c| vec![vec![0.0; halo + chunk_len(c)]; positive.len() * TERMS])
            .collect();
        let lanes = Lanes {
            windows,
            chunks: (0..chunks)
                .map(|c| ChunkVectors::new(chunk_len(c)))
                .collect(),
            ..Lanes::default()
        };
        let geo = Geometry {
            stride,
            margin,
            offsets: slots.iter().map(|s| s.0).collect(),
            spring_of,
            positive,
            halo,
            rest,
        };
        Some(Self { geo, lanes })
    }

    /// Linearises the springs at `st` and adds each particle's share of the right-hand side,
    /// of (A − M) x₀ and of A − M's diagonal block to its row in `rows`.
    pub fn linearize(
        &mut self,
        params: &[FamilyParams],
        st: State<'_>,
        rows: &mut [RowSums],
        path: SimdPath,
    ) {
        self.load_state(params, st);
        let geo = &self.geo;
        let (windows, _, state, p) = self.lanes.split();
        let x0 = st.x0.map(|_| p);
        (rows.par_chunks_mut(CHUNK).zip(windows.par_iter_mut()))
            .enumerate()
            .for_each(|(c, (rows, win))| {
                state.linearize(geo, c, win, path);
                let (start, win) = (c * CHUNK, &win[..]);
                on_path(
                    path,
                    Sums {
                        geo,
                        win,
                        x0,
                        start,
                        rows,
                    },
                );
            });
    }

    /// Loads the state into lanes (x₀ into `p`) and the springs' coefficients, for the
    /// linearisation that follows ([`RayStencil::linearize`] or
    /// [`RayStencil::solve_system`]).
    pub fn load_state(&mut self, params: &[FamilyParams], st: State<'_>) {
        let Self { geo, lanes } = self;
        let len = geo.stride + 2 * geo.margin;
        load(&mut lanes.x, geo.margin, len, st.x);
        load(&mut lanes.v, geo.margin, len, st.v);
        if let Some(x0) = st.x0 {
            load(&mut lanes.p, geo.margin, len, x0);
        }
        lanes.h = st.h;
        lanes.coef = (geo.positive.iter())
            .map(|&(_, g)| {
                let p = &params[g as usize];
                [
                    p.spring_stiffness,
                    p.spring_damping,
                    f64::from(u8::from(p.enabled)),
                ]
            })
            .collect();
    }

    /// Adds the springs' share of (A − M) p to `q`, for the springs of the last
    /// [`RayStencil::linearize`].
    pub fn product(&mut self, p: &[DVec3], q: &mut [DVec3], path: SimdPath) {
        let Self { geo, lanes } = self;
        load(&mut lanes.p, geo.margin, geo.stride + 2 * geo.margin, p);
        let (geo, windows, p) = (&*geo, &lanes.windows, &lanes.p);
        q.par_chunks_mut(CHUNK).enumerate().for_each(|(c, q)| {
            let (start, win) = (c * CHUNK, &windows[c][..]);
            on_path(
                path,
                Product {
                    geo,
                    win,
                    p,
                    start,
                    q,
                },
            );
        });
    }
}

impl Geometry {
    /// The padded index of the first lower end in chunk `c`'s window.
    fn window_from(&self, c: usize) -> usize {
        self.margin + c * CHUNK - self.halo
    }

    /// The padded index and the window index of particle `j` of the chunk from `start`.
    #[inline(always)]
    fn at(&self, start: usize, j: usize) -> (usize, usize) {
        (self.margin + start + j, self.halo + j)
    }
}

/// What the linearisation of a window reads: the state in lanes and the springs' coefficients.
struct LoadedState<'a> {
    x: &'a [Vec<f64>; 3],
    v: &'a [Vec<f64>; 3],
    coef: &'a [[f64; 3]],
    h: f64,
}

impl LoadedState<'_> {
    /// Linearises the springs of chunk `c`'s window into `win`.
    fn linearize(&self, geo: &Geometry, c: usize, win: &mut [Vec<f64>], path: SimdPath) {
        let Self { x, v, coef, h } = *self;
        let from = geo.window_from(c);
        on_path(
            path,
            Terms {
                geo,
                x,
                v,
                coef,
                h,
                from,
                out: win,
            },
        );
    }
}

impl Lanes {
    /// The windows and the chunks' vectors of the solve, to write, beside what the windows'
    /// linearisation reads and `p` (the warm start after [`RayStencil::load_state`]).
    fn split(
        &mut self,
    ) -> (
        &mut [Window],
        &mut [ChunkVectors],
        LoadedState<'_>,
        &[Vec<f64>; 3],
    ) {
        let state = LoadedState {
            x: &self.x,
            v: &self.v,
            coef: &self.coef,
            h: self.h,
        };
        (&mut self.windows, &mut self.chunks, state, &self.p)
    }
}

/// Copies `src` into `dst` per axis from `margin` on, `dst` padded with zeros to `len`.
fn load(dst: &mut [Vec<f64>; 3], margin: usize, len: usize, src: &[DVec3]) {
    for d in dst.iter_mut() {
        d.resize(len, 0.0);
    }
    let n = src.len();
    let [d0, d1, d2] = dst
        .each_mut()
        .map(|d| d[margin..margin + n].par_chunks_mut(CHUNK));
    (d0, d1, d2, src.par_chunks(CHUNK))
        .into_par_iter()
        .for_each(|(d0, d1, d2, s)| {
            for (i, s) in s.iter().enumerate() {
                (d0[i], d1[i], d2[i]) = (s.x, s.y, s.z);
            }
        });
}

/// Three arrays' values from `at` as vectors (the margins keep every load inside).
#[inline(always)]
fn v3<S: Simd, const L: usize>(src: &[Vec<f64>], at: usize) -> V3<S> {
    [
        load_at::<S, L>(&src[0], at),
        load_at::<S, L>(&src[1], at),
        load_at::<S, L>(&src[2], at),
    ]
}

/// The springs' terms at the lower ends of one window, from padded index `from` on, into
/// `out` (the window's arrays).
struct Terms<'a> {
    geo: &'a Geometry,
    x: &'a [Vec<f64>; 3],
    v: &'a [Vec<f64>; 3],
    /// Each positive slot's stiffness k, damping c and whether its family is enabled (1 or 0).
    coef: &'a [[f64; 3]],
    h: f64,
    from: usize,
    out: &'a mut [Vec<f64>],
}

impl LaneKernel for Terms<'_> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        let Terms {
            geo,
            x,
            v,
            coef,
            h,
            from,
            out,
        } = self;
        let f = Ops(s);
        let zero = f.c(0.0);
        let count = out.first().map_or(0, |o| o.len());
        for (k, &(o, _)) in geo.positive.iter().enumerate() {
            let out = &mut out[k * TERMS..(k + 1) * TERMS];
            let [stiff, damping, on] = coef[k];
            if on == 0.0 {
                for t in out.iter_mut() {
                    t.fill(0.0);
                }
                continue;
            }
            let hhk = h * h * stiff;
            let (hhk, sigma) = (f.c(hhk), f.c(hhk + h * damping));
            let (stiff_v, damping, h) = (f.c(stiff), f.c(damping), f.c(h));
            for j in (0..count).step_by(L) {
                let i = from + j;
                let at = i + o as usize;
                let d = f.dif(&v3::<S, L>(x, i), &v3::<S, L>(x, at));
                let uv = f.dif(&v3::<S, L>(v, i), &v3::<S, L>(v, at));
                let rest = load_at::<S, L>(&geo.rest[k], i);
                let len = f.sqrt(f.dot(&d, &d));
                let inv = f.div(f.c(1.0), len);
                let c = f.sub(len, rest);
                let live = f.and(f.ge(rest, zero), f.ge(len, f.c(MIN_LEN)));
                let kappa = match stiff > 0.0 {
                    true => f.sel(f.gt(c, zero), f.mul(f.mul(hhk, c), inv), zero),
                    false => zero,
                };
                let root = f.sqrt(f.max(f.sub(sigma, kappa), zero));
                let n = [f.mul(d[0], inv), f.mul(d[1], inv), f.mul(d[2], inv)];
                let nuv = f.dot(&n, &uv);
                // b = h f − h² K v (`linearize_ray`).
                let force = f.neg(f.add(f.mul(stiff_v, c), f.mul(damping, nuv)));
                let hf = f.mul(h, force);
                let kn = f.mul(f.sub(hhk, kappa), nuv);
                let mut t = [zero; TERMS];
                for a in 0..3 {
                    t[a] = f.mul(n[a], root);
                    let kv = f.add(f.mul(n[a], kn), f.mul(uv[a], kappa));
                    t[4 + a] = f.sub(f.mul(n[a], hf), kv);
                }
                t[3] = kappa;
                for (o, t) in out.iter_mut().zip(t) {
                    o[j..j + L].copy_from_slice(&store::<S, L>(f.sel(live, t, zero)));
                }
            }
        }
    }
}

/// Σ over the slots of g (g·u) + κ u, u = pᵢ − pᵢ₊ₒ, for the `L` particles at padded index `i`
/// and index `w` of their chunk's window `win`.
#[inline(always)]
fn ray_sum<S: Simd, const L: usize>(
    f: Ops<S>,
    geo: &Geometry,
    win: &[Vec<f64>],
    p: &[Vec<f64>; 3],
    (i, w): (usize, usize),
) -> V3<S> {
    let pi = v3::<S, L>(p, i);
    let mut sum = [f.c(0.0); 3];
    for (&o, &k) in geo.offsets.iter().zip(&geo.spring_of) {
        let t = &win[k * TERMS..];
        let low = w.wrapping_add_signed(o.min(0));
        let (g, kappa) = (v3::<S, L>(t, low), load_at::<S, L>(&t[3], low));
        let u = f.dif(&pi, &v3::<S, L>(p, i.wrapping_add_signed(o)));
        let gu = f.dot(&g, &u);
        for a in 0..3 {
            sum[a] = f.add(sum[a], f.add(f.mul(g[a], gu), f.mul(u[a], kappa)));
        }
    }
    sum
}

/// The rows' sums for one chunk of particles from `start`: b, (A − M) x₀ and the diagonal
/// block, added to `rows` (`win`: the chunk's window).
struct Sums<'a> {
    geo: &'a Geometry,
    win: &'a [Vec<f64>],
    x0: Option<&'a [Vec<f64>; 3]>,
    start: usize,
    rows: &'a mut [RowSums],
}

impl LaneKernel for Sums<'_> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        let Sums {
            geo,
            win,
            x0,
            start,
            rows,
        } = self;
        for j in (0..rows.len()).step_by(L) {
            let at = geo.at(start, j);
            let (b, ax, d) = row_terms::<S, L>(Ops(s), geo, win, x0, at);
            let sums = LaneSums::<L> {
                b: store3::<S, L>(&b),
                ax: store3::<S, L>(&ax),
                d: d.map(|d| store::<S, L>(d)),
            };
            let end = L.min(rows.len() - j);
            for (l, row) in rows[j..j + end].iter_mut().enumerate() {
                row.b += sums.b(l);
                row.ax += sums.ax(l);
                row.d = row.d.add(sums.d(l));
            }
        }
    }
}

/// Lane `l` of a vector stored per axis.
#[inline(always)]
fn lane<const L: usize>(t: &[[f64; L]; 3], l: usize) -> DVec3 {
    DVec3::new(t[0][l], t[1][l], t[2][l])
}

/// The springs' sums of `L` particles' rows, per lane.
struct LaneSums<const L: usize> {
    b: [[f64; L]; 3],
    ax: [[f64; L]; 3],
    d: [[f64; L]; 6],
}

impl<const L: usize> LaneSums<L> {
    /// Lane `l`'s share of the right-hand side.
    #[inline(always)]
    fn b(&self, l: usize) -> DVec3 {
        lane(&self.b, l)
    }

    /// Lane `l`'s (A − M) x₀.
    #[inline(always)]
    fn ax(&self, l: usize) -> DVec3 {
        lane(&self.ax, l)
    }

    /// Lane `l`'s share of the diagonal block.
    #[inline(always)]
    fn d(&self, l: usize) -> Sym3 {
        Sym3(std::array::from_fn(|e| self.d[e][l]))
    }
}

/// The springs' sums of the `L` rows at padded index `at.0` and window index `at.1`: ±b,
/// (A − M) x₀ (zero without x₀) and the diagonal block g gᵀ + κ I (entries in `Sym3`'s
/// order), over the slots in slot order.
#[inline(always)]
fn row_terms<S: Simd, const L: usize>(
    f: Ops<S>,
    geo: &Geometry,
    win: &[Vec<f64>],
    x0: Option<&[Vec<f64>; 3]>,
    at: (usize, usize),
) -> (V3<S>, V3<S>, [S::f64s; 6]) {
    let ax = match x0 {
        Some(x0) => ray_sum::<S, L>(f, geo, win, x0, at),
        None => [f.c(0.0); 3],
    };
    let mut b = [f.c(0.0); 3];
    let mut d = [f.c(0.0); 6];
    for (&o, &k) in geo.offsets.iter().zip(&geo.spring_of) {
        let t = &win[k * TERMS..];
        let low = at.1.wrapping_add_signed(o.min(0));
        let (g, kappa) = (v3::<S, L>(t, low), load_at::<S, L>(&t[3], low));
        let bs = v3::<S, L>(&t[4..], low);
        // Sym3::outer(g, 1) + κ I.
        let block = [
            f.add(f.mul(g[0], g[0]), kappa),
            f.add(f.mul(g[1], g[1]), kappa),
            f.add(f.mul(g[2], g[2]), kappa),
            f.mul(g[0], g[1]),
            f.mul(g[0], g[2]),
            f.mul(g[1], g[2]),
        ];
        for e in 0..6 {
            d[e] = f.add(d[e], block[e]);
        }
        for a in 0..3 {
            b[a] = match o > 0 {
                true => f.add(b[a], bs[a]),
                false => f.sub(b[a], bs[a]),
            };
        }
    }
    (b, ax, d)
}

/// The springs' share of (A − M) p for one chunk of particles from `start`, added to `q`
/// (`win`: the chunk's window).
struct Product<'a> {
    geo: &'a Geometry,
    win: &'a [Vec<f64>],
    p: &'a [Vec<f64>; 3],
    start: usize,
    q: &'a mut [DVec3],
}

impl LaneKernel for Product<'_> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        let Product {
            geo,
            win,
            p,
            start,
            q,
        } = self;
        let f = Ops(s);
        for j in (0..q.len()).step_by(L) {
            let at = geo.at(start, j);
            let sum = ray_sum::<S, L>(f, geo, win, p, at);
            let t = store3::<S, L>(&sum);
            let end = L.min(q.len() - j);
            for (l, q) in q[j..j + end].iter_mut().enumerate() {
                *q += lane(&t, l);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::BlockBuilder;

    /// The springs `pairs` of groups `groups`, rest length 1, as a block.
    fn block(pairs: &[[u32; 2]], groups: &[u32]) -> Block<2, Distance> {
        let mut b = BlockBuilder::default();
        for (&pq, &g) in pairs.iter().zip(groups) {
            b.push(pq, g, Distance { rest: 1.0 });
        }
        b.unordered()
    }

    #[test]
    fn a_chain_is_a_stencil_and_repeated_or_outside_springs_are_refused() {
        let st = RayStencil::build(&block(&[[0, 1], [2, 1], [2, 4]], &[0, 0, 1]), 5)
            .expect("a chain is a stencil");
        assert_eq!(st.geo.offsets, [-2, -1, 1, 2]);
        assert_eq!(st.geo.positive, [(1, 0), (2, 1)]);
        // Each spring sits at its lower end, in its slot; none elsewhere.
        let m = st.geo.margin;
        let at = |k: usize| {
            (0..5)
                .filter(|&i| st.geo.rest[k][m + i] >= 0.0)
                .collect::<Vec<_>>()
        };
        assert_eq!((at(0), at(1)), (vec![0, 1], vec![2]));
        // One group's spring twice between two particles, either way round.
        assert!(RayStencil::build(&block(&[[0, 1], [1, 0]], &[0, 0]), 5).is_none());
        // A particle beyond the count.
        assert!(RayStencil::build(&block(&[[3, 5]], &[0]), 5).is_none());
        // Two groups on one pair are two slots.
        assert!(RayStencil::build(&block(&[[0, 1], [0, 1]], &[0, 1]), 5).is_some());
    }
}
