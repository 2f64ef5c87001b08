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
//! 3-vector, g (g·u) + κ u, that each of its particles reads with its weight aₖ. The dihedral
//! keeps one [`Outer`] term per particle, gₖ = √σ ∇ₖC. Every pass runs in parallel over fixed
//! chunks of springs, each writing its own terms, and each particle sums its terms in a fixed
//! order ([`crate::sparse::Terms`]).

use glam::DVec3;
use rayon::prelude::*;

use super::{Block, ConstraintSet, Distance, Isometric, Seam, Shape, Tether};
use crate::params::FamilyParams;
use crate::sparse::{Entry, Sym3, Terms};

/// Springs per parallel task.
const SPRINGS: usize = 512;

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

/// A term's share of the right-hand side, of A x₀ and of A's diagonal block, each read by a
/// particle with its weight (the diagonal with the weight squared).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TermRhs {
    /// h f − h² K v.
    pub b: DVec3,
    /// (A − M) x₀ for the warm start x₀.
    pub ax: DVec3,
    /// The diagonal block of A − M.
    pub d: Sym3,
}

/// Every spring of a constraint set, linearised at one state, aligned with the constraint
/// blocks (a disabled or degenerate spring is all zeros); terms in block order: distance,
/// dihedral, isometric, tethers, seams.
#[derive(Clone, Debug, Default)]
pub(crate) struct Springs {
    distance: Vec<Ray>,
    dihedral: Vec<Outer<4>>,
    isometric: Vec<Ray>,
    tethers: Vec<Ray>,
    seams: Vec<Ray>,
}

/// What the linearisation needs besides the springs: the state, the substep and the warm start.
#[derive(Clone, Copy)]
pub(crate) struct State<'a> {
    /// Positions.
    pub x: &'a [DVec3],
    /// Velocities.
    pub v: &'a [DVec3],
    /// The substep h.
    pub h: f64,
    /// The warm start x₀ of Δv, if any.
    pub x0: Option<&'a [DVec3]>,
}

/// Linearises a rank-one block: one ray and one [`TermRhs`] per spring.
fn linearize_rays<const N: usize, S: RankOne<N>>(
    block: &Block<N, S>,
    params: &[FamilyParams],
    st: State<'_>,
    out: &mut Vec<Ray>,
    rhs: &mut [TermRhs],
) {
    let h = st.h;
    out.clear();
    out.resize(block.particles.len(), Ray::default());
    out.par_chunks_mut(SPRINGS)
        .zip(rhs.par_chunks_mut(SPRINGS))
        .enumerate()
        .for_each(|(c, (out, rhs))| {
            let base = c * SPRINGS;
            for (j, (ray, term)) in out.iter_mut().zip(rhs.iter_mut()).enumerate() {
                let s = base + j;
                let idx = block.particles[s];
                let p = &params[block.group[s] as usize];
                let shape = &block.shapes[s];
                let a = shape.coefficients();
                let u = weighted(&a, &idx, st.x);
                let len = u.length();
                let (k, damping) = (p.spring_stiffness, p.spring_damping);
                let hhk = h * h * k;
                let (c, n, kappa) = match p.enabled.then(|| shape.value(len)).flatten() {
                    Some(c) => {
                        let kappa = if c > 0.0 && k > 0.0 {
                            hhk * c / len
                        } else {
                            0.0
                        };
                        (c, u / len, kappa)
                    }
                    // ℓ = 0 where C = ℓ (a flat isometric hinge): no direction, so no force and
                    // no damping, and κ = h² k, the limit of h² k C/ℓ.
                    None if p.enabled && S::QUADRATIC => (0.0, DVec3::ZERO, hhk),
                    None => {
                        (*ray, *term) = (Ray::default(), TermRhs::default());
                        continue;
                    }
                };
                let sigma = hhk + h * damping;
                *ray = Ray {
                    g: n * (sigma - kappa).max(0.0).sqrt(),
                    kappa,
                };
                // Ċ = Σ ∇ₖC·vₖ = n·Σ aₖ vₖ.
                let uv = weighted(&a, &idx, st.v);
                let force = -(k * c + damping * n.dot(uv));
                // h² K v = a ⊗ ((h² k − κ) n n·u_v + κ u_v); b = h f − h² K v (Baraff &
                // Witkin eq. 6, spring part).
                let kv = n * ((hhk - kappa) * n.dot(uv)) + uv * kappa;
                *term = TermRhs {
                    b: n * (h * force) - kv,
                    ax: st
                        .x0
                        .map_or(DVec3::ZERO, |x0| ray.apply(weighted(&a, &idx, x0))),
                    d: Sym3::outer(ray.g, 1.0).add(Sym3::scaled_identity(kappa)),
                };
            }
        });
}

