//! The implicit system where the stencil's springs are all there are (a grid with no
//! bending, tethers or seams), solved in lanes: its rows, and each pass of the conjugate
//! gradients (products, updates with the preconditioner, directions), run over the chunks'
//! vectors held per axis in f64 lanes. The arithmetic is that of the general passes
//! (`methods/implicit_mass_spring.rs`, `sparse/pcg.rs`) in the same order, lane by lane, and
//! every sum over particles is taken one particle after another in particle order, then over
//! the chunks in chunk order: the results are the general passes' bits on every lane width
//! and thread count.
//!
//! A = M + h D + h² K with M = 1/w, filtered as Baraff & Witkin 1998, §5.3: the rows of
//! particles with inverse mass 0 are zero in A, in the residual and in the preconditioner.

use glam::DVec3;
use pulp::Simd;
use rayon::prelude::*;
use weft_simd::{LaneKernel, Ops, SimdPath, V3, load, load_at, on_path, store};

use super::{Geometry, RayStencil, ray_sum, row_terms, v3};
use crate::chunk::CHUNK;
use crate::sparse::{CgLimits, CgPasses, Outcome, in_chunk_order, iterate};

/// What the implicit solve reads and writes per particle.
pub(crate) struct SystemIo<'a> {
    /// Inverse masses.
    pub w: &'a [f64],
    /// The external accelerations in; at free particles, Δv / h out.
    pub accel: &'a mut [DVec3],
    /// The warm start in (read from the lanes of [`RayStencil::load_state`]); Δv out.
    pub dv: &'a mut [DVec3],
}

/// One chunk's vectors of the solve, per axis over its lanes: its particles, rounded up to the
/// widest lane group (zero past them, where w = 0 filters them out).
#[derive(Clone, Debug, Default)]
pub(super) struct ChunkVectors {
    /// Masses, zero where filtered (w = 0) and past the particles.
    m: Vec<f64>,
    /// The solution Δv.
    x: [Vec<f64>; 3],
    /// The residual b − A x.
    r: [Vec<f64>; 3],
    /// The preconditioned residual P⁻¹ r.
    z: [Vec<f64>; 3],
    /// A p.
    q: [Vec<f64>; 3],
    /// The inverse diagonal blocks of A, entry by entry in `Sym3`'s order.
    pinv: [Vec<f64>; 6],
}

impl ChunkVectors {
    /// Zeroed vectors over `len` lanes.
    pub(super) fn new(len: usize) -> Self {
        let v = || vec![0.0; len];
        Self {
            m: v(),
            x: [v(), v(), v()],
            r: [v(), v(), v()],
            z: [v(), v(), v()],
            q: [v(), v(), v()],
            pinv: std::array::from_fn(|_| v()),
        }
    }
}

impl RayStencil {
    /// Solves the implicit system at the state of the last [`RayStencil::load_state`] and
    /// substep h for Δv, by block-Jacobi conjugate gradients from the warm start (when `warm`,
    /// else from zero) within `limits`, polling `stopping` once per iteration; writes Δv to
    /// `io.dv` and Δv / h to `io.accel` at the free particles.
    pub fn solve_system(
        &mut self,
        io: SystemIo<'_>,
        warm: bool,
        limits: CgLimits,
        stopping: &dyn Fn() -> bool,
        path: SimdPath,
    ) -> Outcome {
        let len = self.geo.stride + 2 * self.geo.margin;
        for d in self.lanes.p.iter_mut() {
            d.resize(len, 0.0);
        }
        let b_norm2 = self.system_rows(io.w, io.accel, warm, path);
        let mut passes = Passes {
            stencil: self,
            path,
        };
        let outcome = iterate(&mut passes, b_norm2, limits, stopping);
        let (h, w) = (self.lanes.h, io.w);
        (self.lanes.chunks.par_iter())
            .zip(
                io.accel
                    .par_chunks_mut(CHUNK)
                    .zip(io.dv.par_chunks_mut(CHUNK)),
            )
            .enumerate()
            .for_each(|(c, (cv, (accel, dv)))| {
                for (j, (a, dv)) in accel.iter_mut().zip(dv).enumerate() {
                    *dv = DVec3::new(cv.x[0][j], cv.x[1][j], cv.x[2][j]);
                    if w[c * CHUNK + j] > 0.0 {
                        *a = *dv / h;
                    }
                }
            });
        outcome
    }

