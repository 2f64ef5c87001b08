//! Springs linearised at the current state: the force −(k C + c Ċ)∇C of every constraint and
//! its Jacobians, for the implicit mass-spring method (Baraff & Witkin 1998, §5).
//!
//! For a spring on constraint C with stiffness k and damping c,
//!
//! ```text
//! −∂f/∂x = k (∇C ∇Cᵀ + C ∇²C)      −∂f/∂v = c ∇C ∇Cᵀ
//! ```
//!
//! (the damping force's own position derivative is dropped, as Baraff & Witkin do). The
//! curvature term C ∇²C is kept only while C > 0 (a stretched distance spring, whose ∇²C is
//! positive semi-definite), so −∂f/∂x stays positive semi-definite and the implicit system
//! symmetric positive definite (Choi & Ko 2002 make the same choice against buckling
//! instability); shapes without a closed-form Hessian (the dihedral) use ∇C ∇Cᵀ alone.
//!
//! Every shape with a Hessian here is rank one ([`RankOne`]): ∇ₖC = aₖ n and
//! ∂²C/∂pₖ∂pₘ = aₖ aₘ (I − n nᵀ)/ℓ, with u = Σ aₖ pₖ, ℓ = |u| and n = u/ℓ. Its share of
//! A − M = h D + h² K is then a aᵀ ⊗ (g gᵀ + κ I), with
//!
//! ```text
//! κ = h² k C⁺/ℓ      g = n √(h² k + h c − κ)
//! ```
//!
//! (σ n nᵀ + κ (I − n nᵀ) written as (σ − κ) n nᵀ + κ I, σ = h² k + h c; σ ≥ κ as the rest
//! length is not negative), so a spring is one [`Ray`] of four numbers and its product one
//! 3-vector, g (g·u) + κ u, that each of its particles adds with its weight aₖ. The dihedral
//! keeps one [`Outer`] term per particle, gₖ = √σ ∇ₖC. Each pass adds every spring's terms
//! straight into its particles' rows: the springs of each particle range ([`PassOrder`]) in
//! one task, the ranges in parallel, then the few springs that straddle ranges, so each
//! particle sums its terms in a fixed order whatever the thread count. Nothing per spring is
//! stored but the ray.

use glam::DVec3;
use rayon::prelude::*;

use super::linear_rows::{RowSums, State};
use super::ray_stencil::RayStencil;
use super::{Block, ConstraintSet, Distance, Isometric, Seam, Shape, Tether};
use crate::params::FamilyParams;
use crate::sparse::Sym3;
use weft_simd::SimdPath;

/// A shape whose gradient is one direction weighted per particle, ∇ₖC = aₖ n, and whose
/// Hessian is ∂²C/∂pₖ∂pₘ = aₖ aₘ (I − n nᵀ)/ℓ, with u = Σ aₖ pₖ, ℓ = |u| and n = u/ℓ.
pub(crate) trait RankOne<const N: usize>: Shape<N> {
    /// The weights a.
    fn coefficients(&self) -> [f64; N];

    /// C = ℓ (no rest length): the energy ½ k |u|² has the Hessian k a aᵀ ⊗ I everywhere, at
    /// ℓ = 0 too, where n and the damping have no direction.
    const QUADRATIC: bool = false;

    /// C at ℓ = |u|, or `None` where [`Shape::evaluate`] gives none.
    fn value(&self, len: f64) -> Option<f64>;
}

impl RankOne<2> for Distance {
    fn coefficients(&self) -> [f64; 2] {
        [1.0, -1.0]
    }

    fn value(&self, len: f64) -> Option<f64> {
        (len >= 1e-9).then_some(len - self.rest)
    }
}

impl RankOne<2> for Tether {
    fn coefficients(&self) -> [f64; 2] {
        [1.0, -1.0]
    }

    fn value(&self, len: f64) -> Option<f64> {
        (len > self.max_length && len >= 1e-9).then_some(len - self.max_length)
    }
}

impl RankOne<2> for Seam {
    fn coefficients(&self) -> [f64; 2] {
        [1.0, -1.0]
    }

    fn value(&self, len: f64) -> Option<f64> {
        (len >= 1e-12).then_some(len - self.rest)
    }
}

impl RankOne<4> for Isometric {
    const QUADRATIC: bool = true;

    /// C = |v|, v = Σ kᵢ pᵢ (Bergou et al. 2006): a = k.
    fn coefficients(&self) -> [f64; 4] {
        self.weights
    }