/// Linearises a block with ∇C ∇Cᵀ alone: `N` terms and `N` [`TermRhs`] per spring.
fn linearize_outers<const N: usize, S: Shape<N>>(
    block: &Block<N, S>,
    params: &[FamilyParams],
    st: State<'_>,
    out: &mut Vec<Outer<N>>,
    rhs: &mut [TermRhs],
) {
    let h = st.h;
    out.clear();
    out.resize(block.particles.len(), [DVec3::ZERO; N]);
    out.par_chunks_mut(SPRINGS)
        .zip(rhs.par_chunks_mut(SPRINGS * N))
        .enumerate()
        .for_each(|(c, (out, rhs))| {
            let base = c * SPRINGS;
            for (j, (g, terms)) in out.iter_mut().zip(rhs.chunks_exact_mut(N)).enumerate() {
                let s = base + j;
                let idx = block.particles[s];
                let p = &params[block.group[s] as usize];
                let pos = idx.map(|i| st.x[i as usize]);
                let evaluated = p.enabled.then(|| block.shapes[s].evaluate(&pos)).flatten();
                let Some((c, grad)) = evaluated else {
                    *g = [DVec3::ZERO; N];
                    terms.fill(TermRhs::default());
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
                    terms[m] = TermRhs {
                        b: grad[m] * (h * force - h * h * k * c_dot),
                        ax: g[m] * g_x0,
                        d: Sym3::outer(g[m], 1.0),
                    };
                }
            }
        });
}

/// One term per spring: g (g·u) + κ u, u = Σ aₖ pₖ.
fn product_rays<const N: usize, S: RankOne<N>>(
    block: &Block<N, S>,
    rays: &[Ray],
    p: &[DVec3],
    t: &mut [DVec3],
) {
    rays.par_chunks(SPRINGS)
        .zip(t.par_chunks_mut(SPRINGS))
        .enumerate()
        .for_each(|(c, (rays, t))| {
            let base = c * SPRINGS;
            for (j, (ray, t)) in rays.iter().zip(t).enumerate() {
                let s = base + j;
                let u = weighted(&block.shapes[s].coefficients(), &block.particles[s], p);
                *t = ray.apply(u);
            }
        });
}

/// `N` terms per spring: gₖ (Σₘ gₘ·pₘ).
fn product_outers<const N: usize, S: Sync>(
    block: &Block<N, S>,
    outers: &[Outer<N>],
    p: &[DVec3],
    t: &mut [DVec3],
) {
    outers
        .par_chunks(SPRINGS)
        .zip(t.par_chunks_mut(SPRINGS * N))
        .enumerate()
        .for_each(|(c, (outers, t))| {
            let base = c * SPRINGS;
            for (j, (g, t)) in outers.iter().zip(t.chunks_exact_mut(N)).enumerate() {
                let idx = &block.particles[base + j];
                let s: f64 = (0..N).map(|m| g[m].dot(p[idx[m] as usize])).sum();
                for m in 0..N {
                    t[m] = g[m] * s;
                }
            }
        });
}

/// A rank-one block's entries: spring s's term, `first + s`, read by each particle with its
/// weight.
fn ray_entries<const N: usize, S: RankOne<N>>(
    block: &Block<N, S>,
    first: usize,
    out: &mut Vec<Entry>,
) {
    for (s, (idx, shape)) in block.particles.iter().zip(&block.shapes).enumerate() {
        let a = shape.coefficients();
        for m in 0..N {
            out.push(Entry {
                particle: idx[m],
                term: (first + s) as u32,
                coef: a[m],
            });
        }
    }
}

/// An outer block's entries: particle m of spring s reads term `first + N s + m`.
fn outer_entries<const N: usize, S>(block: &Block<N, S>, first: usize, out: &mut Vec<Entry>) {
    for (s, idx) in block.particles.iter().enumerate() {
        for (m, &particle) in idx.iter().enumerate() {
            out.push(Entry {
                particle,
                term: (first + N * s + m) as u32,
                coef: 1.0,
            });
        }
    }
}

