//! The symmetric Gauss–Seidel sweep (forward only where every constraint is soft per substep)
//! of a block of four-particle constraints (dihedral or isometric bending) through its lane
//! kernel ([`super::quad_lanes`]), decomposed by particle ranges (see [`super::parts`]): every
//! part's constraints colour by colour, the parts in parallel on their own slices of the
//! positions, then the straddlers colour by colour; the backward half in the reverse order.
//! One fork–join per half sweep instead of one per colour, and the order depends on the mesh
//! alone, never on the thread count.

use std::ops::Range;

use glam::DVec3;
use pulp::{Scalar, Simd};
use rayon::prelude::*;
use weft_simd::{LaneKernel, SimdPath, on_path};

use super::lanes::{Coef, Coefs, Quads};
use super::quad_lanes::{FrameConstants, QuadLanes};
use super::{Block, Rule};
use crate::params::FamilyParams;

/// The per-group coefficients of `rule` ([`Coef::of`]), and whether any group is damped; under
/// PBD each half of the symmetric sweep uses k' = 1 − (1 − k)^(1/2) (see
/// [`Block::project_symmetric_lanes`]).
fn coefficients(params: &[FamilyParams], rule: Rule) -> (Vec<Coef>, bool) {
    let coef: Vec<Coef> = params
        .iter()
        .map(|p| {
            let c = Coef::of(p, rule);
            match rule {
                Rule::Pbd if p.enabled => Coef {
                    k: 1.0 - (1.0 - c.k).sqrt(),
                    ..c
                },
                _ => c,
            }
        })
        .collect();
    let damped = (params.iter().zip(&coef)).any(|(p, c)| p.enabled && c.gamma > 0.0);
    (coef, damped)
}

/// What every run of one sweep shares.
struct Sweep<'a, Q: QuadLanes> {
    /// Each constraint's frame constants, or empty (then computed in the kernel).
    prepared: &'a [Q::Prepared],
    /// Previous positions (global), read when damped.
    prev: &'a [DVec3],
    /// Inverse masses (global).
    w: &'a [f64],
    /// Coefficients per group.
    coef: &'a [Coef],
    /// Whether any group is damped.
    damped: bool,
    /// The kernel path.
    path: SimdPath,
}

/// One run of constraints projected on one slice of the positions.
struct Segment<'a, Q: QuadLanes> {
    /// The positions of particles `base ..`.
    x: &'a mut [DVec3],
    /// Global index of `x[0]`.
    base: usize,
    /// The constraints' particles (global indices, all in `base .. base + x.len()`).
    idx: &'a [[u32; 4]],
    /// Their rest data.
    shapes: &'a [Q],
    /// Their parameter groups.
    groups: &'a [u32],
    /// Their multipliers.
    lambda: &'a mut [f64],
    /// The sweep's shared inputs.
    sweep: &'a Sweep<'a, Q>,
    /// The constraints' frame constants (empty: none).
    prepared: &'a [Q::Prepared],
}

/// Projects the block's constraints `r` (arrays `particles`, `shapes`, `groups`; multipliers
/// `lambda`, already sliced to `r`) on the positions `x` of particles `base ..`, on the
/// sweep's kernel path (every path gives the same bits).
#[allow(clippy::too_many_arguments)]
fn project_run<Q: QuadLanes>(
    sweep: &Sweep<Q>,
    x: &mut [DVec3],
    base: usize,
    particles: &[[u32; 4]],
    shapes: &[Q],
    groups: &[u32],
    r: Range<usize>,
    lambda: &mut [f64],
) {
    let seg = &mut Segment {
        x,
        base,
        idx: &particles[r.clone()],
        shapes: &shapes[r.clone()],
        groups: &groups[r.clone()],
        lambda,
        sweep,
        prepared: sweep.prepared.get(r).unwrap_or_default(),
    };
    if !seg.prepared.is_empty() {
        return if sweep.damped {
            run_prepared::<Q, true>(seg)
        } else {
            run_prepared::<Q, false>(seg)
        };
    }
    if !Q::WIDE {
        return Run(seg).run::<_, 1>(Scalar);
    }
    on_path(sweep.path, Run(seg))
}

