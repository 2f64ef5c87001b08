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
//! Every shape with a Hessian here has one of rank-one-times-projector form,
//! ∂²C/∂pₖ∂pₘ = aₖ aₘ (I − n nᵀ)/ℓ ([`Curved`]), so a spring is stored in a few numbers and
//! its 3×3 blocks are never formed: the system matrix is applied spring by spring into slots
//! (one per spring and particle), and the slots summed by rows ([`crate::sparse::Rows`]).
//! Every pass runs in parallel over fixed chunks of springs, each writing its own slots.

use glam::DVec3;
use rayon::prelude::*;

use super::{Block, ConstraintSet, Dihedral, Distance, Isometric, Seam, Shape, Tether};
use crate::params::FamilyParams;
use crate::sparse::{Rows, Sym3};

/// Springs per parallel task.
const SPRINGS: usize = 512;

/// The Hessian of C in the form ∂²C/∂pₖ∂pₘ = aₖ aₘ (I − n nᵀ)/ℓ, as (a, n, 1/ℓ), where the
/// shape has one ([`Shape::curvature_product`] applies the same operator).
pub(crate) trait Curved<const N: usize>: Shape<N> {
    /// (a, n, 1/ℓ) at `p`, or `None` where the shape has no curvature term.
    fn frame(&self, p: &[DVec3; N]) -> Option<([f64; N], DVec3, f64)>;
}

/// A distance-like C = |p₀ − p₁| − d: a = (1, −1), n = (p₀ − p₁)/ℓ (as `distance_curvature`).
#[inline]
fn pair_frame(p: &[DVec3; 2]) -> Option<([f64; 2], DVec3, f64)> {
    let d = p[0] - p[1];
    let len = d.length();
    (len >= 1e-9).then(|| ([1.0, -1.0], d / len, 1.0 / len))
}

impl Curved<2> for Distance {
    fn frame(&self, p: &[DVec3; 2]) -> Option<([f64; 2], DVec3, f64)> {
        pair_frame(p)
    }
}

impl Curved<2> for Tether {
    fn frame(&self, p: &[DVec3; 2]) -> Option<([f64; 2], DVec3, f64)> {
        pair_frame(p)
    }
}

impl Curved<2> for Seam {
    fn frame(&self, p: &[DVec3; 2]) -> Option<([f64; 2], DVec3, f64)> {
        pair_frame(p)
    }
}

impl Curved<4> for Dihedral {
    fn frame(&self, _p: &[DVec3; 4]) -> Option<([f64; 4], DVec3, f64)> {
        None
    }
}

impl Curved<4> for Isometric {
    /// C = |v|, v = Σ kᵢ pᵢ: a = k, n = v/|v|, ℓ = |v| (Bergou et al. 2006).
    fn frame(&self, p: &[DVec3; 4]) -> Option<([f64; 4], DVec3, f64)> {
        let v = self.curvature(p);
        let c = v.length();
        (c >= 1e-12).then(|| (self.weights, v / c, 1.0 / c))
    }
}

/// One spring linearised for the system matrix A = M + h D + h² K of a substep h.
#[derive(Clone, Copy, Debug)]
struct Linear<const N: usize> {
    idx: [u32; N],
    grad: [DVec3; N],
    /// h² k + h c: the weight of ∇C ∇Cᵀ in A.
    sigma: f64,
    /// h² k C⁺/ℓ: the weight of aₖ aₘ (I − n nᵀ) in A (and in h² K).
    kappa: f64,
    a: [f64; N],
    n: DVec3,
}

impl<const N: usize> Default for Linear<N> {
    fn default() -> Self {
        Self {
            idx: [0; N],
            grad: [DVec3::ZERO; N],
            sigma: 0.0,
            kappa: 0.0,
            a: [0.0; N],
            n: DVec3::ZERO,
        }
    }
}

impl<const N: usize> Linear<N> {
    /// (s ∇C ∇Cᵀ + κ a aᵀ ⊗ (I − n nᵀ)) p at this spring's particles, slot by slot.
    #[inline(always)]
    fn product(&self, s: f64, p: &[DVec3]) -> [DVec3; N] {
        let dp = self.idx.map(|i| p[i as usize]);
        let g_dot = (self.grad.iter().zip(&dp)).fold(0.0, |acc, (g, d)| acc + g.dot(*d));
        let gs = g_dot * s;
        let mut out = self.grad.map(|g| g * gs);
        if self.kappa != 0.0 {
            let u = (dp.iter().zip(&self.a)).fold(DVec3::ZERO, |u, (d, a)| u + *d * *a);
            let t = (u - self.n * self.n.dot(u)) * self.kappa;
            for (o, a) in out.iter_mut().zip(&self.a) {
                *o += t * *a;
            }
        }
        out
    }
}

/// A slot's share of the right-hand side, of A x₀ and of A's diagonal block.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SlotRhs {
    /// h f − h² K v.
    pub b: DVec3,
    /// (A − M) x₀ for the warm start x₀.
    pub ax: DVec3,
    /// The diagonal block of A − M.
    pub d: Sym3,
}