impl ConstraintSet {
    /// The terms of the spring operator over `n` particles (in [`Springs`]' order).
    pub(crate) fn spring_terms(&self, n: usize) -> Terms {
        let counts = self.spring_counts();
        let mut first = [0; 5];
        for k in 1..5 {
            first[k] = first[k - 1] + counts[k - 1] * TERMS_PER_SPRING[k - 1];
        }
        let mut e = Vec::new();
        ray_entries(&self.distance, first[0], &mut e);
        outer_entries(&self.dihedral, first[1], &mut e);
        ray_entries(&self.isometric, first[2], &mut e);
        ray_entries(&self.tethers, first[3], &mut e);
        ray_entries(&self.seams, first[4], &mut e);
        Terms::new(n, &e)
    }

    /// Spring counts of each block, in slot order: what [`ConstraintSet::spring_rows`] and
    /// [`ConstraintSet::spring_terms`] depend on.
    pub(crate) fn spring_counts(&self) -> [usize; 5] {
        [
            self.distance.particles.len(),
            self.dihedral.particles.len(),
            self.isometric.particles.len(),
            self.tethers.particles.len(),
            self.seams.particles.len(),
        ]
    }

    /// Linearises every spring at `st` into `out`, and writes each term's share of the
    /// right-hand side, of A x₀ and of A's diagonal into `rhs` (one per term).
    pub(crate) fn linearize(
        &self,
        params: &[FamilyParams],
        st: State<'_>,
        out: &mut Springs,
        rhs: &mut Vec<TermRhs>,
    ) {
        let [r_d, r_b, r_i, r_t, r_s] = cut(self.spring_counts(), TERMS_PER_SPRING, rhs);
        linearize_rays(&self.distance, params, st, &mut out.distance, r_d);
        linearize_outers(&self.dihedral, params, st, &mut out.dihedral, r_b);
        linearize_rays(&self.isometric, params, st, &mut out.isometric, r_i);
        linearize_rays(&self.tethers, params, st, &mut out.tethers, r_t);
        linearize_rays(&self.seams, &self.seam_params, st, &mut out.seams, r_s);
    }

    /// Writes each term of (A − M) p = (h D + h² K) p into `t`, for `springs` linearised on
    /// this set.
    pub(crate) fn spring_product(&self, springs: &Springs, p: &[DVec3], t: &mut Vec<DVec3>) {
        let [t_d, t_b, t_i, t_t, t_s] = cut(self.spring_counts(), TERMS_PER_SPRING, t);
        product_rays(&self.distance, &springs.distance, p, t_d);
        product_outers(&self.dihedral, &springs.dihedral, p, t_b);
        product_rays(&self.isometric, &springs.isometric, p, t_i);
        product_rays(&self.tethers, &springs.tethers, p, t_t);
        product_rays(&self.seams, &springs.seams, p, t_s);
    }
}

/// Slots each spring of a block owns in the explicit force pass, block by block: distance,
/// dihedral, isometric, tethers, seams (the order of [`ConstraintSet::spring_rows`]).
const SLOTS_PER_SPRING: [usize; 5] = [2, 4, 4, 2, 2];

/// Terms each spring of a block owns in the implicit system, in the same block order.
const TERMS_PER_SPRING: [usize; 5] = [1, 4, 1, 1, 1];

/// `v` resized to hold `per[k]` entries for each of `counts[k]` springs of block k, cut into
/// the blocks' parts, in block order.
fn cut<T: Clone + Default>(counts: [usize; 5], per: [usize; 5], v: &mut Vec<T>) -> [&mut [T]; 5] {
    let lens = std::array::from_fn::<_, 5, _>(|k| counts[k] * per[k]);
    v.resize(lens.iter().sum(), T::default());
    let mut rest = &mut v[..];
    lens.map(|len| {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        rest = tail;
        head
    })
}

/// `slots` resized to hold every slot of `counts` springs per block, cut into the blocks'
/// slots, in slot order.
pub(super) fn slot_blocks<T: Clone + Default>(
    counts: [usize; 5],
    slots: &mut Vec<T>,
) -> [&mut [T]; 5] {
    cut(counts, SLOTS_PER_SPRING, slots)
}

#[cfg(test)]
#[path = "linear_tests.rs"]
pub(crate) mod tests;