/// One run of the sweep on the vectors of whatever [`Simd`] it is handed, `L` f64 lanes wide
/// ([`on_path`]: eight on the AVX-512 path, four on AVX2, two portable lanes elsewhere). Every
/// width gives the same bits.
///
/// Written with explicit vectors: left to LLVM's SLP vectoriser, the same kernel over lane
/// arrays compiled to scalar divisions and branches once inlined into the sweep (T-shirt,
/// solve only, 2 threads: 22.8 ms against 12.9 ms with `V3`; `V4` against `V3` alternated:
/// 12.1, 12.1, 12.5 against 13.1, 13.3, 14.3 ms).
struct Run<'s, 'a, Q: QuadLanes>(&'s mut Segment<'a, Q>);

impl<Q: QuadLanes> LaneKernel for Run<'_, '_, Q> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        if self.0.sweep.damped {
            run_with::<S, Q, L, true>(s, self.0);
        } else {
            run_with::<S, Q, L, false>(s, self.0);
        }
    }
}

/// Full chunks of `L` constraints through the `L`-lane kernel, the rest one at a time.
#[inline(always)]
fn run_with<S: Simd, Q: QuadLanes, const L: usize, const DAMPED: bool>(s: S, seg: &mut Segment<Q>) {
    let n = seg.idx.len();
    let full = n / L * L;
    for start in (0..full).step_by(L) {
        chunk::<S, Q, L, DAMPED>(s, seg, start);
    }
    for k in full..n {
        chunk::<Scalar, Q, 1, DAMPED>(Scalar, seg, k);
    }
}

/// Constraint after constraint with its frame constants ([`QuadLanes::project_prepared`]).
#[inline(always)]
fn run_prepared<Q: QuadLanes, const DAMPED: bool>(seg: &mut Segment<Q>) {
    for k in 0..seg.idx.len().min(seg.prepared.len()) {
        let prep = seg.prepared[k];
        gathered::<Q, 1, DAMPED>(seg, k, WithConstants(prep));
    }
}

/// Gathers constraints `start .. start + L`, projects them, scatters the positions back.
#[inline(always)]
fn chunk<S: Simd, Q: QuadLanes, const L: usize, const DAMPED: bool>(
    s: S,
    seg: &mut Segment<Q>,
    start: usize,
) {
    gathered::<Q, L, DAMPED>(seg, start, Lanes(s));
}

/// A chunk of `L` constraints gathered into lanes: positions and previous positions
/// `[particle][axis][lane]`, inverse masses, shapes, coefficients and multipliers.
struct Gather<'a, Q, const L: usize> {
    x: Quads<L>,
    prev: Quads<L>,
    w: [[f64; L]; 4],
    shapes: &'a [Q; L],
    coef: Coefs<L>,
    lambda: &'a mut [f64],
}

