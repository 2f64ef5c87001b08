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

use glam::DVec3;

use super::{Block, ConstraintSet, Dihedral, Distance, Isometric, Seam, Shape, Tether};
use crate::params::FamilyParams;

/// One spring evaluated at the current state.
#[derive(Clone, Copy, Debug)]
struct Linear<const N: usize, S> {
    idx: [u32; N],
    shape: S,
    pos: [DVec3; N],
    grad: [DVec3; N],
    /// Stiffness k.
    k: f64,
    /// Damping c.
    c: f64,
    /// max(C, 0): the weight of the curvature term.
    tension: f64,
    /// The force magnitude −(k C + c Ċ) along ∇C.
    force: f64,
}

/// Every enabled spring of a constraint set, linearised at one state.
#[derive(Clone, Debug, Default)]
pub(crate) struct Springs {
    distance: Vec<Linear<2, Distance>>,
    dihedral: Vec<Linear<4, Dihedral>>,
    isometric: Vec<Linear<4, Isometric>>,
    tethers: Vec<Linear<2, Tether>>,
    seams: Vec<Linear<2, Seam>>,
}

fn linearize<const N: usize, S: Shape<N>>(
    block: &Block<N, S>,
    x: &[DVec3],
    v: &[DVec3],
    params: &[FamilyParams],
    out: &mut Vec<Linear<N, S>>,
) {
    out.clear();
    for ((idx, shape), &g) in block.particles.iter().zip(&block.shapes).zip(&block.group) {
        let p = &params[g as usize];
        if !p.enabled {
            continue;
        }
        let pos = idx.map(|i| x[i as usize]);
        let Some((c, grad)) = shape.evaluate(&pos) else {
            continue;
        };
        let c_dot: f64 = (0..N).map(|k| grad[k].dot(v[idx[k] as usize])).sum();
        out.push(Linear {
            idx: *idx,
            shape: *shape,
            pos,
            grad,
            k: p.spring_stiffness,
            c: p.spring_damping,
            tension: c.max(0.0),
            force: -(p.spring_stiffness * c + p.spring_damping * c_dot),
        });
    }
}

impl<const N: usize, S: Shape<N>> Linear<N, S> {
    /// out += (a_k k + a_c c) ∇C (∇C·p) + a_k k C⁺ ∇²C p.
    #[inline]
    fn product(&self, a_k: f64, a_c: f64, p: &[DVec3], out: &mut [DVec3]) {
        let dp = self.idx.map(|i| p[i as usize]);
        let g_dot: f64 = (0..N).map(|k| self.grad[k].dot(dp[k])).sum();
        let s = (a_k * self.k + a_c * self.c) * g_dot;
        let curv = (self.tension > 0.0 && self.k > 0.0)
            .then(|| self.shape.curvature_product(&self.pos, &dp));
        for k in 0..N {
            let mut add = self.grad[k] * s;
            if let Some(h) = &curv {
                add += h[k] * (a_k * self.k * self.tension);
            }
            out[self.idx[k] as usize] += add;
        }
    }

    /// diag += the per-particle trace / 3 of the same operator's diagonal blocks.
    #[inline]
    fn diagonal(&self, a_k: f64, a_c: f64, diag: &mut [f64]) {
        let s = a_k * self.k + a_c * self.c;
        for k in 0..N {
            diag[self.idx[k] as usize] += s * self.grad[k].length_squared() / 3.0;
        }
    }
}

impl ConstraintSet {
    /// Linearises every enabled spring at positions `x` and velocities `v` into `out`.
    pub(crate) fn linearize(
        &self,
        x: &[DVec3],
        v: &[DVec3],
        params: &[FamilyParams],
        out: &mut Springs,
    ) {
        linearize(&self.distance, x, v, params, &mut out.distance);
        linearize(&self.dihedral, x, v, params, &mut out.dihedral);
        linearize(&self.isometric, x, v, params, &mut out.isometric);
        linearize(&self.tethers, x, v, params, &mut out.tethers);
        linearize(&self.seams, x, v, &self.seam_params, &mut out.seams);
    }
}

impl Springs {
    /// Adds every spring force −(k C + c Ċ) ∇C to `f` (N), in a fixed order.
    pub fn add_forces(&self, f: &mut [DVec3]) {
        fn add<const N: usize, S>(s: &[Linear<N, S>], f: &mut [DVec3]) {
            for l in s {
                for k in 0..N {
                    f[l.idx[k] as usize] += l.grad[k] * l.force;
                }
            }
        }
        add(&self.distance, f);
        add(&self.dihedral, f);
        add(&self.isometric, f);
        add(&self.tethers, f);
        add(&self.seams, f);
    }

    /// Adds (a_k K + a_c D) p to `out`, with K = −∂f/∂x and D = −∂f/∂v as above, in a fixed order.
    pub fn add_product(&self, a_k: f64, a_c: f64, p: &[DVec3], out: &mut [DVec3]) {
        for l in &self.distance {
            l.product(a_k, a_c, p, out);
        }
        for l in &self.dihedral {
            l.product(a_k, a_c, p, out);
        }
        for l in &self.isometric {
            l.product(a_k, a_c, p, out);
        }
        for l in &self.tethers {
            l.product(a_k, a_c, p, out);
        }
        for l in &self.seams {
            l.product(a_k, a_c, p, out);
        }
    }

    /// Adds a scalar per particle approximating the diagonal of a_k K + a_c D (its Gauss–Newton
    /// part's trace / 3): the Jacobi preconditioner's share.
    pub fn add_diagonal(&self, a_k: f64, a_c: f64, diag: &mut [f64]) {
        for l in &self.distance {
            l.diagonal(a_k, a_c, diag);
        }
        for l in &self.dihedral {
            l.diagonal(a_k, a_c, diag);
        }
        for l in &self.isometric {
            l.diagonal(a_k, a_c, diag);
        }
        for l in &self.tethers {
            l.diagonal(a_k, a_c, diag);
        }
        for l in &self.seams {
            l.diagonal(a_k, a_c, diag);
        }
    }
}