    /// Linearises the springs and writes each chunk's rows: r = b − A x₀, the inverse of A's
    /// diagonal block and x = x₀ (b = h M a_ext + the springs' share, A x₀ = M x₀ + the
    /// springs'); zeros where w = 0. Each chunk linearises its window and sums its rows in
    /// one task. Returns ‖b‖², the chunks' sums added in order.
    fn system_rows(&mut self, w: &[f64], accel: &[DVec3], warm: bool, path: SimdPath) -> f64 {
        let (geo, h) = (&self.geo, self.lanes.h);
        let (windows, chunks, state, p) = self.lanes.split();
        let x0 = warm.then_some(p);
        let partials: Vec<f64> = (windows.par_iter_mut().zip(chunks.par_iter_mut()))
            .enumerate()
            .map(|(c, (win, cv))| {
                state.linearize(geo, c, win, path);
                let start = c * CHUNK;
                let end = w.len().min(start + CHUNK);
                let chunk = Setup {
                    geo,
                    win,
                    x0,
                    start,
                    h,
                    w: &w[start..end],
                    accel: &accel[start..end],
                    cv,
                };
                on_path(path, chunk)
            })
            .collect();
        partials.iter().sum()
    }
}

/// The conjugate gradients' passes over the stencil's chunks.
struct Passes<'a> {
    stencil: &'a mut RayStencil,
    path: SimdPath,
}

impl Passes<'_> {
    /// Runs `kernel` on every chunk's vectors with the chunk's part of p to write, and
    /// returns the chunks' sums added in order.
    fn with_direction<K>(&mut self, kernel: K) -> (f64, f64)
    where
        K: Fn(&mut ChunkVectors, [&mut [f64]; 3]) -> (f64, f64) + Sync,
    {
        let (geo, lanes) = (&self.stencil.geo, &mut self.stencil.lanes);
        let (m, stride) = (geo.margin, geo.stride);
        let [d0, d1, d2] = (lanes.p.each_mut()).map(|d| d[m..m + stride].par_chunks_mut(CHUNK));
        let partials: Vec<(f64, f64)> = (lanes.chunks.par_iter_mut(), d0, d1, d2)
            .into_par_iter()
            .map(|(cv, d0, d1, d2)| kernel(cv, [d0, d1, d2]))
            .collect();
        in_chunk_order(partials)
    }
}

impl CgPasses for Passes<'_> {
    fn start(&mut self) -> (f64, f64) {
        let path = self.path;
        self.with_direction(|cv, p| on_path(path, Direction { cv, beta: None, p }))
    }

    fn apply(&mut self) -> f64 {
        let (geo, lanes, path) = (&self.stencil.geo, &mut self.stencil.lanes, self.path);
        let (windows, p) = (&lanes.windows, &lanes.p);
        let partials: Vec<f64> = (lanes.chunks.par_iter_mut().enumerate())
            .map(|(c, cv)| {
                let (start, win) = (c * CHUNK, &windows[c][..]);
                on_path(
                    path,
                    Product {
                        geo,
                        win,
                        p,
                        start,
                        cv,
                    },
                )
            })
            .collect();
        partials.iter().sum()
    }

    fn step(&mut self, alpha: f64) -> (f64, f64) {
        let (geo, lanes, path) = (&self.stencil.geo, &mut self.stencil.lanes, self.path);
        let p = &lanes.p;
        let partials: Vec<(f64, f64)> = (lanes.chunks.par_iter_mut().enumerate())
            .map(|(c, cv)| {
                let from = geo.margin + c * CHUNK;
                on_path(path, Step { cv, alpha, p, from })
            })
            .collect();
        in_chunk_order(partials)
    }

    fn direction(&mut self, beta: f64) {
        let path = self.path;
        let beta = Some(beta);
        self.with_direction(|cv, p| on_path(path, Direction { cv, beta, p }));
    }
}

