//! One Gauss–Seidel sweep over a domain's interior constraints: full chunks through the lane
//! kernel, each colour's remainder one at a time through the one-lane kernel, all in f32 on the
//! domain's rebased positions (see `Rebased`); the links between domains run in f64
//! ([`project_one`]).

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use multiversion::multiversion;

use super::domain::{Domain, Mode, Pairs, Rebased};
use super::layout::{ALL_LIVE, Chunk, Layout, layout_of, load_ends, store_ends, window_fits};
use crate::constraints::lanes::{self, Coef, Coefs, Ends, LANES};
use weft_simd::SimdPath;

impl Domain {
    /// One Gauss–Seidel sweep over the interior constraints, colour by colour.
    pub fn project(&mut self, coef: &[Coef], mode: Mode) {
        sweep(self, coef, mode);
    }
}

/// [`Domain::project`] on the domain's kernel path (see [`SimdPath`]; every path does the same
/// IEEE operations, so results depend neither on the CPU nor on the path).
fn sweep(dom: &mut Domain, coef: &[Coef], mode: Mode) {
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
        ..
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
                ALL_LIVE,
            );
        }
    }
    // The displacement is added to the f64 positions by whatever reads them next (see
    // `Rebased::unfolded`): usually the next substep's integration, in its own pass. The
    // links read their ends' positions, so those are added now.
    dom.settle_linked();
    dom.work.unfolded = true;
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

/// Starts a sweep: unless the fused integration just did it, the domain's positions rebased
/// to f32 (see [`Rebased`]) with no displacement yet, relative to the origin the caller gave
/// (the first particle's position at the substep's start, as the integration takes it) or else
/// the first particle's position; for a damped sweep also x − x_prev.
#[inline(always)]
fn rebase<const DAMPED: bool>(dom: &mut Domain) {
    dom.settle();
    let n = dom.len();
    let Rebased {
        base,
        disp,
        motion,
        origin,
        next_origin,
        fresh,
        ..
    } = &mut dom.work;
    let given = next_origin.take();
    for a in 0..3 {
        let x = &dom.x[a][..n];
        if !*fresh {
            origin[a] = given.map_or_else(|| x.first().copied().unwrap_or(0.0), |o| o[a]);
            let (b, d) = (&mut base[a][..n], &mut disp[a][..n]);
            for i in 0..n {
                b[i] = (x[i] - origin[a]) as f32;
                d[i] = 0.0;
            }
        }
        if DAMPED {
            let (prev, m) = (&dom.prev[a][..n], &mut motion[a][..n]);
            for i in 0..n {
                m[i] = (x[i] - prev[i]) as f32;
            }
        }
    }
    *fresh = false;
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
        Layout::Paired => project_paired::<DAMPED, LAMBDA, UNIT_K, W>(chunk, pairs, work, coef),
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
        ..
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
        project_part::<DAMPED, LAMBDA, UNIT_K, LAYOUT, W>(
            work,
            lambda,
            (p, q, off),
            &rest,
            &k,
            chunk.live,
        );
    }
}

