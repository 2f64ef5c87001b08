//! One Gauss–Seidel sweep over a domain's interior constraints: full chunks through the lane
//! kernel, each colour's remainder and the links one at a time through the one-lane kernel.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use multiversion::multiversion;

use super::domain::{Domain, Mode, Pairs};
use super::layout::{Chunk, Layout, layout_of, load_ends, store_ends};
use super::simd::SimdPath;
use crate::constraints::lanes::{self, Coef, Coefs, Ends, LANES};

/// [`Domain::project`] on the domain's kernel path (see [`SimdPath`]; every path does the same
/// IEEE operations, so results depend neither on the CPU nor on the path).
pub(super) fn sweep(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    match dom.path {
        SimdPath::Avx512 => sweep_avx512(dom, coef, mode),
        SimdPath::Avx2 => sweep_avx2(dom, coef, mode),
        SimdPath::Neon => sweep_neon(dom, coef, mode),
        SimdPath::Scalar => sweep_scalar(dom, coef, mode),
    }
}

/// [`sweep`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn sweep_avx512(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    sweep_modes::<LANES>(dom, coef, mode);
}

/// [`sweep`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn sweep_avx2(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    sweep_modes::<4>(dom, coef, mode);
}

/// [`sweep`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn sweep_neon(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    sweep_modes::<2>(dom, coef, mode);
}

/// [`sweep`] compiled for the baseline target.
#[inline(never)]
fn sweep_scalar(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    sweep_modes::<2>(dom, coef, mode);
}

/// The sweep with its optional terms chosen at compile time.
#[inline(always)]
fn sweep_modes<const W: usize>(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    match (mode.damped, mode.lambda, mode.unit_k) {
        (false, false, false) => sweep_with::<false, false, false, W>(dom, coef),
        (false, false, true) => sweep_with::<false, false, true, W>(dom, coef),
        (false, true, false) => sweep_with::<false, true, false, W>(dom, coef),
        (false, true, true) => sweep_with::<false, true, true, W>(dom, coef),
        (true, false, false) => sweep_with::<true, false, false, W>(dom, coef),
        (true, false, true) => sweep_with::<true, false, true, W>(dom, coef),
        (true, true, false) => sweep_with::<true, true, false, W>(dom, coef),
        (true, true, true) => sweep_with::<true, true, true, W>(dom, coef),
    }
}

#[inline(always)]
fn sweep_with<const DAMPED: bool, const LAMBDA: bool, const UNIT_K: bool, const W: usize>(
    dom: &mut Domain,
    coef: &[Coef],
) {
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
            project_chunk::<DAMPED, LAMBDA, UNIT_K, W>(chunk, pairs, x, prev, w, coef);
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

#[inline(always)]
fn project_chunk<const DAMPED: bool, const LAMBDA: bool, const UNIT_K: bool, const W: usize>(
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
        Layout::Contiguous => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 0, W>(chunk, pairs, x, prev, w, coef)
        }
        Layout::Paired => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 1, W>(chunk, pairs, x, prev, w, coef)
        }
        Layout::Quad => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 2, W>(chunk, pairs, x, prev, w, coef)
        }
        Layout::Strided => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 3, W>(chunk, pairs, x, prev, w, coef)
        }
        Layout::Spaced => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 4, W>(chunk, pairs, x, prev, w, coef)
        }
        Layout::Gathered => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 5, W>(chunk, pairs, x, prev, w, coef)
        }
    }
}

/// Projects a chunk in parts of `W` lanes (the path's vector width in f64), each loaded
/// straight from the layout, projected and stored before the next: the lanes of a chunk share
/// no particle, so the parts' order changes no bit.
#[inline(always)]
fn project_laid_out<
    const DAMPED: bool,
    const LAMBDA: bool,
    const UNIT_K: bool,
    const LAYOUT: u8,
    const W: usize,
>(
    chunk: &Chunk,
    pairs: &mut Pairs,
    x: &mut [Vec<f64>; 3],
    prev: &[Vec<f64>; 3],
    w: &[f64],
    coef: &[Coef],
) {
    // A structured layout needs the first lane's particles only, kept in the chunk.
    let (p0, q0) = ([chunk.p0], [chunk.q0]);
    let r = chunk.start..chunk.start + LANES;
    let (p, q): (&[u32], &[u32]) = if matches!(layout_of(LAYOUT), Layout::Gathered) {
        (&pairs.p[r.clone()], &pairs.q[r])
    } else {
        (&p0, &q0)
    };
    let [x0, x1, x2] = x;
    for off in (0..LANES).step_by(W) {
        let r = chunk.start + off..chunk.start + off + W;
        let mut e = Ends {
            p: [[0.0; W]; 3],
            q: [[0.0; W]; 3],
        };
        (e.p[0], e.q[0]) = load_ends::<LAYOUT, W>(x0, p, q, off);
        (e.p[1], e.q[1]) = load_ends::<LAYOUT, W>(x1, p, q, off);
        (e.p[2], e.q[2]) = load_ends::<LAYOUT, W>(x2, p, q, off);
        let pr = if DAMPED {
            let mut pr = e;
            for a in 0..3 {
                (pr.p[a], pr.q[a]) = load_ends::<LAYOUT, W>(&prev[a], p, q, off);
            }
            pr
        } else {
            e
        };
        let (wp, wq) = load_ends::<LAYOUT, W>(w, p, q, off);
        let mut rest = [chunk.rest; W];
        if !chunk.same_rest {
            rest.copy_from_slice(&pairs.rest[r.clone()]);
        }
        let k = if chunk.uniform {
            Coefs::splat(coef[chunk.group as usize])
        } else {
            let groups = &pairs.group[r.clone()];
            Coefs::from_fn(|l| coef[groups[l] as usize])
        };
        let mut lambda = [0.0; W];
        if LAMBDA {
            lambda.copy_from_slice(&pairs.lambda[r.clone()]);
        }
        lanes::project::<W, DAMPED, LAMBDA, UNIT_K>(&mut e, &pr, &wp, &wq, &rest, &k, &mut lambda);
        if LAMBDA {
            pairs.lambda[r].copy_from_slice(&lambda);
        }
        store_ends::<LAYOUT, W>(x0, p, q, off, &e.p[0], &e.q[0]);
        store_ends::<LAYOUT, W>(x1, p, q, off, &e.p[1], &e.q[1]);
        store_ends::<LAYOUT, W>(x2, p, q, off, &e.p[2], &e.q[2]);
    }
}

/// One end of a single constraint: position, previous position and inverse mass.
#[derive(Clone, Copy, Debug)]
pub(super) struct End {
    x: [f64; 3],
    prev: [f64; 3],
    w: f64,
}

impl End {
    /// Particle `i` of struct-of-arrays state.
    #[inline(always)]
    pub(super) fn of(x: &[Vec<f64>; 3], prev: &[Vec<f64>; 3], w: &[f64], i: usize) -> Self {
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
pub(super) fn project_one<const DAMPED: bool>(
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
    lanes::project::<1, DAMPED, true, false>(
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
