//! The symmetric Gauss–Seidel sweep (forward only where every constraint is soft per substep)
//! of a block of four-particle constraints (dihedral or isometric bending) through its lane
//! kernel ([`super::dihedral_lanes`],
//! [`super::isometric_lanes`]), decomposed by particle ranges (see [`super::parts`]): every
//! part's constraints colour by colour, the parts in parallel on their own slices of the
//! positions, then the straddlers colour by colour; the backward half in the reverse order.
//! One fork–join per half sweep instead of one per colour, and the order depends on the mesh
//! alone, never on the thread count.

use std::ops::Range;

use glam::DVec3;
use pulp::{Scalar, Simd};
use rayon::prelude::*;

use super::lanes::{Coef, Coefs};
use super::{Block, Dihedral, Isometric, Rule, Shape, dihedral_lanes, isometric_lanes};
use crate::domains::SimdPath;
use crate::lane_ops::{LaneKernel, on_path};
use crate::params::FamilyParams;

/// Positions of the four particles of `L` constraints, `[particle][axis][lane]`, in the
/// order `[wing_a, wing_b, edge_0, edge_1]` of [`Dihedral`] and [`Isometric`].
pub(crate) type Quads<const L: usize> = [[[f64; L]; 3]; 4];

/// A four-particle shape with a kernel projecting `L` independent constraints at once in the
/// vectors of a [`Simd`], every lane with the same IEEE operations (the same bits on every
/// path and width).
pub(crate) trait QuadLanes: Shape<4> {
    /// Projects the constraints `shapes` (one per lane) on `x` in place, with their
    /// multipliers `lambda` (constraint `l`'s at `l * MULTIPLIERS ..`); `prev` is read only
    /// when `DAMPED`.
    #[allow(clippy::too_many_arguments)]
    fn project_lanes<S: Simd, const L: usize, const DAMPED: bool>(
        s: S,
        x: &mut Quads<L>,
        prev: &Quads<L>,
        w: &[[f64; L]; 4],
        shapes: &[Self; L],
        coef: &Coefs<L>,
        lambda: &mut [f64],
    );

    /// Σᵢ wᵢ |∇ᵢC|² of the constraint on particles of inverse masses `w` where it does not
    /// depend on the positions (per axis, for a vector constraint), else `None`.
    fn constant_stiffness(&self, _w: [f64; 4]) -> Option<f64> {
        None
    }

    /// Whether the kernel pays for its lanes: when its arithmetic outweighs moving twelve
    /// coordinates per constraint between the particles and the lanes and back. Where it does
    /// not, every kernel path projects one constraint at a time (the one-lane kernel, the
    /// same bits).
    const WIDE: bool = true;

    /// What a constraint's projection computes from the inverse masses and coefficients
    /// alone, kept over a frame ([`FrameConstants`]).
    type Prepared: Copy + Send + Sync;

    /// The constants of this constraint on particles of inverse masses `w` with `coef`, or
    /// `None` for a shape that keeps none.
    fn prepare(&self, _w: [f64; 4], _coef: &Coefs<1>) -> Option<Self::Prepared> {
        None
    }

    /// [`QuadLanes::project_lanes`] of this one constraint with its constants `prep` from
    /// [`QuadLanes::prepare`]: the same bits.
    fn project_prepared<const DAMPED: bool>(
        &self,
        prep: &Self::Prepared,
        x: &mut Quads<1>,
        prev: &Quads<1>,
        coef: &Coefs<1>,
        lambda: &mut [f64],
    );
}

/// A shape that keeps no constants: no value exists, so its
/// [`QuadLanes::project_prepared`] cannot be called.
#[derive(Clone, Copy, Debug)]
pub(crate) enum NoConstants {}

/// A block's per-constraint constants for a frame ([`QuadLanes::prepare`]) and the inverse
/// masses and coefficients they hold for: recomputed only when those change (a grab, a
/// pin, an edited parameter, a new time step).
#[derive(Clone, Debug)]
pub(crate) struct FrameConstants<P> {
    /// One per constraint, in block order; empty when the shape keeps none.
    values: Vec<P>,
    w: Vec<f64>,
    coef: Vec<Coef>,
}