    fn value(&self, len: f64) -> Option<f64> {
        (len >= 1e-12).then_some(len)
    }
}

/// u = Σ aₖ pₖ over a spring's particles.
#[inline(always)]
fn weighted<const N: usize>(a: &[f64; N], idx: &[u32; N], p: &[DVec3]) -> DVec3 {
    (a.iter().zip(idx)).fold(DVec3::ZERO, |u, (a, &i)| u + p[i as usize] * *a)
}

/// A rank-one spring's share of A − M: a aᵀ ⊗ (g gᵀ + κ I) (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Ray {
    g: DVec3,
    kappa: f64,
}

impl Ray {
    /// (g gᵀ + κ I) u.
    #[inline(always)]
    fn apply(&self, u: DVec3) -> DVec3 {
        self.g * self.g.dot(u) + u * self.kappa
    }
}

/// A spring without a Hessian: its share of A − M is g gᵀ, g = √σ ∇C, one term per particle.
pub(crate) type Outer<const N: usize> = [DVec3; N];

/// Every spring of a constraint set, linearised at one state, each block's in its
/// [`PassOrder`] (a disabled or degenerate spring is all zeros), with those orders (set by
/// [`Springs::order`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct Springs {
    distance: Vec<Ray>,
    dihedral: Vec<Outer<4>>,
    isometric: Vec<Ray>,
    tethers: Vec<Ray>,
    seams: Vec<Ray>,
    orders: Option<[PassOrder; 5]>,
    /// The distance springs as a stencil, where they form one (a grid): they are then
    /// linearised and multiplied there, not in `distance`.
    stencil: Option<Box<RayStencil>>,
    /// The one-pass system off: its rows and products composed of the general passes.
    #[cfg(test)]
    composed: bool,
}

impl Springs {
    /// Orders the passes over `cs`'s springs for `n` particles (see [`PassOrder`]).
    pub(crate) fn order(&mut self, cs: &ConstraintSet, n: usize) {
        self.orders = Some([
            PassOrder::new(&cs.distance, n),
            PassOrder::new(&cs.dihedral, n),
            PassOrder::new(&cs.isometric, n),
            PassOrder::new(&cs.tethers, n),
            PassOrder::new(&cs.seams, n),
        ]);
        self.stencil = RayStencil::build(&cs.distance, n).map(Box::new);
    }

    /// The stencil, where its springs are all there are (no other block has any).
    pub(crate) fn sole_stencil(&mut self) -> Option<&mut RayStencil> {
        #[cfg(test)]
        if self.composed {
            return None;
        }
        let orders = self.orders.as_ref()?;
        match orders[1..].iter().all(|o| o.springs.is_empty()) {
            true => self.stencil.as_deref_mut(),
            false => None,
        }
    }

    /// Composes the system of the general passes where the stencil holds every spring (to test
    /// the one-pass system against them).
    #[cfg(test)]
    pub(crate) fn without_system_passes(&mut self) {
        self.composed = true;
    }

    /// Drops the stencil: the distance springs take the general passes (to test those).
    #[cfg(test)]
    pub(crate) fn without_stencil(&mut self) {
        self.stencil = None;
    }
}

/// Springs per particle range of the implicit passes, at least.
const PER_PART: usize = 1024;

/// Particle ranges of the implicit passes at most: more leave more springs straddling ranges,
/// which run alone.
const MAX_PARTS: usize = 8;

/// The order in which the implicit passes visit a block's springs: the particles cut into
/// ranges (their number a power of two and a function of the spring count alone, never of the
/// thread count), the springs of each range in insertion order, then those that straddle
/// ranges.
#[derive(Clone, Debug, Default)]
pub(crate) struct PassOrder {
    /// Particle range p is `bounds[p] .. bounds[p + 1]`.
    bounds: Vec<usize>,
    /// The springs in pass order.
    springs: Vec<u32>,
    /// Range p's springs are `springs[starts[p] .. starts[p + 1]]`; the straddlers, the last.
    starts: Vec<usize>,
}

