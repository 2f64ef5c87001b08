//! The implicit system where the stencil's springs are all there are (a grid with no
//! bending, tethers or seams): its rows, products and conjugate gradients' directions each in
//! one pass over the particles, with the arithmetic of the general passes (`methods/
//! implicit_mass_spring.rs`), so that the results are the stencil path's bits.
//!
//! A = M + h D + h² K with M = 1/w, filtered as Baraff & Witkin 1998, §5.3: the rows of
//! particles with inverse mass 0 are zero in A, in the residual and in the preconditioner.

use glam::DVec3;
use pulp::Simd;
use rayon::prelude::*;
use weft_simd::{LaneKernel, Ops, SimdPath, on_path, store3};

use super::{Geometry, RayStencil, RowSums, lane, load, ray_sum, row_sums};
use crate::chunk::CHUNK;
use crate::sparse::Sym3;

/// The implicit system's per-particle vectors a substep's set-up writes: the residual
/// r = b − A x₀, the block-Jacobi preconditioner and the warm start x₀ (zeroed where filtered).
pub(crate) struct SystemRows<'a> {
    /// Inverse masses.
    pub w: &'a [f64],
    /// The external accelerations.
    pub accel: &'a [DVec3],
    /// The warm start x₀ of Δv (zero without one).
    pub x0: &'a mut [DVec3],
    /// The residual (written).
    pub r: &'a mut [DVec3],
    /// The inverse diagonal blocks of A (written).
    pub pinv: &'a mut [Sym3],
}

impl RayStencil {
    /// Linearises the springs at the state of the last [`RayStencil::load_state`] and writes
    /// the rows of the implicit system at its substep h to `rows`: r = b − A x₀ and the
    /// inverse of A's diagonal block (b = h M a_ext + the springs' share, A x₀ = M x₀ + the
    /// springs'); zeros, and x₀ = 0, where w = 0. Each chunk linearises its window and sums
    /// its rows in one task. Returns ‖b‖², the chunks' sums added in order.
    pub fn system_rows(&mut self, rows: SystemRows<'_>, warm: bool, path: SimdPath) -> f64 {
        let SystemRows {
            w,
            accel,
            x0,
            r,
            pinv,
        } = rows;
        let (geo, h) = (&self.geo, self.lanes.h);
        let (windows, state, p) = self.lanes.split();
        let lanes_x0 = warm.then_some(p);
        let partials: Vec<f64> = (r.par_chunks_mut(CHUNK))
            .zip(pinv.par_chunks_mut(CHUNK))
            .zip(x0.par_chunks_mut(CHUNK))
            .zip(windows.par_iter_mut())
            .enumerate()
            .map(|(c, (((r, pinv), x0), win))| {
                state.linearize(geo, c, win, path);
                let start = c * CHUNK;
                let (w, accel) = (&w[start..start + r.len()], &accel[start..start + r.len()]);
                let chunk = Setup {
                    geo,
                    win,
                    lanes_x0,
                    start,
                    h,
                    w,
                    accel,
                    x0,
                    r,
                    pinv,
                };
                on_path(path, chunk)
            })
            .collect();
        partials.iter().sum()
    }

    /// Conjugate gradients' next direction, `p ← z + β p` (`p ← z` without β), kept in lanes
    /// as well for the [`RayStencil::system_product`] that follows: one pass.
    pub fn next_direction(&mut self, z: &[DVec3], beta: Option<f64>, p: &mut [DVec3]) {
        let Self { geo, lanes } = self;
        let (m, n) = (geo.margin, p.len());
        for d in lanes.p.iter_mut() {
            d.resize(geo.stride + 2 * m, 0.0);
        }
        let [d0, d1, d2] = (lanes.p.each_mut()).map(|d| d[m..m + n].par_chunks_mut(CHUNK));
        (d0, d1, d2, p.par_chunks_mut(CHUNK), z.par_chunks(CHUNK))
            .into_par_iter()
            .for_each(|(d0, d1, d2, p, z)| {
                for (i, (p, z)) in p.iter_mut().zip(z).enumerate() {
                    *p = match beta {
                        Some(beta) => *z + *p * beta,
                        None => *z,
                    };
                    (d0[i], d1[i], d2[i]) = (p.x, p.y, p.z);
                }
            });
        lanes.direction = true;
    }