impl<P> Default for FrameConstants<P> {
    fn default() -> Self {
        Self {
            values: Vec::new(),
            w: Vec::new(),
            coef: Vec::new(),
        }
    }
}

impl<P> FrameConstants<P> {
    /// The constants, one per constraint (empty: none kept).
    #[cfg(test)]
    pub fn values(&self) -> &[P] {
        &self.values
    }
}

impl QuadLanes for Dihedral {
    type Prepared = NoConstants;

    fn project_prepared<const DAMPED: bool>(
        &self,
        prep: &NoConstants,
        _x: &mut Quads<1>,
        _prev: &Quads<1>,
        _coef: &Coefs<1>,
        _lambda: &mut [f64],
    ) {
        match *prep {}
    }

    #[inline(always)]
    fn project_lanes<S: Simd, const L: usize, const DAMPED: bool>(
        s: S,
        x: &mut Quads<L>,
        prev: &Quads<L>,
        w: &[[f64; L]; 4],
        shapes: &[Self; L],
        coef: &Coefs<L>,
        lambda: &mut [f64],
    ) {
        let rest: [f64; L] = std::array::from_fn(|l| shapes[l].rest);
        let lambda: &mut [f64; L] = match lambda.try_into() {
            Ok(a) => a,
            Err(_) => return,
        };
        dihedral_lanes::project::<S, L, DAMPED>(s, x, prev, w, &rest, coef, lambda);
    }
}

impl QuadLanes for Isometric {
    /// A dozen flops per axis against twelve gathered and twelve scattered coordinates: one
    /// lane at a time is the quicker (T-shirt, solve only, 1 thread, AVX-512: 8.0 ms per
    /// frame with eight lanes, 8.1–8.5 with four, 8.8 with two, 7.2 with one).
    const WIDE: bool = false;

    /// ∇ᵢCₐ = kᵢ on axis a for every configuration: [`Isometric::stiffness`].
    fn constant_stiffness(&self, w: [f64; 4]) -> Option<f64> {
        Some(self.stiffness(w))
    }

    /// The steps wᵢkᵢ and the inverse denominator: the weights are constant, so all of the
    /// projection but the positions' part (T-shirt, 1 thread: the isometric sweep 4.4 → 3.1 ms
    /// per frame).
    type Prepared = isometric_lanes::Prepared;

    fn prepare(&self, w: [f64; 4], coef: &Coefs<1>) -> Option<isometric_lanes::Prepared> {
        Some(isometric_lanes::Prepared::new(w, self.weights, coef))
    }

    #[inline(always)]
    fn project_prepared<const DAMPED: bool>(
        &self,
        prep: &isometric_lanes::Prepared,
        x: &mut Quads<1>,
        prev: &Quads<1>,
        coef: &Coefs<1>,
        lambda: &mut [f64],
    ) {
        let Ok(lambda) = <&mut [f64; 3]>::try_from(lambda) else {
            return;
        };
        let mut lam = lambda.map(|v| [v]);
        prep.project::<DAMPED>(x, prev, self.weights, coef, &mut lam);
        *lambda = lam.map(|v| v[0]);
    }