/// The sums a pass over lanes adds one particle after another: lane `l` of `v` where lane
/// `l` of the masses `m` is positive (a filtered or padding row adds nothing).
#[inline(always)]
fn add_free<const L: usize>(sum: &mut f64, v: [f64; L], m: [f64; L]) {
    for l in 0..L {
        if m[l] > 0.0 {
            *sum += v[l];
        }
    }
}

/// `Sym3::mul`: the block `m` (entries in `Sym3`'s order) times `u`.
#[inline(always)]
fn sym_mul<S: Simd>(f: Ops<S>, m: &[S::f64s; 6], u: &V3<S>) -> V3<S> {
    let [xx, yy, zz, xy, xz, yz] = *m;
    [
        f.add(f.add(f.mul(xx, u[0]), f.mul(xy, u[1])), f.mul(xz, u[2])),
        f.add(f.add(f.mul(xy, u[0]), f.mul(yy, u[1])), f.mul(yz, u[2])),
        f.add(f.add(f.mul(xz, u[0]), f.mul(yz, u[1])), f.mul(zz, u[2])),
    ]
}

/// `Sym3::inverse` in lanes: zero where the determinant is not positive (or NaN).
#[inline(always)]
fn sym_inverse<S: Simd>(f: Ops<S>, d: &[S::f64s; 6]) -> [S::f64s; 6] {
    let [xx, yy, zz, xy, xz, yz] = *d;
    let cxx = f.sub(f.mul(yy, zz), f.mul(yz, yz));
    let cxy = f.sub(f.mul(xz, yz), f.mul(xy, zz));
    let cxz = f.sub(f.mul(xy, yz), f.mul(xz, yy));
    let det = f.add(f.add(f.mul(xx, cxx), f.mul(xy, cxy)), f.mul(xz, cxz));
    let ok = f.gt(det, f.c(0.0));
    let inv = f.div(f.c(1.0), det);
    let mut out = [
        cxx,
        f.sub(f.mul(xx, zz), f.mul(xz, xz)),
        f.sub(f.mul(xx, yy), f.mul(xy, xy)),
        cxy,
        cxz,
        f.sub(f.mul(xy, xz), f.mul(xx, yz)),
    ];
    for e in out.iter_mut() {
        *e = f.sel(ok, f.mul(*e, inv), f.c(0.0));
    }
    out
}

/// Three arrays' lanes from `j` as vectors.
#[inline(always)]
fn at3<S: Simd, const L: usize>(a: &[Vec<f64>; 3], j: usize) -> V3<S> {
    [
        load_at::<S, L>(&a[0], j),
        load_at::<S, L>(&a[1], j),
        load_at::<S, L>(&a[2], j),
    ]
}

/// The six arrays' lanes from `j` as vectors (a block per lane).
#[inline(always)]
fn pinv_at<S: Simd, const L: usize>(a: &[Vec<f64>; 6], j: usize) -> [S::f64s; 6] {
    [
        load_at::<S, L>(&a[0], j),
        load_at::<S, L>(&a[1], j),
        load_at::<S, L>(&a[2], j),
        load_at::<S, L>(&a[3], j),
        load_at::<S, L>(&a[4], j),
        load_at::<S, L>(&a[5], j),
    ]
}

/// Values `j .. j + L` of `a` (zeros past its end).
#[inline(always)]
fn lanes_at<const L: usize>(a: &[f64], j: usize) -> [f64; L] {
    match a.get(j..j + L).and_then(|c| c.first_chunk::<L>()) {
        Some(c) => *c,
        None => [0.0; L],
    }
}