/// Every spring of a constraint set, linearised at one state, aligned with the constraint
/// blocks (a disabled or degenerate spring is all zeros); slots in block order: distance,
/// dihedral, isometric, tethers, seams.
#[derive(Clone, Debug, Default)]
pub(crate) struct Springs {
    distance: Vec<Linear<2>>,
    dihedral: Vec<Linear<4>>,
    isometric: Vec<Linear<4>>,
    tethers: Vec<Linear<2>>,
    seams: Vec<Linear<2>>,
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

fn linearize<const N: usize, S: Curved<N>>(
    block: &Block<N, S>,
    params: &[FamilyParams],
    st: State<'_>,
    out: &mut Vec<Linear<N>>,
    rhs: &mut [SlotRhs],
) {
    let h = st.h;
    out.clear();
    out.resize(block.particles.len(), Linear::default());
    out.par_chunks_mut(SPRINGS)
        .zip(rhs.par_chunks_mut(SPRINGS * N))
        .enumerate()
        .for_each(|(c, (out, rhs))| {
            let base = c * SPRINGS;
            for (j, (lin, slots)) in out.iter_mut().zip(rhs.chunks_exact_mut(N)).enumerate() {
                let s = base + j;
                let idx = block.particles[s];
                let p = &params[block.group[s] as usize];
                let pos = idx.map(|i| st.x[i as usize]);
                let evaluated = p.enabled.then(|| block.shapes[s].evaluate(&pos)).flatten();
                let Some((c, grad)) = evaluated else {
                    *lin = Linear {
                        idx,
                        ..Linear::default()
                    };
                    slots.fill(SlotRhs::default());
                    continue;
                };
                let (k, damping) = (p.spring_stiffness, p.spring_damping);
                let mut lin_k = Linear {
                    idx,
                    grad,
                    sigma: h * h * k,
                    kappa: 0.0,
                    a: [0.0; N],
                    n: DVec3::ZERO,
                };
                if c > 0.0 && k > 0.0 {
                    if let Some((a, n, inv_len)) = block.shapes[s].frame(&pos) {
                        lin_k.kappa = h * h * k * c * inv_len;
                        lin_k.a = a;
                        lin_k.n = n;
                    }
                }
                let c_dot: f64 = (0..N).map(|m| grad[m].dot(st.v[idx[m] as usize])).sum();
                let force = -(k * c + damping * c_dot);
                // b = h f − h² K v (Baraff & Witkin eq. 6, spring part).
                let kv = lin_k.product(h * h * k, st.v);
                *lin = Linear {
                    sigma: h * h * k + h * damping,
                    ..lin_k
                };
                let ax = st.x0.map(|x0| lin.product(lin.sigma, x0));
                for m in 0..N {
                    let d = Sym3::outer(grad[m], lin.sigma);
                    let d = if lin.kappa != 0.0 {
                        d.add(Sym3::projector(lin.n, lin.kappa * lin.a[m] * lin.a[m]))
                    } else {
                        d
                    };
                    slots[m] = SlotRhs {
                        b: grad[m] * (h * force) - kv[m],
                        ax: ax.map_or(DVec3::ZERO, |ax| ax[m]),
                        d,
                    };
                }
            }
        });
}

fn product<const N: usize>(springs: &[Linear<N>], p: &[DVec3], y: &mut [DVec3]) {
    springs
        .par_chunks(SPRINGS)
        .zip(y.par_chunks_mut(SPRINGS * N))
        .for_each(|(springs, y)| {
            for (l, y) in springs.iter().zip(y.chunks_exact_mut(N)) {
                y.copy_from_slice(&l.product(l.sigma, p));
            }
        });
}

fn owners<const N: usize, S>(block: &Block<N, S>, out: &mut Vec<u32>) {
    out.extend(block.particles.iter().flatten());
}

impl ConstraintSet {
    /// The rows of the spring operator over `n` particles (slots in [`Springs`]' order).
    pub(crate) fn spring_rows(&self, n: usize) -> Rows {
        let mut o = Vec::new();
        owners(&self.distance, &mut o);
        owners(&self.dihedral, &mut o);
        owners(&self.isometric, &mut o);
        owners(&self.tethers, &mut o);
        owners(&self.seams, &mut o);
        Rows::new(n, &o)
    }

    /// Spring counts of each block, in slot order: what [`ConstraintSet::spring_rows`] depends
    /// on.
    pub(crate) fn spring_counts(&self) -> [usize; 5] {
        [
            self.distance.particles.len(),
            self.dihedral.particles.len(),
            self.isometric.particles.len(),
            self.tethers.particles.len(),
            self.seams.particles.len(),
        ]
    }

    /// Linearises every spring at `st` into `out`, and writes each slot's share of the
    /// right-hand side, of A x₀ and of A's diagonal into `rhs` (one per slot).
    pub(crate) fn linearize(
        &self,
        params: &[FamilyParams],
        st: State<'_>,
        out: &mut Springs,
        rhs: &mut Vec<SlotRhs>,
    ) {
        let [r_d, r_b, r_i, r_t, r_s] = slot_blocks(self.spring_counts(), rhs);
        linearize(&self.distance, params, st, &mut out.distance, r_d);
        linearize(&self.dihedral, params, st, &mut out.dihedral, r_b);
        linearize(&self.isometric, params, st, &mut out.isometric, r_i);
        linearize(&self.tethers, params, st, &mut out.tethers, r_t);
        linearize(&self.seams, &self.seam_params, st, &mut out.seams, r_s);
    }
}

/// Slots each spring of a block owns, block by block in slot order: distance, dihedral,
/// isometric, tethers, seams (the order of [`ConstraintSet::spring_rows`]).
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

impl Springs {
    /// Writes (A − M) p = (h D + h² K) p into the slots `y` (one per slot).
    pub(crate) fn product(&self, p: &[DVec3], y: &mut Vec<DVec3>) {
        let counts = [
            self.distance.len(),
            self.dihedral.len(),
            self.isometric.len(),
            self.tethers.len(),
            self.seams.len(),
        ];
        let [y_d, y_b, y_i, y_t, y_s] = slot_blocks(counts, y);
        product(&self.distance, p, y_d);
        product(&self.dihedral, p, y_b);
        product(&self.isometric, p, y_i);
        product(&self.tethers, p, y_t);
        product(&self.seams, p, y_s);
    }
}

#[cfg(test)]
#[path = "linear_tests.rs"]
pub(crate) mod tests;