    #[inline(always)]
    fn project_lanes<S: Simd, const L: usize, const DAMPED: bool>(
        s: S,
        x: &mut Quads<L>,
        prev: &Quads<L>,
        w: &[[f64; L]; 4],
        shapes: &[Self; L],
        coef: &Coefs<L>,
        lambda: &mut [f64],
    ) {
        let k: [[f64; L]; 4] =
            std::array::from_fn(|v| std::array::from_fn(|l| shapes[l].weights[v]));
        if lambda.len() != 3 * L {
            return;
        }
        let mut lam: [[f64; L]; 3] =
            std::array::from_fn(|a| std::array::from_fn(|l| lambda[3 * l + a]));
        isometric_lanes::project::<S, L, DAMPED>(s, x, prev, w, &k, coef, &mut lam);
        for l in 0..L {
            for a in 0..3 {
                lambda[3 * l + a] = lam[a][l];
            }
        }
    }
}

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
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::constraints::{BlockBuilder, Isometric};
    use crate::test_rand::rng;
    use crate::topology::Topology;

    /// A `n × n` grid of spacing 0.02 m, flat at rest, crumpled by up to ±`bump` in z.
    fn crumpled(n: u32, bump: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut rnd = rng(0x6a09_e667_f3bc_c909);
        let x = (0..n * n)
            .map(|i| DVec3::new(0.02 * (i % n) as f64, 0.02 * (i / n) as f64, bump * rnd()))
            .collect();
        let mut tris = Vec::new();
        for r in 0..n - 1 {
            for c in 0..n - 1 {
                let i = r * n + c;
                tris.push([i, i + 1, i + n]);
                tris.push([i + 1, i + n + 1, i + n]);
            }
        }
        (x, tris)
    }

    /// A dihedral family at compliance 0, undamped.
    fn rigid() -> FamilyParams {
        FamilyParams {
            enabled: true,
            compliance: 0.0,
            damping: 0.0,
            pbd_stiffness: 1.0,
            spring_stiffness: 0.0,
            spring_damping: 0.0,
        }
    }

    /// `sweeps` symmetric XPBD sweeps (h = 1 ms) of `block` on the widest path, each from
    /// cleared multipliers, with `prev` and inverse masses 1.
    fn sweep<Q: QuadLanes>(
        block: &mut Block<4, Q>,
        x: &mut [DVec3],
        prev: &[DVec3],
        params: &[FamilyParams],
        sweeps: usize,
    ) {
        let w = vec![1.0; x.len()];
        for _ in 0..sweeps {
            block.reset_multipliers();
            block.project_symmetric_lanes(
                x,
                prev,
                &w,
                params,
                Rule::Xpbd { h: 1e-3 },
                SimdPath::widest(),
                false,
                &FrameConstants::default(),
            );
        }
    }

    #[test]
    fn sweeps_flatten_a_crumpled_sheet_through_every_part_and_straddler() {
        let n = 48;
        let (mut x, tris) = crumpled(n, 0.004);
        let mut b = BlockBuilder::<4, Dihedral>::default();
        for wing in Topology::new(&tris).wings {
            b.push(
                [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]],
                0,
                Dihedral { rest: 0.0 },
            );
        }
        let free = vec![true; x.len()];
        let mut block = b.finish(&free);
        let parts = block.part_bounds.len() - 1;
        let straddlers: usize = (block.segments.iter())
            .map(|s| s[parts + 1] - s[parts])
            .sum();
        assert!(
            parts >= 2 && straddlers > 0,
            "{parts} parts, {straddlers} straddlers"
        );
        let prev = x.clone();
        let worst = |x: &[DVec3], block: &Block<4, Dihedral>| {
            (block.residuals(x)).fold(0.0f64, |m, c| m.max(c.abs()))
        };
        let start = worst(&x, &block);
        sweep(&mut block, &mut x, &prev, &[rigid()], 1000);
        let end = worst(&x, &block);
        // 6e-4 rad after 1,000 sweeps (bending alone converges slowly on long waves); with
        // the straddlers left out their row of hinges keeps a crease of 0.02 rad.
        assert!(
            start > 0.2 && end < 3e-3,
            "largest |θ − θ₀|: {start} → {end}"
        );
    }

    #[test]
    fn a_block_is_soft_per_substep_exactly_when_every_hinge_is() {
        // One isometric hinge per group; Σ w k² against α/h² decides, hinge by hinge.
        let rest = [
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        let shape = Isometric::at_rest(&rest).expect("a hinge");
        let w = [2.0, 1.0, 0.5, 0.0];
        let s: f64 = (0..4)
            .map(|i| w[i] * shape.weights[i] * shape.weights[i])
            .sum();
        let h = 1e-3;
        let mut b = BlockBuilder::<4, Isometric>::default();
        b.push([0, 1, 2, 3], 0, shape);
        b.push([0, 1, 2, 3], 1, shape);
        let block = b.finish(&[true, true, true, false]);
        let at = |alpha: f64| FamilyParams {
            compliance: alpha * h * h,
            ..rigid()
        };
        let xpbd = Rule::Xpbd { h };
        assert!(block.soft_per_substep(&w, &[at(1.001 * s), at(2.0 * s)], xpbd));
        assert!(!block.soft_per_substep(&w, &[at(2.0 * s), at(0.9 * s)], xpbd));
        // A disabled family does not count; PBD and the dihedral never sweep forward only.
        let off = FamilyParams {
            enabled: false,
            ..at(0.0)
        };
        assert!(block.soft_per_substep(&w, &[at(1.001 * s), off], xpbd));
        assert!(!block.soft_per_substep(&w, &[at(s), at(s)], Rule::Pbd));
        let mut d = BlockBuilder::<4, Dihedral>::default();
        d.push([0, 1, 2, 3], 0, Dihedral { rest: 0.0 });
        let d = d.finish(&[true, true, true, false]);
        assert!(!d.soft_per_substep(&w, &[at(1e9)], xpbd));
    }

    #[test]
    fn each_constraint_takes_its_own_group_coefficients() {
        // Two crumpled sheets in one block (so with more than one group, the lanes look their
        // coefficients up): group 0 rigid, group 1 disabled. The first sheet flattens, the
        // second does not move a bit.
        let n = 16;
        let (sheet, tris) = crumpled(n, 0.004);
        let count = sheet.len() as u32;
        let mut x: Vec<DVec3> = sheet.iter().chain(&sheet).copied().collect();
        let mut b = BlockBuilder::<4, Dihedral>::default();
        for wing in Topology::new(&tris).wings {
            let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
            b.push(q, 0, Dihedral { rest: 0.0 });
            b.push(q.map(|i| i + count), 1, Dihedral { rest: 0.0 });
        }
        let mut block = b.finish(&vec![true; x.len()]);
        let params = [
            rigid(),
            FamilyParams {
                enabled: false,
                ..rigid()
            },
        ];
        let prev = x.clone();
        let second = x[sheet.len()..].to_vec();
        let worst = |x: &[DVec3]| {
            let mut one = BlockBuilder::<4, Dihedral>::default();
            for wing in Topology::new(&tris).wings {
                let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
                one.push(q, 0, Dihedral { rest: 0.0 });
            }
            let one = one.finish(&vec![true; x.len()]);
            one.residuals(x).fold(0.0f64, |m, c| m.max(c.abs()))
        };
        let start = worst(&x[..sheet.len()]);
        sweep(&mut block, &mut x, &prev, &params, 200);
        let end = worst(&x[..sheet.len()]);
        assert!(start > 0.1 && end < 0.2 * start, "{start} → {end}");
        assert_eq!(x[sheet.len()..], second[..], "the disabled group moved");
    }

    #[test]
    fn the_parted_isometric_sweep_carries_each_constraints_three_multipliers() {
        // Compliant isometric hinges on a crumpled sheet cut into parts and straddlers: one
        // sweep through the parts in parallel, symmetric or forward only, equals the same
        // sweep written out one constraint at a time in the block's order, each constraint's
        // multipliers carried from the forward half into the backward one.
        let n = 48;
        let (rest, tris) = crumpled(n, 0.0);
        let (mut x, _) = crumpled(n, 0.004);
        let mut b = BlockBuilder::<4, Isometric>::default();
        for wing in Topology::new(&tris).wings {
            let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
            let shape = Isometric::at_rest(&q.map(|i| rest[i as usize])).expect("hinge");
            b.push(q, 0, shape);
        }
        let mut block = b.finish(&vec![true; x.len()]);
        let parts = block.part_bounds.len() - 1;
        assert!(parts >= 2, "{parts} parts");
        let h = 1e-3;
        // α/h² = 2500 against Σ w kᵢ² of the order of 10⁴: the multipliers matter between the
        // halves.
        let params = [FamilyParams {
            compliance: 2500.0 * h * h,
            ..rigid()
        }];
        let w = vec![1.0; x.len()];
        let colours = block.colors.len();
        let mut order: Vec<usize> = Vec::new();
        // Every part's colours (parts are disjoint: their order is free), then the straddlers'.
        for p in 0..=parts {
            for c in 0..colours {
                order.extend(block.segments[c][p]..block.segments[c][p + 1]);
            }
        }
        let start = x.clone();
        // Forward and backward, and (as a soft block sweeps) forward only.
        for forward_only in [false, true] {
            let mut want = start.clone();
            let mut lambda = vec![DVec3::ZERO; block.len()];
            let mut one = |k: usize, x: &mut [DVec3]| {
                let (q, kw) = (block.particles[k], block.shapes[k].weights);
                let p = q.map(|i| x[i as usize]);
                let s: f64 = kw.iter().map(|k| k * k).sum();
                let v = block.shapes[k].curvature(&p);
                let alpha = 2500.0;
                let dl = (-v - lambda[k] * alpha) * (1.0 / (s + alpha));
                lambda[k] += dl;
                for j in 0..4 {
                    x[q[j] as usize] += dl * kw[j];
                }
            };
            let backward = if forward_only { &[][..] } else { &order[..] };
            for &k in order.iter().chain(backward.iter().rev()) {
                one(k, &mut want);
            }
            x.copy_from_slice(&start);
            let prev = x.clone();
            block.reset_multipliers();
            block.project_symmetric_lanes(
                &mut x,
                &prev,
                &w,
                &params,
                Rule::Xpbd { h },
                SimdPath::widest(),
                forward_only,
                &FrameConstants::default(),
            );
            let worst = x
                .iter()
                .zip(&want)
                .map(|(a, b)| (*a - *b).length())
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-12,
                "forward only {forward_only}: largest difference {worst} m"
            );
        }
    }

    #[test]
    fn frame_constants_give_the_kernels_bits_and_follow_the_inverse_masses() {
        // Damped, compliant isometric hinges on a crumpled sheet, some particles pinned: a
        // symmetric sweep with the frame constants equals one computing them in the kernel, to
        // the bit, positions and multipliers; constants kept for other inverse masses are
        // refused (the sweep then computes its own), and preparing again renews them.
        let n = 32;
        let (rest, tris) = crumpled(n, 0.0);
        let (start, _) = crumpled(n, 0.004);
        let mut b = BlockBuilder::<4, Isometric>::default();
        for wing in Topology::new(&tris).wings {
            let q = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
            let shape = Isometric::at_rest(&q.map(|i| rest[i as usize])).expect("hinge");
            b.push(q, 0, shape);
        }
        let mut plain = b.finish(&vec![true; start.len()]);
        let mut kept = plain.clone();
        let h = 1e-3;
        let params = [FamilyParams {
            compliance: 300.0 * h * h,
            damping: 0.02,
            ..rigid()
        }];
        let rule = Rule::Xpbd { h };
        let mut w: Vec<f64> = (0..start.len()).map(|i| 1.0 + (i % 3) as f64).collect();
        w[0] = 0.0;
        w[n as usize - 1] = 0.0;
        let prev: Vec<DVec3> = start
            .iter()
            .map(|p| *p - DVec3::new(0.0, 0.0, 1e-3))
            .collect();
        let mut constants = FrameConstants::default();
        kept.prepare_constants(&mut constants, &w, &params, rule);
        assert_eq!(constants.values().len(), kept.len());
        let none = FrameConstants::default();
        let run = |block: &mut Block<4, Isometric>, w: &[f64], c: &FrameConstants<_>| {
            let mut x = start.clone();
            block.reset_multipliers();
            for _ in 0..3 {
                block.project_symmetric_lanes(
                    &mut x,
                    &prev,
                    w,
                    &params,
                    rule,
                    SimdPath::widest(),
                    false,
                    c,
                );
            }
            let bits: Vec<[u64; 3]> = x.iter().map(|p| p.to_array().map(f64::to_bits)).collect();
            let lambda: Vec<u64> = block.lambda.iter().map(|l| l.to_bits()).collect();
            (bits, lambda)
        };
        let want = run(&mut plain, &w, &none);
        assert_eq!(run(&mut kept, &w, &constants), want);
        assert_ne!(
            run(&mut kept, &w, &none).0,
            run(&mut kept, &[1.0; 1024][..], &none).0
        );
        // Another particle pinned: the kept constants no longer hold.
        let mut pinned = w.clone();
        pinned[n as usize * 5 + 7] = 0.0;
        let want = run(&mut plain, &pinned, &none);
        assert_eq!(run(&mut kept, &pinned, &constants), want);
        let before = constants.values().to_vec();
        kept.prepare_constants(&mut constants, &pinned, &params, rule);
        assert_ne!(constants.values(), &before[..]);
        assert_eq!(run(&mut kept, &pinned, &constants), want);
    }
}