/// What [`gathered`] hands a chunk to. A trait rather than a closure: a closure compiles as a
/// function without the kernel path's target features, into which the kernel's intrinsics do
/// not inline (the dihedral sweep ran seven times slower through one).
trait Projector<Q: QuadLanes, const L: usize, const DAMPED: bool> {
    /// Projects the gathered constraints in place.
    fn project(self, g: &mut Gather<'_, Q, L>);
}

/// The lane kernel on the vectors of `S`.
struct Lanes<S>(S);

impl<S: Simd, Q: QuadLanes, const L: usize, const DAMPED: bool> Projector<Q, L, DAMPED>
    for Lanes<S>
{
    #[inline(always)]
    fn project(self, g: &mut Gather<'_, Q, L>) {
        Q::project_lanes::<S, L, DAMPED>(
            self.0, &mut g.x, &g.prev, &g.w, g.shapes, &g.coef, g.lambda,
        );
    }
}

/// One constraint with its frame constants.
struct WithConstants<P>(P);

impl<Q: QuadLanes, const DAMPED: bool> Projector<Q, 1, DAMPED> for WithConstants<Q::Prepared> {
    #[inline(always)]
    fn project(self, g: &mut Gather<'_, Q, 1>) {
        g.shapes[0].project_prepared::<DAMPED>(&self.0, &mut g.x, &g.prev, &g.coef, g.lambda);
    }
}

/// Gathers constraints `start .. start + L` (positions, previous positions when `DAMPED`,
/// inverse masses, shapes, coefficients, multipliers), hands them to `project`, scatters the
/// positions back.
#[inline(always)]
fn gathered<Q: QuadLanes, const L: usize, const DAMPED: bool>(
    seg: &mut Segment<Q>,
    start: usize,
    projector: impl Projector<Q, L, DAMPED>,
) {
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
    let (pos, old, mass) = (&*seg.x, seg.sweep.prev, seg.sweep.w);
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
    let shapes: &[Q; L] = match seg.shapes[start..start + L].try_into() {
        Ok(a) => a,
        Err(_) => return,
    };
    // One parameter group (one cloth) is the common case: its coefficients in every lane
    // without a per-lane lookup.
    let coef = match seg.sweep.coef {
        [one] => Coefs::splat(*one),
        all => Coefs::from_fn(|l| all[seg.groups[start + l] as usize]),
    };
    let m = Q::MULTIPLIERS;
    let Some(lambda) = seg.lambda.get_mut(start * m..(start + L) * m) else {
        return;
    };
    let mut g = Gather {
        x,
        prev,
        w,
        shapes,
        coef,
        lambda,
    };
    projector.project(&mut g);
    let x = g.x;
    for v in 0..4 {
        for l in 0..L {
            seg.x[at[v][l]] = DVec3::new(x[v][0][l], x[v][1][l], x[v][2][l]);
        }
    }
}

impl<Q: QuadLanes> Block<4, Q> {
    /// One symmetric Gauss–Seidel sweep through the lane kernel on kernel path `path`: forward,
    /// every part's constraints colour by colour (the parts in parallel, each on its own
    /// particles), then the straddlers colour by colour; backward, the same in reverse. The
    /// bits depend neither on the thread count nor on the path.
    ///
    /// A single forward sweep of stiff, overlapping constraints acts like the non-symmetric
    /// operator (D + L)⁻¹ instead of (D + L + U)⁻¹; its non-symmetric part is a circulatory
    /// force that can feed energy into the cloth (flutter). The backward half makes the sweep
    /// the symmetric preconditioner (D + L) D⁻¹ (D + U) (symmetric Gauss–Seidel, SSOR with
    /// ω = 1: Saad, "Iterative Methods for Sparse Linear Systems", 2nd ed., §4.1), which does
    /// not. XPBD's multipliers carry over between the halves; under PBD each half uses
    /// k' = 1 − (1 − k)^(1/2), so that the two halves together correct an isolated constraint
    /// as one projection with k would (Müller et al. 2007, §3.3).
    ///
    /// With `forward_only` (XPBD only, for a block that [`Self::soft_per_substep`]), the
    /// backward half is left out: there every projection's own term α̃ at least equals
    /// Σ w|∇C|², so each constraint's step is at most half its error and the coupling through
    /// shared particles at most the diagonal's, and the sweep's non-symmetric part is too weak
    /// to feed energy (`tests/integration/isometric_bending.rs` checks a free bent sheet
    /// both ways).
    #[allow(clippy::too_many_arguments)]
    pub fn project_symmetric_lanes(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
        path: SimdPath,
        forward_only: bool,
        constants: &FrameConstants<Q::Prepared>,
    ) {
        if self.len() == 0 {
            return;
        }
        // Forward only under XPBD alone: PBD's per-half stiffness assumes both halves.
        let forward_only = forward_only && matches!(rule, Rule::Xpbd { .. });
        let (coef, damped) = coefficients(params, rule);
        // The frame constants, where they hold for these inverse masses and coefficients.
        let prepared =
            if constants.values.len() == self.len() && constants.coef == coef && constants.w == w {
                &constants.values[..]
            } else {
                &[]
            };
        let sweep = Sweep {
            prepared,
            prev,
            w,
            coef: &coef,
            damped,
            path,
        };
        self.project_interiors(x, &sweep, false);
        self.project_straddlers(x, &sweep, false);
        if !forward_only {
            self.project_straddlers(x, &sweep, true);
            self.project_interiors(x, &sweep, true);
        }
    }

    /// Brings `constants` up to date for inverse masses `w`, `params` and `rule`: computed again,
    /// in parallel, only when one of them changed since. Empty for a shape that keeps none.
    pub fn prepare_constants(
        &self,
        constants: &mut FrameConstants<Q::Prepared>,
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
    ) {
        let (coef, _) = coefficients(params, rule);
        if constants.values.len() == self.len() && constants.coef == coef && constants.w == w {
            return;
        }
        let values: Option<Vec<Q::Prepared>> = (self.particles.par_iter())
            .zip(self.shapes.par_iter())
            .zip(self.group.par_iter())
            .with_min_len(4096)
            .map(|((idx, shape), &g)| {
                let c = coef.get(g as usize)?;
                let mut wi = [0.0; 4];
                for (v, &i) in wi.iter_mut().zip(idx) {
                    *v = *w.get(i as usize)?;
                }
                shape.prepare(wi, &Coefs::splat(*c))
            })
            .collect();
        constants.values = values.unwrap_or_default();
        constants.w.clear();
        constants.w.extend_from_slice(w);
        constants.coef = coef;
    }