    /// q ← A p for the whole system, A = M + the springs (M = 1/w), zero on the rows of
    /// particles with w = 0 (Baraff & Witkin's filter), where these springs are all there are:
    /// one pass, the general product's arithmetic. Returns p·q, the chunks' sums added in
    /// order. `p` is the last [`RayStencil::next_direction`]'s where one came since.
    pub fn system_product(
        &mut self,
        w: &[f64],
        p: &[DVec3],
        q: &mut [DVec3],
        path: SimdPath,
    ) -> f64 {
        let Self { geo, lanes } = self;
        if !std::mem::take(&mut lanes.direction) {
            load(&mut lanes.p, geo.margin, geo.stride + 2 * geo.margin, p);
        }
        let (geo, windows, lanes_p) = (&*geo, &lanes.windows, &lanes.p);
        let partials: Vec<f64> = (q.par_chunks_mut(CHUNK))
            .zip(p.par_chunks(CHUNK).zip(w.par_chunks(CHUNK)))
            .enumerate()
            .map(|(c, (q, (p, w)))| {
                let (start, win) = (c * CHUNK, &windows[c][..]);
                let rows = Rows { p, w, q };
                on_path(
                    path,
                    System {
                        geo,
                        win,
                        p: lanes_p,
                        start,
                        rows,
                    },
                )
            })
            .collect();
        partials.iter().sum()
    }
}

/// One chunk's rows of a system product: p, the inverse masses and q.
struct Rows<'a> {
    p: &'a [DVec3],
    w: &'a [f64],
    q: &'a mut [DVec3],
}

/// q ← A p for one chunk of particles from `start` (see [`RayStencil::system_product`]);
/// `win`: the chunk's window.
struct System<'a> {
    geo: &'a Geometry,
    win: &'a [Vec<f64>],
    p: &'a [Vec<f64>; 3],
    start: usize,
    rows: Rows<'a>,
}

impl LaneKernel for System<'_> {
    type Output = f64;

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> f64 {
        let System {
            geo,
            win,
            p: lanes_p,
            start,
            rows: Rows { p, w, q },
        } = self;
        let f = Ops(s);
        let mut pq = 0.0;
        for j in (0..q.len()).step_by(L) {
            let at = geo.at(start, j);
            let sum = ray_sum::<S, L>(f, geo, win, lanes_p, at);
            let t = store3::<S, L>(&sum);
            let end = L.min(q.len() - j);
            for l in 0..end {
                let i = j + l;
                // The general product's order: M p, the springs, then the filter.
                q[i] = match w[i] > 0.0 {
                    true => p[i] / w[i] + lane(&t, l),
                    false => DVec3::ZERO,
                };
                if w[i] > 0.0 {
                    pq += p[i].dot(q[i]);
                }
            }
        }
        pq
    }
}

/// One chunk's rows of the implicit system (see [`RayStencil::system_rows`]); `win`: the
/// chunk's window.
struct Setup<'a> {
    geo: &'a Geometry,
    win: &'a [Vec<f64>],
    lanes_x0: Option<&'a [Vec<f64>; 3]>,
    start: usize,
    h: f64,
    w: &'a [f64],
    accel: &'a [DVec3],
    x0: &'a mut [DVec3],
    r: &'a mut [DVec3],
    pinv: &'a mut [Sym3],
}

impl LaneKernel for Setup<'_> {
    type Output = f64;

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> f64 {
        let Setup {
            geo,
            win,
            lanes_x0,
            start,
            h,
            w,
            accel,
            x0,
            r,
            pinv,
        } = self;
        let mut bb = 0.0;
        for j in (0..r.len()).step_by(L) {
            let at = geo.at(start, j);
            let sums = row_sums::<S, L>(Ops(s), geo, win, lanes_x0, at);
            for l in 0..L.min(r.len() - j) {
                let k = j + l;
                // M's share first, then the springs' (the general passes' order).
                let mut row = RowSums::of_mass(w[k], accel[k], x0[k], h);
                row.add(1.0, sums.b(l), sums.ax(l), sums.d(l));
                bb += row.finish(w[k], &mut r[k], &mut pinv[k], &mut x0[k]);
            }
        }
        bb
    }
}