impl PassOrder {
    /// The pass order of `block`'s springs over `n` particles.
    fn new<const N: usize, S>(block: &Block<N, S>, n: usize) -> Self {
        let len = block.particles.len();
        // A power of two, so that the ranges share out evenly among 2, 4 or 8 threads.
        let parts = (len / PER_PART).clamp(1, MAX_PARTS).min(n.max(1));
        let parts = 1 << parts.ilog2();
        let bounds: Vec<usize> = (0..=parts).map(|p| n * p / parts).collect();
        let mut by_insertion: Vec<u32> = (0..len as u32).collect();
        if block.order.len() == len {
            by_insertion.sort_by_key(|&s| block.order[s as usize]);
        }
        let mut buckets = vec![Vec::new(); parts + 1];
        for s in by_insertion {
            buckets[super::parts::part_of(&block.particles[s as usize], &bounds)].push(s);
        }
        let mut starts = vec![0];
        for b in &buckets {
            starts.push(starts.last().copied().unwrap_or(0) + b.len());
        }
        Self {
            bounds,
            springs: buckets.concat(),
            starts,
        }
    }
}

/// Runs `f(start, springs, per, rows, base)` over `order`'s runs of springs (from position
/// `start` of the pass order, `per` their slice of the per-spring data), where `rows` holds
/// the particles from `base` on: each particle range's springs on that range's own rows, the
/// ranges in parallel, then the springs that straddle ranges on all the rows. Each range's
/// springs run in one task, so every particle receives its springs' shares in a fixed order
/// whatever the thread count.
fn by_parts<A, R, F>(order: &PassOrder, rows: &mut [A], per: &mut [R], f: F)
where
    A: Send,
    R: Send,
    F: Fn(usize, &[u32], &mut [R], &mut [A], usize) + Sync,
{
    let PassOrder {
        bounds,
        springs,
        starts,
    } = order;
    let parts = bounds.len() - 1;
    if parts < 2 {
        f(0, springs, per, rows, 0);
        return;
    }
    let (own, straddlers) = per.split_at_mut(starts[parts]);
    let mut tasks = Vec::with_capacity(parts);
    let (mut left, mut rest) = (&mut rows[..], own);
    for p in 0..parts {
        let (head, tail) = std::mem::take(&mut left).split_at_mut(bounds[p + 1] - bounds[p]);
        let (mine, others) = std::mem::take(&mut rest).split_at_mut(starts[p + 1] - starts[p]);
        tasks.push((
            starts[p],
            &springs[starts[p]..starts[p + 1]],
            mine,
            head,
            bounds[p],
        ));
        (left, rest) = (tail, others);
    }
    tasks
        .into_par_iter()
        .for_each(|(start, springs, per, rows, base)| f(start, springs, per, rows, base));
    f(
        starts[parts],
        &springs[starts[parts]..],
        straddlers,
        rows,
        0,
    );
}

/// Linearises a rank-one block: one ray per spring, its share added to its particles' rows.
fn linearize_rays<const N: usize, S: RankOne<N>>(
    (block, order): (&Block<N, S>, &PassOrder),
    params: &[FamilyParams],
    st: State<'_>,
    out: &mut Vec<Ray>,
    rows: &mut [RowSums],
) {
    out.clear();
    out.resize(block.particles.len(), Ray::default());
    by_parts(order, rows, out, |_, springs, run, rows, base| {
        for (springs, run) in springs
            .chunks(GEOMETRY_RUN)
            .zip(run.chunks_mut(GEOMETRY_RUN))
        {
            // u, ℓ and 1/ℓ first, in a loop of their own: there the square roots and
            // divisions of many springs overlap, where in the loop below each waited for the
            // last.
            let mut geometry = [(DVec3::ZERO, 0.0, 0.0); GEOMETRY_RUN];
            for (g, &s) in geometry.iter_mut().zip(springs) {
                let s = s as usize;
                let u = weighted(&block.shapes[s].coefficients(), &block.particles[s], st.x);
                let len = u.length();
                *g = (u, len, 1.0 / len);
            }
            for ((ray, &(u, len, inv)), &s) in run.iter_mut().zip(&geometry).zip(springs) {
                linearize_ray(
                    block,
                    params,
                    st,
                    s as usize,
                    (u, len, inv),
                    ray,
                    rows,
                    base,
                );
            }
        }
    });
}

/// Springs whose geometry is computed ahead of the rest of their linearisation.
const GEOMETRY_RUN: usize = 64;