/// Stores vectors into three arrays from `j`.
#[inline(always)]
fn put3<S: Simd, const L: usize>(a: &mut [Vec<f64>; 3], j: usize, v: V3<S>) {
    for (a, v) in a.iter_mut().zip(v) {
        a[j..j + L].copy_from_slice(&store::<S, L>(v));
    }
}

/// One chunk's rows (see [`RayStencil::system_rows`]); `win`: its window, `w` and `accel` its
/// particles'.
struct Setup<'a> {
    geo: &'a Geometry,
    win: &'a [Vec<f64>],
    x0: Option<&'a [Vec<f64>; 3]>,
    start: usize,
    h: f64,
    w: &'a [f64],
    accel: &'a [DVec3],
    cv: &'a mut ChunkVectors,
}

impl LaneKernel for Setup<'_> {
    type Output = f64;

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> f64 {
        let Setup {
            geo,
            win,
            x0,
            start,
            h,
            w,
            accel,
            cv,
        } = self;
        let f = Ops(s);
        let (zero, one, h) = (f.c(0.0), f.c(1.0), f.c(h));
        let mut bb = 0.0;
        for j in (0..cv.m.len()).step_by(L) {
            let at = geo.at(start, j);
            let (sb, sax, sd) = row_terms::<S, L>(f, geo, win, x0, at);
            let (mut wl, mut al) = ([0.0; L], [[0.0; L]; 3]);
            for l in 0..L.min(w.len().saturating_sub(j)) {
                wl[l] = w[j + l];
                al[0][l] = accel[j + l].x;
                al[1][l] = accel[j + l].y;
                al[2][l] = accel[j + l].z;
            }
            let wv = load::<S, L>(wl);
            let free = f.gt(wv, zero);
            // M's share first (`RowSums::of_mass`), then the springs' (`RowSums::add`).
            let m = f.sel(free, f.div(one, wv), zero);
            let mh = f.mul(m, h);
            let x0v = match x0 {
                Some(p) => v3::<S, L>(p, at.0),
                None => [zero; 3],
            };
            let (mut b, mut ax, mut r, mut d) = (sb, sax, sb, sd);
            for a in 0..3 {
                b[a] = f.add(f.mul(load::<S, L>(al[a]), mh), sb[a]);
                ax[a] = f.add(f.mul(x0v[a], m), sax[a]);
                r[a] = f.sel(free, f.sub(b[a], ax[a]), zero);
                d[a] = f.add(m, sd[a]);
                d[a + 3] = f.add(zero, sd[a + 3]);
            }
            // `RowSums::finish`: zeros where filtered.
            let inv = sym_inverse(f, &d);
            for (out, e) in cv.pinv.iter_mut().zip(inv) {
                out[j..j + L].copy_from_slice(&store::<S, L>(f.sel(free, e, zero)));
            }
            put3::<S, L>(&mut cv.r, j, r);
            let x = [
                f.sel(free, x0v[0], zero),
                f.sel(free, x0v[1], zero),
                f.sel(free, x0v[2], zero),
            ];
            put3::<S, L>(&mut cv.x, j, x);
            cv.m[j..j + L].copy_from_slice(&store::<S, L>(m));
            add_free(&mut bb, store::<S, L>(f.dot(&b, &b)), wl);
        }
        bb
    }
}

/// z = P⁻¹ r and p = z + β p (p = z without β) over one chunk; with β absent (the first
/// direction) also returns (r·z, r·r), else zeros.
struct Direction<'a> {
    cv: &'a mut ChunkVectors,
    beta: Option<f64>,
    p: [&'a mut [f64]; 3],
}

