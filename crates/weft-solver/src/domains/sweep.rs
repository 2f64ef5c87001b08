//! One Gauss–Seidel sweep over a domain's interior constraints: full chunks through the lane
//! kernel, each colour's remainder one at a time through the one-lane kernel, all in f32 on the
//! domain's rebased positions (see `Rebased`); the links between domains run in f64
//! ([`project_one`]).

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use multiversion::multiversion;

use super::domain::{Domain, Mode, Pairs, Rebased};
use super::layout::{Chunk, Layout, layout_of, load_ends, store_ends, window_fits};
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
    sweep_modes::<8>(dom, coef, mode);
}

/// [`sweep`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn sweep_neon(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    sweep_modes::<4>(dom, coef, mode);
}

/// [`sweep`] compiled for the baseline target.
#[inline(never)]
fn sweep_scalar(dom: &mut Domain, coef: &[Coef], mode: Mode) {
    sweep_modes::<4>(dom, coef, mode);
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
    rebase::<DAMPED>(dom);
    let n = dom.len();
    let Domain {
        work,
        pairs,
        chunks,
        plan,
        colours,
        ..
    } = dom;
    let Rebased {
        base: [b0, b1, b2],
        disp: [d0, d1, d2],
        motion: [m0, m1, m2],
        w,
    } = work;
    let work = &mut View {
        base: [&b0[..n], &b1[..n], &b2[..n]],
        disp: [&mut d0[..n], &mut d1[..n], &mut d2[..n]],
        motion: [&m0[..n], &m1[..n], &m2[..n]],
        w: &w[..n],
    };
    for (c, (chunk_range, tail)) in plan.iter().enumerate() {
        for chunk in &chunks[chunk_range.clone()] {
            project_chunk::<DAMPED, LAMBDA, UNIT_K, W>(chunk, pairs, work, coef);
        }
        for k in *tail..colours[c].end {
            let (p, q) = ([pairs.p[k]], [pairs.q[k]]);
            let rest = [pairs.rest[k]];
            let k_coef = Coefs::splat(coef[pairs.group[k] as usize]);
            project_part::<DAMPED, LAMBDA, UNIT_K, GATHERED, 1>(
                work,
                &mut pairs.lambda[k..k + 1],
                (&p, &q, 0),
                &rest,
                &k_coef,
            );
        }
    }
    fold(dom);
}

/// A domain's [`Rebased`] arrays cut to its particle count: every slice has the same length,
/// so the compiler checks an index once for all of them.
struct View<'a> {
    base: [&'a [f32]; 3],
    disp: [&'a mut [f32]; 3],
    motion: [&'a [f32]; 3],
    w: &'a [f32],
}

/// The layout number of [`Layout::Gathered`] (one load per lane), as `project_part` takes it.
const GATHERED: u8 = 5;

/// Starts a sweep: the domain's positions rebased to f32 (see [`Rebased`]), relative to its
/// first particle, with no displacement yet; for a damped sweep also x − x_prev.
#[inline(always)]
fn rebase<const DAMPED: bool>(dom: &mut Domain) {
    let n = dom.len();
    let Rebased {
        base,
        disp,
        motion,
        w,
    } = &mut dom.work;
    for a in 0..3 {
        let x = &dom.x[a][..n];
        let origin = x.first().copied().unwrap_or(0.0);
        let (b, d) = (&mut base[a][..n], &mut disp[a][..n]);
        for i in 0..n {
            b[i] = (x[i] - origin) as f32;
            d[i] = 0.0;
        }
        if DAMPED {
            let (prev, m) = (&dom.prev[a][..n], &mut motion[a][..n]);
            for i in 0..n {
                m[i] = (x[i] - prev[i]) as f32;
            }
        }
    }
    for (w32, &w) in w[..n].iter_mut().zip(&dom.w[..n]) {
        *w32 = w as f32;
    }
}

/// Ends a sweep: the displacement it accumulated added to the f64 positions (each f32 widens
/// exactly; the sum rounds in f64 like any position update).
#[inline(always)]
fn fold(dom: &mut Domain) {
    let n = dom.len();
    for a in 0..3 {
        let (x, d) = (&mut dom.x[a][..n], &dom.work.disp[a][..n]);
        for i in 0..n {
            x[i] += f64::from(d[i]);
        }
    }
}

#[inline(always)]
fn project_chunk<const DAMPED: bool, const LAMBDA: bool, const UNIT_K: bool, const W: usize>(
    chunk: &Chunk,
    pairs: &mut Pairs,
    work: &mut View<'_>,
    coef: &[Coef],
) {
    // One specialised body per layout keeps every lane array in registers (a layout
    // switch inside the per-axis loops made the compiler spill them and reload with
    // masked loads, which cannot forward from the stores).
    match chunk.layout {
        Layout::Contiguous => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 0, W>(chunk, pairs, work, coef)
        }
        Layout::Paired => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 1, W>(chunk, pairs, work, coef)
        }
        Layout::Quad => project_laid_out::<DAMPED, LAMBDA, UNIT_K, 2, W>(chunk, pairs, work, coef),
        Layout::Strided => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 3, W>(chunk, pairs, work, coef)
        }
        Layout::Spaced => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, 4, W>(chunk, pairs, work, coef)
        }
        Layout::Gathered => {
            project_laid_out::<DAMPED, LAMBDA, UNIT_K, GATHERED, W>(chunk, pairs, work, coef)
        }
    }
}