    /// Whether every enabled constraint is soft per substep under `rule`: XPBD, Σ w|∇C|²
    /// independent of the positions ([`QuadLanes::constant_stiffness`]) and at most α̃ = α/h²
    /// with inverse masses `w`. False for an empty block, PBD, or a shape whose gradient moves.
    pub fn soft_per_substep(&self, w: &[f64], params: &[FamilyParams], rule: Rule) -> bool {
        let Rule::Xpbd { h } = rule else {
            return false;
        };
        self.len() > 0
            && (self.particles.iter().zip(&self.shapes).zip(&self.group)).all(
                |((idx, shape), &g)| {
                    let Some(p) = params.get(g as usize) else {
                        return false;
                    };
                    let (alpha, _) = Rule::xpbd_terms(p, h);
                    !p.enabled
                        || shape
                            .constant_stiffness(idx.map(|i| w[i as usize]))
                            .is_some_and(|s| s <= alpha)
                },
            )
    }

    /// Every part's constraints, colour by colour (backward: in reverse), one task per part on
    /// its own slice of the positions.
    fn project_interiors(&mut self, x: &mut [DVec3], sweep: &Sweep<Q>, backward: bool) {
        let Block {
            particles,
            shapes,
            group,
            lambda,
            segments,
            part_bounds,
            ..
        } = self;
        let parts = part_bounds.len() - 1;
        // Each part's runs, one per colour: the constraint range and its multipliers.
        let mut runs: Vec<Vec<(Range<usize>, &mut [f64])>> = (0..parts)
            .map(|_| Vec::with_capacity(segments.len()))
            .collect();
        let m = Q::MULTIPLIERS;
        let (mut rest, mut offset) = (&mut lambda[..], 0);
        for seg in segments.iter() {
            for (p, part_runs) in runs.iter_mut().enumerate() {
                let r = seg[p]..seg[p + 1];
                let (_, tail) = rest.split_at_mut((r.start - offset) * m);
                let (mine, tail) = tail.split_at_mut(r.len() * m);
                part_runs.push((r.clone(), mine));
                (rest, offset) = (tail, r.end);
            }
        }
        let mut slices = Vec::with_capacity(parts);
        let mut xs = &mut x[..];
        for p in 0..parts {
            let (xp, xr) = xs.split_at_mut(part_bounds[p + 1] - part_bounds[p]);
            slices.push((part_bounds[p], xp));
            xs = xr;
        }
        let (particles, shapes, group) = (&particles[..], &shapes[..], &group[..]);
        let project = |(base, xp): (usize, &mut [DVec3]),
                       part_runs: Vec<(Range<usize>, &mut [f64])>| {
            let mut one = |(r, lam): (Range<usize>, &mut [f64])| {
                project_run(sweep, xp, base, particles, shapes, group, r, lam)
            };
            if backward {
                part_runs.into_iter().rev().for_each(&mut one);
            } else {
                part_runs.into_iter().for_each(&mut one);
            }
        };
        if parts == 1 {
            for (slice, part_runs) in slices.into_iter().zip(runs) {
                project(slice, part_runs);
            }
        } else {
            slices
                .into_par_iter()
                .zip(runs)
                .for_each(|(slice, part_runs)| project(slice, part_runs));
        }
    }

    /// The straddlers, colour by colour (backward: in reverse), on the calling thread.
    fn project_straddlers(&mut self, x: &mut [DVec3], sweep: &Sweep<Q>, backward: bool) {
        let parts = self.part_bounds.len() - 1;
        let mut colour = |c: usize| {
            let r = self.segments[c][parts]..self.segments[c][parts + 1];
            let m = Q::MULTIPLIERS;
            let lambda = &mut self.lambda[r.start * m..r.end * m];
            project_run(
                sweep,
                x,
                0,
                &self.particles,
                &self.shapes,
                &self.group,
                r,
                lambda,
            );
        };
        let k = self.colors.len();
        if backward {
            (0..k).rev().for_each(&mut colour);
        } else {
            (0..k).for_each(&mut colour);
        }
    }
}

#[cfg(test)]
#[path = "quad_sweep_tests.rs"]
mod tests;