impl LaneKernel for Direction<'_> {
    type Output = (f64, f64);

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> (f64, f64) {
        let Direction { cv, beta, mut p } = self;
        let f = Ops(s);
        let mut sums = (0.0, 0.0);
        for j in (0..cv.m.len()).step_by(L) {
            let z = match beta {
                Some(beta) => {
                    let (z, beta) = (at3::<S, L>(&cv.z, j), f.c(beta));
                    let mut out = z;
                    for a in 0..3 {
                        out[a] = f.add(z[a], f.mul(load_at::<S, L>(p[a], j), beta));
                    }
                    out
                }
                None => {
                    let pinv = pinv_at::<S, L>(&cv.pinv, j);
                    let r = at3::<S, L>(&cv.r, j);
                    let z = sym_mul(f, &pinv, &r);
                    put3::<S, L>(&mut cv.z, j, z);
                    let ml = lanes_at::<L>(&cv.m, j);
                    add_free(&mut sums.0, store::<S, L>(f.dot(&r, &z)), ml);
                    add_free(&mut sums.1, store::<S, L>(f.dot(&r, &r)), ml);
                    z
                }
            };
            for (p, z) in p.iter_mut().zip(z) {
                p[j..j + L].copy_from_slice(&store::<S, L>(z));
            }
        }
        sums
    }
}

/// q ← A p over one chunk of particles from `start`, zero on filtered rows; returns p·q.
struct Product<'a> {
    geo: &'a Geometry,
    win: &'a [Vec<f64>],
    p: &'a [Vec<f64>; 3],
    start: usize,
    cv: &'a mut ChunkVectors,
}

impl LaneKernel for Product<'_> {
    type Output = f64;

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> f64 {
        let Product {
            geo,
            win,
            p,
            start,
            cv,
        } = self;
        let f = Ops(s);
        let zero = f.c(0.0);
        let mut pq = 0.0;
        for j in (0..cv.m.len()).step_by(L) {
            let at = geo.at(start, j);
            let sum = ray_sum::<S, L>(f, geo, win, p, at);
            let (pv, m) = (v3::<S, L>(p, at.0), load_at::<S, L>(&cv.m, j));
            let free = f.gt(m, zero);
            // The general product's order: M p, the springs, then the filter.
            let mut q = sum;
            for a in 0..3 {
                q[a] = f.sel(free, f.add(f.mul(pv[a], m), sum[a]), zero);
            }
            put3::<S, L>(&mut cv.q, j, q);
            add_free(&mut pq, store::<S, L>(f.dot(&pv, &q)), store::<S, L>(m));
        }
        pq
    }
}

/// x += α p, r −= α q and z = P⁻¹ r over one chunk (p from padded index `from`); returns
/// (r·z, r·r).
struct Step<'a> {
    cv: &'a mut ChunkVectors,
    alpha: f64,
    p: &'a [Vec<f64>; 3],
    from: usize,
}

impl LaneKernel for Step<'_> {
    type Output = (f64, f64);

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> (f64, f64) {
        let Step { cv, alpha, p, from } = self;
        let f = Ops(s);
        let alpha = f.c(alpha);
        let mut sums = (0.0, 0.0);
        for j in (0..cv.m.len()).step_by(L) {
            let (pv, q) = (v3::<S, L>(p, from + j), at3::<S, L>(&cv.q, j));
            let (x, r) = (at3::<S, L>(&cv.x, j), at3::<S, L>(&cv.r, j));
            let (mut x, mut r) = (x, r);
            for a in 0..3 {
                x[a] = f.add(x[a], f.mul(pv[a], alpha));
                r[a] = f.sub(r[a], f.mul(q[a], alpha));
            }
            let pinv = pinv_at::<S, L>(&cv.pinv, j);
            let z = sym_mul(f, &pinv, &r);
            put3::<S, L>(&mut cv.x, j, x);
            put3::<S, L>(&mut cv.r, j, r);
            put3::<S, L>(&mut cv.z, j, z);
            let ml = lanes_at::<L>(&cv.m, j);
            add_free(&mut sums.0, store::<S, L>(f.dot(&r, &z)), ml);
            add_free(&mut sums.1, store::<S, L>(f.dot(&r, &r)), ml);
        }
        sums
    }
}