/// Linearises spring `s` of a rank-one block, its u, ℓ and 1/ℓ given: its ray, and its share
/// added to the rows of its particles (`rows` holding those from `base` on).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn linearize_ray<const N: usize, S: RankOne<N>>(
    block: &Block<N, S>,
    params: &[FamilyParams],
    st: State<'_>,
    s: usize,
    (u, len, inv): (DVec3, f64, f64),
    ray: &mut Ray,
    rows: &mut [RowSums],
    base: usize,
) {
    let h = st.h;
    let idx = block.particles[s];
    let p = &params[block.group[s] as usize];
    let shape = &block.shapes[s];
    let a = shape.coefficients();
    let (k, damping) = (p.spring_stiffness, p.spring_damping);
    let hhk = h * h * k;
    let (c, n, kappa) = match p.enabled.then(|| shape.value(len)).flatten() {
        Some(c) => {
            let kappa = if c > 0.0 && k > 0.0 {
                hhk * c * inv
            } else {
                0.0
            };
            (c, u * inv, kappa)
        }
        // ℓ = 0 where C = ℓ (a flat isometric hinge): no direction, so no force and no
        // damping, and κ = h² k, the limit of h² k C/ℓ.
        None if p.enabled && S::QUADRATIC => (0.0, DVec3::ZERO, hhk),
        None => return,
    };
    let sigma = hhk + h * damping;
    *ray = Ray {
        g: n * (sigma - kappa).max(0.0).sqrt(),
        kappa,
    };
    // Ċ = Σ ∇ₖC·vₖ = n·Σ aₖ vₖ.
    let uv = weighted(&a, &idx, st.v);
    let force = -(k * c + damping * n.dot(uv));
    // h² K v = a ⊗ ((h² k − κ) n n·u_v + κ u_v); b = h f − h² K v (Baraff & Witkin eq. 6,
    // spring part).
    let kv = n * ((hhk - kappa) * n.dot(uv)) + uv * kappa;
    let b = n * (h * force) - kv;
    let ax = st
        .x0
        .map_or(DVec3::ZERO, |x0| ray.apply(weighted(&a, &idx, x0)));
    let d = Sym3::outer(ray.g, 1.0).add(Sym3::scaled_identity(kappa));
    for m in 0..N {
        rows[idx[m] as usize - base].add(a[m], b, ax, d);
    }
}

/// Linearises a block with ∇C ∇Cᵀ alone: `N` terms per spring, each added to its particle's
/// row.
fn linearize_outers<const N: usize, S: Shape<N>>(
    (block, order): (&Block<N, S>, &PassOrder),
    params: &[FamilyParams],
    st: State<'_>,
    out: &mut Vec<Outer<N>>,
    rows: &mut [RowSums],
) {
    let h = st.h;
    out.clear();
    out.resize(block.particles.len(), [DVec3::ZERO; N]);
    by_parts(order, rows, out, |_, springs, run, rows, base| {
        for (g, &s) in run.iter_mut().zip(springs) {
            let s = s as usize;
            let idx = block.particles[s];
            let p = &params[block.group[s] as usize];
            let pos = idx.map(|i| st.x[i as usize]);
            let evaluated = p.enabled.then(|| block.shapes[s].evaluate(&pos)).flatten();
            let Some((c, grad)) = evaluated else {
                continue;
            };
            let (k, damping) = (p.spring_stiffness, p.spring_damping);
            let root = (h * h * k + h * damping).sqrt();
            *g = grad.map(|d| d * root);
            let c_dot: f64 = (0..N).map(|m| grad[m].dot(st.v[idx[m] as usize])).sum();
            let force = -(k * c + damping * c_dot);
            let g_x0: f64 = st.x0.map_or(0.0, |x0| {
                (0..N).map(|m| g[m].dot(x0[idx[m] as usize])).sum()
            });
            for m in 0..N {
                rows[idx[m] as usize - base].add(
                    1.0,
                    grad[m] * (h * force - h * h * k * c_dot),
                    g[m] * g_x0,
                    Sym3::outer(g[m], 1.0),
                );
            }
        }
    });
}

/// Adds each spring's product g (g·u) + κ u, u = Σ aₖ pₖ, to its particles, weighted by aₖ.
fn product_rays<const N: usize, S: RankOne<N>>(
    (block, order): (&Block<N, S>, &PassOrder),
    rays: &[Ray],
    p: &[DVec3],
    q: &mut [DVec3],
) {
    let mut none = vec![(); rays.len()];
    by_parts(order, q, &mut none, |start, springs, _, q, base| {
        for (ray, &s) in rays[start..].iter().zip(springs) {
            let (a, idx) = (
                block.shapes[s as usize].coefficients(),
                &block.particles[s as usize],
            );
            let t = ray.apply(weighted(&a, idx, p));
            for m in 0..N {
                q[idx[m] as usize - base] += t * a[m];
            }
        }
    });
}