/// Projects a [`Layout::Paired`] chunk (constraint l joins particles p₀ + 2l and p₀ + 2l + 1)
/// without de-interleaving: each part loads `W` consecutive particles as `W` slots, and every
/// slot computes its constraint from its own end's point of view, with the partner in the
/// neighbouring slot (`l ^ 1`). The second end's slot sees q − p = −(p − q), −m for the motion
/// and w_q + w_p for the denominator, all exact, and adds (q − p)(w_q s) where the lane kernel
/// subtracts (p − q)(w_q s): the same bits as [`project_part`], at one swap per value instead of
/// two shuffles per value and end.
#[inline(always)]
fn project_paired<const DAMPED: bool, const LAMBDA: bool, const UNIT_K: bool, const W: usize>(
    chunk: &Chunk,
    pairs: &mut Pairs,
    work: &mut View<'_>,
    coef: &[Coef],
) {
    const { assert!(W % 2 == 0 && (2 * LANES) % W == 0) };
    let n = work.w.len();
    for off in (0..2 * LANES).step_by(W) {
        let s0 = chunk.p0 as usize + off;
        assert!(s0 + W <= n, "a chunk reaches past its domain");
        // Constraint of slot l: start + off/2 + l/2.
        let first = chunk.start + off / 2;
        let ld = |src: &[f32]| -> [f32; W] {
            let mut out = [0.0f32; W];
            out.copy_from_slice(&src[s0..s0 + W]);
            out
        };
        let base = [ld(work.base[0]), ld(work.base[1]), ld(work.base[2])];
        let mut disp = [ld(work.disp[0]), ld(work.disp[1]), ld(work.disp[2])];
        let mut x = [[0.0f32; W]; 3];
        let mut d = [[0.0f32; W]; 3];
        for a in 0..3 {
            for l in 0..W {
                x[a][l] = base[a][l] + disp[a][l];
            }
            for l in 0..W {
                d[a][l] = x[a][l] - x[a][l ^ 1];
            }
        }
        let mut motion = [[0.0f32; W]; 3];
        if DAMPED {
            for a in 0..3 {
                let m = ld(work.motion[a]);
                let mut own = [0.0f32; W];
                for l in 0..W {
                    own[l] = m[l] + disp[a][l];
                }
                for l in 0..W {
                    motion[a][l] = own[l] - own[l ^ 1];
                }
            }
        }
        let wp = ld(work.w);
        let mut wq = [0.0f32; W];
        for l in 0..W {
            wq[l] = wp[l ^ 1];
        }
        let mut rest = [chunk.rest; W];
        if !chunk.same_rest {
            for l in 0..W {
                rest[l] = pairs.rest[first + l / 2];
            }
        }
        let k = if chunk.uniform {
            Coefs::splat(coef[chunk.group as usize])
        } else {
            Coefs::from_fn(|l| coef[pairs.group[first + l / 2] as usize])
        };
        let mut lambda = [0.0f32; W];
        if LAMBDA {
            for l in 0..W {
                lambda[l] = pairs.lambda[first + l / 2];
            }
        }
        let mut s = lanes::scale::<f32, W, DAMPED, LAMBDA, UNIT_K>(
            &d,
            &motion,
            &wp,
            &wq,
            &rest,
            &k,
            &mut lambda,
        );
        if chunk.live != ALL_LIVE {
            kill_dead(&mut s, chunk.live, |l| (off + l) / 2);
        }
        if LAMBDA {
            for j in 0..W / 2 {
                pairs.lambda[first + j] = lambda[2 * j];
            }
        }
        for a in 0..3 {
            for l in 0..W {
                disp[a][l] += d[a][l] * (wp[l] * s[l]);
            }
            work.disp[a][s0..s0 + W].copy_from_slice(&disp[a]);
        }
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
    live: u8,
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
    let mut s =
        lanes::scale::<f32, W, DAMPED, LAMBDA, UNIT_K>(&d, &motion, &wp, &wq, rest, k, &mut lambda);
    if live != ALL_LIVE {
        kill_dead(&mut s, live, |l| off + l);
    }
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

/// Forces the correction factor of every dead lane to zero (`lane` maps a slot of the part to
/// its lane in the chunk). Its corrections are then d · (w · 0) = ±0, which leave every
/// displacement as it was (a displacement is never −0: it starts at +0 and an IEEE sum is −0
/// only when both terms are), so the dead lane stores back the values it loaded.
#[inline(always)]
fn kill_dead<const W: usize>(s: &mut [f32; W], live: u8, lane: impl Fn(usize) -> usize) {
    for l in 0..W {
        if live & (1 << lane(l)) == 0 {
            s[l] = 0.0;
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rng;

    /// A domain's rebased state for a chunk test: random bases, displacements and motions of
    /// `n` particles, positive inverse masses.
    struct State {
        base: [Vec<f32>; 3],
        disp: [Vec<f32>; 3],
        motion: [Vec<f32>; 3],
        w: Vec<f32>,
    }

    impl State {
        fn random(seed: u64, n: usize) -> Self {
            let mut rnd = rng(seed);
            let mut f =
                |scale: f64| -> Vec<f32> { (0..n).map(|_| (rnd() * scale) as f32).collect() };
            let base = [f(1.0), f(1.0), f(1.0)];
            let disp = [f(1e-2), f(1e-2), f(1e-2)];
            let motion = [f(1e-2), f(1e-2), f(1e-2)];
            let w = f(1.0).iter().map(|v| v.abs() + 0.5).collect();
            Self {
                base,
                disp,
                motion,
                w,
            }
        }

        /// Runs `f` on a view of the state with its own copy of the displacements; returns
        /// them.
        fn run(&self, f: impl FnOnce(&mut View<'_>)) -> [Vec<f32>; 3] {
            let mut d = self.disp.clone();
            let [d0, d1, d2] = &mut d;
            let (b, m) = (&self.base, &self.motion);
            f(&mut View {
                base: [&b[0][..], &b[1][..], &b[2][..]],
                disp: [&mut d0[..], &mut d1[..], &mut d2[..]],
                motion: [&m[0][..], &m[1][..], &m[2][..]],
                w: &self.w[..],
            });
            d
        }
    }

    fn bits(d: &[Vec<f32>; 3]) -> Vec<u32> {
        d.iter().flatten().map(|v| v.to_bits()).collect()
    }

    /// Runs one paired chunk of 16 particles through `project_paired` and through the lane
    /// kernel's de-interleaving path; returns both results' bits (displacements, multipliers).
    fn both<const D: bool, const L: bool, const U: bool, const W: usize>(
        seed: u64,
        live: u8,
    ) -> [(Vec<u32>, Vec<u32>); 3] {
        let mut state = State::random(seed, 2 * LANES + 3);
        // One pinned particle (w = 0).
        state.w[4] = 0.0;
        let first = 1usize;
        let mut pairs = Pairs::default();
        for l in 0..LANES {
            let p = (first + 2 * l) as u32;
            pairs.push(p, p + 1, 0.3 + 0.01 * l as f64, (l % 2) as u32);
        }
        for (l, lam) in pairs.lambda.iter_mut().enumerate() {
            *lam = if L { 0.1 * l as f32 - 0.3 } else { 0.0 };
        }
        let coef: Vec<Coef> = (0..2)
            .map(|g| Coef {
                k: if U { 1.0 } else { 0.7 + 0.2 * g as f64 },
                alpha: if L { 0.05 + 0.1 * g as f64 } else { 0.0 },
                gamma: if D { 0.2 + 0.1 * g as f64 } else { 0.0 },
            })
            .collect();
        let chunk = Chunk {
            start: 0,
            layout: Layout::Paired,
            uniform: false,
            same_rest: false,
            p0: first as u32,
            q0: first as u32 + 1,
            group: 0,
            rest: pairs.rest[0],
            live,
        };
        let run = |paired: bool| {
            let mut pr = pairs.clone();
            let d = state.run(|view| {
                if paired {
                    project_paired::<D, L, U, W>(&chunk, &mut pr, view, &coef);
                } else {
                    project_laid_out::<D, L, U, 1, W>(&chunk, &mut pr, view, &coef);
                }
            });
            (bits(&d), pr.lambda.iter().map(|v| v.to_bits()).collect())
        };
        let before = bits(&state.disp);
        [run(true), run(false), (before, Vec::new())]
    }

    #[test]
    fn a_paired_chunk_projected_slot_by_slot_gives_the_lane_kernels_bits() {
        for seed in 1..6 {
            // With every lane live, and with dead lanes (a row's end).
            let checks = [
                both::<false, false, true, 8>(seed, ALL_LIVE),
                both::<false, false, false, 8>(seed, ALL_LIVE),
                both::<false, true, true, 8>(seed, ALL_LIVE),
                both::<true, true, false, 8>(seed, ALL_LIVE),
                both::<true, false, true, 4>(seed, ALL_LIVE),
                both::<true, true, false, 2>(seed, ALL_LIVE),
                both::<false, false, true, 8>(seed, 0b0111_1111),
                both::<true, true, false, 4>(seed, 0b1010_0101),
            ];
            for (i, [paired, lanes, before]) in checks.iter().enumerate() {
                assert_eq!(paired, lanes, "seed {seed}, form {i}");
                // The chunk moved particles: the comparison is not of two untouched copies.
                assert_ne!(paired.0, before.0, "seed {seed}, form {i}");
            }
        }
    }

    /// A contiguous chunk with dead lanes against its live constraints projected one at a
    /// time: the same bits, and the dead lanes' particles keep theirs.
    fn holey<const D: bool, const L: bool, const W: usize>(seed: u64, live: u8) {
        let gap = 11usize;
        let state = State::random(seed, gap + LANES + 2);
        let mut pairs = Pairs::default();
        for l in 0..LANES {
            let p = (1 + l) as u32;
            pairs.push_f32(p, p + gap as u32, 0.3 + 0.01 * l as f32, 0);
        }
        for lam in pairs.lambda.iter_mut() {
            *lam = if L { 0.2 } else { 0.0 };
        }
        let coef = [Coef {
            k: 1.0,
            alpha: if L { 0.05 } else { 0.0 },
            gamma: if D { 0.2 } else { 0.0 },
        }];
        let chunk = Chunk {
            start: 0,
            layout: Layout::Contiguous,
            uniform: true,
            same_rest: false,
            p0: 1,
            q0: 1 + gap as u32,
            group: 0,
            rest: pairs.rest[0],
            live,
        };
        let chunked = state.run(|view| {
            let mut pr = pairs.clone();
            project_laid_out::<D, L, true, 0, W>(&chunk, &mut pr, view, &coef);
        });
        let one_by_one = state.run(|view| {
            let mut pr = pairs.clone();
            for k in (0..LANES).filter(|&k| live & (1 << k) != 0) {
                let (p, q) = ([pr.p[k]], [pr.q[k]]);
                let rest = [pr.rest[k]];
                project_part::<D, L, true, GATHERED, 1>(
                    view,
                    &mut pr.lambda[k..k + 1],
                    (&p, &q, 0),
                    &rest,
                    &Coefs::splat(coef[0]),
                    ALL_LIVE,
                );
            }
        });
        assert_eq!(
            bits(&chunked),
            bits(&one_by_one),
            "seed {seed}, live {live:#010b}"
        );
        assert_ne!(
            bits(&chunked),
            bits(&state.disp),
            "seed {seed}: nothing moved"
        );
        for l in (0..LANES).filter(|l| live & (1 << l) == 0) {
            for i in [1 + l, 1 + l + gap] {
                for a in 0..3 {
                    assert_eq!(
                        chunked[a][i].to_bits(),
                        state.disp[a][i].to_bits(),
                        "dead lane {l}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_chunks_dead_lanes_write_back_what_they_read_and_its_live_ones_project() {
        for seed in 1..6 {
            for live in [0b0111_1111, 0b1000_0001, 0b0101_0110] {
                holey::<false, false, 8>(seed, live);
                holey::<false, true, 4>(seed, live);
                holey::<true, true, 8>(seed, live);
                holey::<true, false, 2>(seed, live);
            }
        }
    }
}
