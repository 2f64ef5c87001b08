//! The dihedral block's symmetric Gauss–Seidel sweep through the lane kernel
//! ([`super::dihedral_lanes`]): colour by colour, each colour's parts in parallel on their own
//! slices of the positions (see [`super::parts`]), then its straddlers.

use std::ops::Range;

use glam::DVec3;
use multiversion::multiversion;
use rayon::prelude::*;

use super::dihedral_lanes::{self, Quads};
use super::lanes::{Coef, Coefs};
use super::{Block, Dihedral, Rule};
use crate::domains::SimdPath;
use crate::params::FamilyParams;

/// Colours with fewer constraints than this are projected on the calling thread (a fork–join
/// costs a few µs; a lane-kernel dihedral about 20 ns).
const PARALLEL_MIN_COLOUR: usize = 512;

/// The per-group coefficients of `rule`; under PBD each half of the symmetric sweep uses
/// k' = 1 − (1 − k)^(1/2) (see [`Block::project_symmetric_lanes`]). A disabled group gets k = 0,
/// α̃ = 1, γ = 0, which leaves its constraints (whose λ stays 0) where they are.
fn coefficients(params: &[FamilyParams], rule: Rule) -> (Vec<Coef>, bool) {
    let mut damped = false;
    let coef = params
        .iter()
        .map(|p| match (p.enabled, rule) {
            (false, _) => Coef {
                k: 0.0,
                alpha: 1.0,
                gamma: 0.0,
            },
            (true, Rule::Xpbd { h }) => {
                let (alpha, gamma) = Rule::xpbd_terms(p, h);
                damped |= gamma > 0.0;
                Coef {
                    k: 1.0,
                    alpha,
                    gamma,
                }
            }
            (true, Rule::Pbd) => Coef {
                k: 1.0 - (1.0 - p.pbd_stiffness).sqrt(),
                alpha: 0.0,
                gamma: 0.0,
            },
        })
        .collect();
    (coef, damped)
}

/// One run of constraints projected on one slice of the positions.
struct Segment<'a> {
    /// The positions of particles `base ..`.
    x: &'a mut [DVec3],
    /// Global index of `x[0]`.
    base: usize,
    /// Previous positions (global), read when damped.
    prev: &'a [DVec3],
    /// Inverse masses (global).
    w: &'a [f64],
    /// The constraints' particles (global indices, all in `base .. base + x.len()`).
    idx: &'a [[u32; 4]],
    /// Their rest angles.
    shapes: &'a [Dihedral],
    /// Their parameter groups.
    groups: &'a [u32],
    /// Their multipliers.
    lambda: &'a mut [f64],
    /// Coefficients per group.
    coef: &'a [Coef],
    /// Whether any group is damped.
    damped: bool,
}

/// [`Segment`] projected on kernel path `path` (every path gives the same bits).
fn run(seg: &mut Segment, path: SimdPath) {
    match path {
        SimdPath::Avx512 => run_avx512(seg),
        SimdPath::Avx2 => run_avx2(seg),
        SimdPath::Neon => run_neon(seg),
        SimdPath::Scalar => run_scalar(seg),
    }
}

/// [`run`] compiled for AVX-512 (the baseline build where the CPU lacks it).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx512dq+avx2+fma"))]
fn run_avx512(seg: &mut Segment) {
    run_modes::<8>(seg);
}

/// [`run`] compiled for AVX2 and FMA.
#[multiversion(targets("x86_64+avx2+fma"))]
fn run_avx2(seg: &mut Segment) {
    run_modes::<4>(seg);
}

/// [`run`] compiled for NEON.
#[multiversion(targets("aarch64+neon"))]
fn run_neon(seg: &mut Segment) {
    run_modes::<2>(seg);
}

/// [`run`] compiled for the baseline target.
#[inline(never)]
fn run_scalar(seg: &mut Segment) {
    run_modes::<2>(seg);
}

#[inline(always)]
fn run_modes<const L: usize>(seg: &mut Segment) {
    if seg.damped {
        run_with::<L, true>(seg);
    } else {
        run_with::<L, false>(seg);
    }
}

/// Full chunks of `L` constraints through the `L`-lane kernel, the rest one at a time.
#[inline(always)]
fn run_with<const L: usize, const DAMPED: bool>(seg: &mut Segment) {
    let n = seg.idx.len();
    let full = n / L * L;
    for start in (0..full).step_by(L) {
        chunk::<L, DAMPED>(seg, start);
    }
    for k in full..n {
        chunk::<1, DAMPED>(seg, k);
    }
}