/// Adds each spring's gₖ (Σₘ gₘ·pₘ) to its particle k.
fn product_outers<const N: usize, S: Sync>(
    (block, order): (&Block<N, S>, &PassOrder),
    outers: &[Outer<N>],
    p: &[DVec3],
    q: &mut [DVec3],
) {
    let mut none = vec![(); outers.len()];
    by_parts(order, q, &mut none, |start, springs, _, q, base| {
        for (g, &s) in outers[start..].iter().zip(springs) {
            let idx = &block.particles[s as usize];
            let t: f64 = (0..N).map(|m| g[m].dot(p[idx[m] as usize])).sum();
            for m in 0..N {
                q[idx[m] as usize - base] += g[m] * t;
            }
        }
    });
}

impl ConstraintSet {
    /// Spring counts of each block, in slot order: what [`ConstraintSet::spring_rows`] and the
    /// implicit solve's warm start depend on.
    pub(crate) fn spring_counts(&self) -> [usize; 5] {
        [
            self.distance.particles.len(),
            self.dihedral.particles.len(),
            self.isometric.particles.len(),
            self.tethers.particles.len(),
            self.seams.particles.len(),
        ]
    }

    /// Linearises every spring at `st` into `out`, and adds each spring's share of the
    /// right-hand side, of (A − M) x₀ and of A − M's diagonal to its particles' `rows` (one per
    /// particle). `out`'s pass orders must be this set's over as many particles
    /// ([`Springs::order`]); without them nothing is added. The stencil runs on `path`.
    pub(crate) fn linearize(
        &self,
        params: &[FamilyParams],
        st: State<'_>,
        out: &mut Springs,
        rows: &mut [RowSums],
        path: SimdPath,
    ) {
        let Some([o_d, o_b, o_i, o_t, o_s]) = &out.orders else {
            return;
        };
        match out.stencil.as_deref_mut() {
            Some(stencil) => stencil.linearize(params, st, rows, path),
            None => linearize_rays((&self.distance, o_d), params, st, &mut out.distance, rows),
        }
        linearize_outers((&self.dihedral, o_b), params, st, &mut out.dihedral, rows);
        linearize_rays((&self.isometric, o_i), params, st, &mut out.isometric, rows);
        linearize_rays((&self.tethers, o_t), params, st, &mut out.tethers, rows);
        let seams = (&self.seams, o_s);
        linearize_rays(seams, &self.seam_params, st, &mut out.seams, rows);
    }

    /// Adds (A − M) p = (h D + h² K) p to `q`, for `springs` linearised on this set over as many
    /// particles as `p` holds; the stencil runs on `path`.
    pub(crate) fn spring_product(
        &self,
        springs: &mut Springs,
        p: &[DVec3],
        q: &mut [DVec3],
        path: SimdPath,
    ) {
        let Some([o_d, o_b, o_i, o_t, o_s]) = &springs.orders else {
            return;
        };
        match springs.stencil.as_deref_mut() {
            Some(stencil) => stencil.product(p, q, path),
            None => product_rays((&self.distance, o_d), &springs.distance, p, q),
        }
        product_outers((&self.dihedral, o_b), &springs.dihedral, p, q);
        product_rays((&self.isometric, o_i), &springs.isometric, p, q);
        product_rays((&self.tethers, o_t), &springs.tethers, p, q);
        product_rays((&self.seams, o_s), &springs.seams, p, q);
    }
}

/// Slots each spring of a block owns in the explicit force pass, block by block: distance,
/// dihedral, isometric, tethers, seams (the order of [`ConstraintSet::spring_rows`]).
const SLOTS_PER_SPRING: [usize; 5] = [2, 4, 4, 2, 2];

/// `slots` resized to hold every slot of `counts` springs per block, cut into the blocks'
/// slots, in slot order.
pub(super) fn slot_blocks<T: Clone + Default>(
    counts: [usize; 5],
    slots: &mut Vec<T>,
) -> [&mut [T]; 5] {
    let lens = std::array::from_fn::<_, 5, _>(|k| counts[k] * SLOTS_PER_SPRING[k]);
    slots.resize(lens.iter().sum(), T::default());
    let mut rest = &mut slots[..];
    lens.map(|len| {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        rest = tail;
        head
    })
}

#[cfg(test)]
#[path = "linear_tests.rs"]
pub(crate) mod tests;