/// Projects a chunk in parts of `W` lanes (the path's vector width in f32), each loaded
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
    work: &mut View<'_>,
    coef: &[Coef],
) {
    let Pairs {
        p: all_p,
        q: all_q,
        rest: all_rest,
        group,
        lambda,
    } = pairs;
    // A structured layout needs the first lane's particles only, kept in the chunk.
    let (p0, q0) = ([chunk.p0], [chunk.q0]);
    let lanes = chunk.start..chunk.start + LANES;
    let (p, q): (&[u32], &[u32]) = if matches!(layout_of(LAYOUT), Layout::Gathered) {
        (&all_p[lanes.clone()], &all_q[lanes])
    } else {
        (&p0, &q0)
    };
    for off in (0..LANES).step_by(W) {
        let r = chunk.start + off..chunk.start + off + W;
        let mut rest = [chunk.rest; W];
        if !chunk.same_rest {
            rest.copy_from_slice(&all_rest[r.clone()]);
        }
        let k = if chunk.uniform {
            Coefs::splat(coef[chunk.group as usize])
        } else {
            let groups = &group[r.clone()];
            Coefs::from_fn(|l| coef[groups[l] as usize])
        };
        let lambda = &mut lambda[r];
        project_part::<DAMPED, LAMBDA, UNIT_K, LAYOUT, W>(work, lambda, (p, q, off), &rest, &k);
    }
}

/// Projects `W` lanes in f32 on the rebased positions: `ends` are the particle indices (or the
/// first lane's, for a structured layout) and the lanes' offset in them, `lambda` the lanes'
/// multipliers. Each end sits at base + disp; C and the step come from [`lanes::scale`], and
/// the corrections go into disp.
#[inline(always)]
fn project_part<
    const DAMPED: bool,
    const LAMBDA: bool,
    const UNIT_K: bool,
    const LAYOUT: u8,
    const W: usize,
>(
    work: &mut View<'_>,
    lambda_out: &mut [f32],
    (p, q, off): (&[u32], &[u32], usize),
    rest: &[f32; W],
    k: &Coefs<W, f32>,
) {
    assert!(
        window_fits::<LAYOUT, W>(p, q, off, work.w.len()),
        "a chunk reaches past its domain"
    );
    // Every load first, written out per axis: as a loop over the axes, the gathered layout's
    // body was too large for the compiler to unroll, and it went lane by lane through the stack.
    let ld = |src: &[f32]| load_ends::<LAYOUT, W, f32>(src, p, q, off);
    let base = [ld(work.base[0]), ld(work.base[1]), ld(work.base[2])];
    let disp = [ld(work.disp[0]), ld(work.disp[1]), ld(work.disp[2])];
    let mut pd = disp.map(|(p, _)| p);
    let mut qd = disp.map(|(_, q)| q);
    let mut d = [[0.0f32; W]; 3];
    for a in 0..3 {
        for l in 0..W {
            d[a][l] = (base[a].0[l] + pd[a][l]) - (base[a].1[l] + qd[a][l]);
        }
    }
    let mut motion = [[0.0f32; W]; 3];
    if DAMPED {
        let m = [ld(work.motion[0]), ld(work.motion[1]), ld(work.motion[2])];
        for a in 0..3 {
            for l in 0..W {
                motion[a][l] = (m[a].0[l] + pd[a][l]) - (m[a].1[l] + qd[a][l]);
            }
        }
    }
    let (wp, wq) = load_ends::<LAYOUT, W, f32>(work.w, p, q, off);
    let mut lambda = [0.0f32; W];
    if LAMBDA {
        lambda.copy_from_slice(lambda_out);
    }
    let s =
        lanes::scale::<f32, W, DAMPED, LAMBDA, UNIT_K>(&d, &motion, &wp, &wq, rest, k, &mut lambda);
    if LAMBDA {
        lambda_out.copy_from_slice(&lambda);
    }
    for a in 0..3 {
        for l in 0..W {
            pd[a][l] += d[a][l] * (wp[l] * s[l]);
            qd[a][l] -= d[a][l] * (wq[l] * s[l]);
        }
        store_ends::<LAYOUT, W, f32>(work.disp[a], p, q, off, &pd[a], &qd[a]);
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