/// Gathers constraints `start .. start + L`, projects them, scatters the positions back.
#[inline(always)]
fn chunk<const L: usize, const DAMPED: bool>(seg: &mut Segment, start: usize) {
    let idx: &[[u32; 4]; L] = match seg.idx[start..start + L].try_into() {
        Ok(a) => a,
        Err(_) => return,
    };
    // Slice-local indices, clamped into the slice (a no-op for the block's constraints) so
    // that the loads below need no bounds checks and compile to vector gathers.
    let last = seg.x.len().saturating_sub(1);
    let mut at = [[0usize; L]; 4];
    for v in 0..4 {
        for l in 0..L {
            at[v][l] = (idx[l][v] as usize).wrapping_sub(seg.base).min(last);
        }
    }
    let mut x: Quads<L> = [[[0.0; L]; 3]; 4];
    let mut prev: Quads<L> = [[[0.0; L]; 3]; 4];
    let mut w = [[0.0; L]; 4];
    let (pos, old, mass) = (&*seg.x, seg.prev, seg.w);
    for v in 0..4 {
        for l in 0..L {
            let p = pos[at[v][l]];
            x[v][0][l] = p.x;
            x[v][1][l] = p.y;
            x[v][2][l] = p.z;
        }
        if DAMPED {
            for l in 0..L {
                let q = old[(at[v][l] + seg.base).min(old.len().saturating_sub(1))];
                prev[v][0][l] = q.x;
                prev[v][1][l] = q.y;
                prev[v][2][l] = q.z;
            }
        }
        for l in 0..L {
            w[v][l] = mass[(at[v][l] + seg.base).min(mass.len().saturating_sub(1))];
        }
    }
    let rest: [f64; L] = std::array::from_fn(|l| seg.shapes[start + l].rest);
    let coef = Coefs::from_fn(|l| seg.coef[seg.groups[start + l] as usize]);
    let lambda: &mut [f64; L] = match (&mut seg.lambda[start..start + L]).try_into() {
        Ok(a) => a,
        Err(_) => return,
    };
    dihedral_lanes::project::<L, DAMPED>(&mut x, &prev, &w, &rest, &coef, lambda);
    for v in 0..4 {
        for l in 0..L {
            seg.x[at[v][l]] = DVec3::new(x[v][0][l], x[v][1][l], x[v][2][l]);
        }
    }
}

impl Block<4, Dihedral> {
    /// One symmetric Gauss–Seidel sweep, the colours forward then backward, through the lane
    /// kernel on kernel path `path`. Each large colour's parts run in parallel, each on its own
    /// particles; the bits depend neither on the thread count nor on the path.
    ///
    /// A single forward sweep of stiff, overlapping constraints acts like the non-symmetric
    /// operator (D + L)⁻¹ instead of (D + L + U)⁻¹; its non-symmetric part is a circulatory
    /// force that can feed energy into the cloth (flutter). The backward half makes the sweep
    /// the symmetric preconditioner (D + L) D⁻¹ (D + U) (symmetric Gauss–Seidel, SSOR with
    /// ω = 1: Saad, "Iterative Methods for Sparse Linear Systems", 2nd ed., §4.1), which does
    /// not. XPBD's multipliers carry over between the halves; under PBD each half uses
    /// k' = 1 − (1 − k)^(1/2), so that the two halves together correct an isolated constraint
    /// as one projection with k would (Müller et al. 2007, §3.3).
    #[allow(clippy::too_many_arguments)]
    pub fn project_symmetric_lanes(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
        path: SimdPath,
    ) {
        if self.len() == 0 {
            return;
        }
        let (coef, damped) = coefficients(params, rule);
        let k = self.colors.len();
        for c in (0..k).chain((0..k).rev()) {
            self.project_colour(c, x, prev, w, &coef, damped, path);
        }
    }

    /// Projects colour `c`: its parts (in parallel when the colour is large), then its
    /// straddlers.
    #[allow(clippy::too_many_arguments)]
    fn project_colour(
        &mut self,
        c: usize,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        coef: &[Coef],
        damped: bool,
        path: SimdPath,
    ) {
        let seg = &self.segments[c];
        let colour = self.colors[c].clone();
        let parts = self.part_bounds.len() - 1;
        let straddle = seg[parts]..seg[parts + 1];
        let make = |r: Range<usize>| (r.start - colour.start)..(r.end - colour.start);
        let idx = &self.particles[colour.clone()];
        let shapes = &self.shapes[colour.clone()];
        let groups = &self.group[colour.clone()];
        let lambda = &mut self.lambda[colour.clone()];
        if colour.len() >= PARALLEL_MIN_COLOUR && parts > 1 {
            // Split the positions at the part boundaries and the colour's multipliers at its
            // segment boundaries; one task per part.
            let (lam_parts, lam_straddle) = lambda.split_at_mut(straddle.start - colour.start);
            let mut tasks = Vec::with_capacity(parts);
            let (mut xs, mut lams) = (&mut x[..], lam_parts);
            for p in 0..parts {
                let (xp, xr) = xs.split_at_mut(self.part_bounds[p + 1] - self.part_bounds[p]);
                let r = make(seg[p]..seg[p + 1]);
                let (lp, lr) = lams.split_at_mut(r.len());
                tasks.push(Segment {
                    x: xp,
                    base: self.part_bounds[p],
                    prev,
                    w,
                    idx: &idx[r.clone()],
                    shapes: &shapes[r.clone()],
                    groups: &groups[r],
                    lambda: lp,
                    coef,
                    damped,
                });
                (xs, lams) = (xr, lr);
            }
            tasks.par_iter_mut().for_each(|t| run(t, path));
            let r = make(straddle);
            run(
                &mut Segment {
                    x,
                    base: 0,
                    prev,
                    w,
                    idx: &idx[r.clone()],
                    shapes: &shapes[r.clone()],
                    groups: &groups[r],
                    lambda: lam_straddle,
                    coef,
                    damped,
                },
                path,
            );
        } else {
            run(
                &mut Segment {
                    x,
                    base: 0,
                    prev,
                    w,
                    idx,
                    shapes,
                    groups,
                    lambda,
                    coef,
                    damped,
                },
                path,
            );
        }
    }
}
