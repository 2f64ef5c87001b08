//! XPBD's bending step solved to a tolerance by conjugate gradients, where one Gauss–Seidel
//! sweep leaves it soft, and the residual of XPBD's equation that measures it.
//!
//! XPBD solves C(x) + α̃ λ + γ ∇C·(x − x_prev) = 0 with α̃ = α/h² (Macklin et al. 2016, eqs.
//! 9 and 26) by a Gauss–Seidel sweep on λ from λ = 0 each substep. The linearised system is
//! ((1 + γ) J W Jᵀ + α̃) Δλ = −C − α̃ λ − γ J (x − x_prev) (their eq. 12 with every constraint
//! at once), of condition about 1 + s/α̃ with s = Σᵢ wᵢ|∇ᵢC|²: one sweep leaves a hinge
//! acting with compliance about α + h² s instead of α. For bending, s/α̃ = h² s α grows as N⁴
//! on a strip of N segments (cotton in the cantilever test: 1.5, 24 and 390 at 8, 16 and 32
//! segments), and the strip hangs limp. Where s/α̃ is not small ([`CG_ABOVE`]) the block's
//! sweep is replaced by Jacobi-preconditioned conjugate gradients on that system, matrix-free
//! (J W Jᵀ p scattered to the particles and gathered back), stopped when the residual has
//! fallen by [`CG_TOLERANCE`] (Hestenes & Stiefel 1952; Saad 2003, "Iterative methods for
//! sparse linear systems", alg. 9.1): the fixed point is then XPBD's at any iteration count.
//!
//! Warm-starting the sweep instead (λ carried from the last substep, its force put into the
//! prediction) is unstable: for a slow mode of stiffness k relative to the sweep's diagonal
//! d, the recursion of (x, λ) has a spectral radius of 1.02 (k/d = 10⁻⁴) to 1.15 (k/d = 0.1),
//! and the cantilever strip swings without settling (measured, `docs/validation.md`).

use glam::DVec3;

use super::{Block, Dihedral, Isometric, Rule, Shape};
use crate::params::FamilyParams;

/// A block is solved by conjugate gradients when its mean s/α̃ (see the module documentation)
/// exceeds this: one sweep would leave its hinges more than about 5 % too soft (about 1° in
/// the cantilever test). Below it the parallel lane sweep is kept: a 1 m cotton sheet at 64²
/// has s/α̃ ≈ 0.014.
pub(crate) const CG_ABOVE: f64 = 0.05;

/// The conjugate gradients stop when the preconditioned residual has fallen to this fraction
/// of the right-hand side's.
pub(crate) const CG_TOLERANCE: f64 = 1e-3;

/// At most this many conjugate-gradient iterations per solve.
pub(crate) const CG_MAX_ITERATIONS: usize = 400;

/// One scalar row of a bending constraint: its value and gradient at the current positions.
pub(crate) type Row = (f64, [DVec3; 4]);

/// What the solve and the residual need from a four-particle bending shape beyond [`Shape`].
pub(crate) trait Rows: Shape<4> {
    /// The constraint's rows (one per multiplier) at `p`, or `None` where it is degenerate.
    fn rows(&self, p: &[DVec3; 4]) -> Option<[Row; 3]>;
}

impl Rows for Dihedral {
    fn rows(&self, p: &[DVec3; 4]) -> Option<[Row; 3]> {
        let row = self.evaluate(p)?;
        Some([row, (0.0, [DVec3::ZERO; 4]), (0.0, [DVec3::ZERO; 4])])
    }
}

impl Rows for Isometric {
    /// ∇ᵢCₐ = kᵢ on axis a, Cₐ the curvature vector's component a.
    fn rows(&self, p: &[DVec3; 4]) -> Option<[Row; 3]> {
        let v = self.curvature(p);
        Some(std::array::from_fn(|a| {
            let e = DVec3::AXES[a];
            (v[a], self.weights.map(|k| e * k))
        }))
    }
}

/// Sums of a residual over constraints: Σ |C + α̃ λ + γ ∇C·Δx|² and Σ |α̃ λ|².
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ResidualSums {
    /// Σ of the squared residuals.
    pub residual: f64,
    /// Σ |α̃ λ|², the compliance term the residual is relative to.
    pub reference: f64,
}

/// One hinge's row: particles, inverse masses, gradient, α̃/(1 + γ), multiplier slot.
type HingeRow = ([u32; 4], [f64; 4], [DVec3; 4], f64, usize);

/// Scratch of the conjugate gradients, kept between substeps.
#[derive(Clone, Debug, Default)]
pub(crate) struct CgScratch {
    /// Per row: particles, inverse masses, gradient, α̃/(1 + γ), multiplier slot.
    rows: Vec<HingeRow>,
    /// Right-hand side, residual, preconditioned residual, direction, A p, solution.
    b: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    dl: Vec<f64>,
    /// Jacobi preconditioner: the inverse diagonal.
    inv_diag: Vec<f64>,
    /// Per particle: Σ ∇C p over the rows (scattered), zero between products.
    u: Vec<DVec3>,
    /// Each multiplier's value at the end of the last solve, by slot: the next substep's
    /// initial guess.
    last: Vec<f64>,
    /// Iterations of the last solve.
    pub iterations: usize,
}

impl CgScratch {
    /// A p for the rows into `q` (A = J W Jᵀ + α̃/(1 + γ) per row).
    fn product(&mut self) {
        let Self { rows, p, q, u, .. } = self;
        for (row, &pr) in rows.iter().zip(p.iter()) {
            for v in 0..4 {
                u[row.0[v] as usize] += row.2[v] * (row.1[v] * pr);
            }
        }
        for ((row, qr), &pr) in rows.iter().zip(q.iter_mut()).zip(p.iter()) {
            *qr = (0..4)
                .map(|v| row.2[v].dot(u[row.0[v] as usize]))
                .sum::<f64>()
                + row.3 * pr;
        }
        for row in rows.iter() {
            for &i in &row.0 {
                u[i as usize] = DVec3::ZERO;
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl<Q: Rows> Block<4, Q> {
    /// Mean s/α̃ = Σᵢ wᵢ|∇ᵢC|² / α̃ over the enabled constraints at `x` with substep `h`.
    pub(crate) fn mean_stiffness_ratio(
        &self,
        x: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        h: f64,
    ) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for (k, (idx, shape)) in self.particles.iter().zip(&self.shapes).enumerate() {
            let Some(p) = params.get(self.group[k] as usize).filter(|p| p.enabled) else {
                continue;
            };
            let (alpha, _) = Rule::xpbd_terms(p, h);
            let Some(rows) = shape.rows(&idx.map(|i| x[i as usize])) else {
                continue;
            };
            let s: f64 = (0..4)
                .map(|v| w[idx[v] as usize] * rows[0].1[v].length_squared())
                .sum();
            sum += if alpha > 0.0 {
                s / alpha
            } else {
                f64::INFINITY
            };
            n += 1;
        }
        if n == 0 { 0.0 } else { sum / n as f64 }
    }

    /// One XPBD step of every enabled constraint at once: the linearised system at `x`
    /// (see the module documentation) solved by preconditioned conjugate gradients in
    /// `scratch`, then λ += Δλ and xᵢ += wᵢ ∇ᵢCᵀΔλ.
    pub(crate) fn solve_cg(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        h: f64,
        scratch: &mut CgScratch,
    ) {
        let m = Q::MULTIPLIERS;
        let cg = scratch;
        cg.rows.clear();
        cg.b.clear();
        cg.inv_diag.clear();
        if cg.u.len() < x.len() {
            cg.u.resize(x.len(), DVec3::ZERO);
        }
        for (k, (idx, shape)) in self.particles.iter().zip(&self.shapes).enumerate() {
            let Some(p) = params.get(self.group[k] as usize).filter(|p| p.enabled) else {
                continue;
            };
            let (alpha, gamma) = Rule::xpbd_terms(p, h);
            let pos = idx.map(|i| x[i as usize]);
            let Some(rows) = shape.rows(&pos) else {
                continue;
            };
            let wi = idx.map(|i| w[i as usize]);
            for (a, (c, g)) in rows.into_iter().take(m).enumerate() {
                let s: f64 = (0..4).map(|v| wi[v] * g[v].length_squared()).sum();
                let g2: f64 = g.iter().map(|v| v.length_squared()).sum();
                let w_max = wi.iter().copied().fold(0.0, f64::max);
                // As the sweep: a row its free particles barely move is left alone.
                if s <= 1e-12 * g2 * w_max {
                    continue;
                }
                let moved: f64 = (0..4)
                    .map(|v| g[v].dot(pos[v] - prev[idx[v] as usize]))
                    .sum();
                let slot = k * m + a;
                let b = (-c - alpha * self.lambda[slot] - gamma * moved) / (1.0 + gamma);
                let alpha_row = alpha / (1.0 + gamma);
                cg.rows.push((*idx, wi, g, alpha_row, slot));
                cg.b.push(b);
                cg.inv_diag.push(1.0 / (s + alpha_row));
            }
        }
        let n = cg.rows.len();
        cg.iterations = 0;
        if n == 0 {
            return;
        }
        // The initial guess: the multipliers the last substep ended with (those of a slow
        // motion change little), less what λ already holds.
        if cg.last.len() != self.lambda.len() {
            cg.last = vec![0.0; self.lambda.len()];
        }
        cg.dl.clear();
        let (last, lambda) = (&cg.last, &self.lambda);
        cg.dl
            .extend(cg.rows.iter().map(|row| last[row.4] - lambda[row.4]));
        cg.p.clone_from(&cg.dl);
        cg.q.clear();
        cg.q.resize(n, 0.0);
        cg.product();
        let bz = dot(
            &cg.b,
            &cg.inv_diag
                .iter()
                .zip(&cg.b)
                .map(|(d, b)| d * b)
                .collect::<Vec<_>>(),
        );
        cg.r.clear();
        cg.r.extend(cg.b.iter().zip(&cg.q).map(|(b, q)| b - q));
        cg.z.clear();
        cg.z.extend(cg.r.iter().zip(&cg.inv_diag).map(|(r, d)| r * d));
        cg.p.clone_from(&cg.z);
        cg.q.clear();
        cg.q.resize(n, 0.0);
        let mut rz = dot(&cg.r, &cg.z);
        let stop = bz * CG_TOLERANCE * CG_TOLERANCE;
        while cg.iterations < CG_MAX_ITERATIONS && rz > stop && rz > 0.0 {
            cg.product();
            let pq = dot(&cg.p, &cg.q);
            if pq.is_nan() || pq <= 0.0 {
                break;
            }
            let step = rz / pq;
            for i in 0..n {
                cg.dl[i] += step * cg.p[i];
                cg.r[i] -= step * cg.q[i];
                cg.z[i] = cg.r[i] * cg.inv_diag[i];
            }
            let next = dot(&cg.r, &cg.z);
            let beta = next / rz;
            rz = next;
            for i in 0..n {
                cg.p[i] = cg.z[i] + beta * cg.p[i];
            }
            cg.iterations += 1;
        }
        cg.last.fill(0.0);
        for (row, &dl) in cg.rows.iter().zip(&cg.dl) {
            self.lambda[row.4] += dl;
            cg.last[row.4] = self.lambda[row.4];
            for v in 0..4 {
                x[row.0[v] as usize] += row.2[v] * (row.1[v] * dl);
            }
        }
    }

    /// [`ResidualSums`] of the enabled constraints at `x` (previous positions `prev`) with
    /// substep `h`.
    pub(crate) fn residual_sums(
        &self,
        x: &[DVec3],
        prev: &[DVec3],
        params: &[FamilyParams],
        h: f64,
    ) -> ResidualSums {
        let m = Q::MULTIPLIERS;
        let mut sums = ResidualSums::default();
        for (k, (idx, shape)) in self.particles.iter().zip(&self.shapes).enumerate() {
            let Some(p) = params.get(self.group[k] as usize).filter(|p| p.enabled) else {
                continue;
            };
            let (alpha, gamma) = Rule::xpbd_terms(p, h);
            let pos = idx.map(|i| x[i as usize]);
            let Some(rows) = shape.rows(&pos) else {
                continue;
            };
            for (a, (c, g)) in rows.into_iter().take(m).enumerate() {
                let moved: f64 = (0..4)
                    .map(|v| g[v].dot(pos[v] - prev[idx[v] as usize]))
                    .sum();
                let al = alpha * self.lambda[k * m + a];
                sums.residual += (c + al + gamma * moved).powi(2);
                sums.reference += al * al;
            }
        }
        sums
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::BlockBuilder;

    /// A row of `n` flat isometric hinges along x (a strip of unit squares, alternate
    /// diagonals), its first column pinned, folded by lifting the free particles
    /// quadratically: positions, inverse masses and the block.
    fn strip(n: usize) -> (Vec<DVec3>, Vec<f64>, Block<4, Isometric>) {
        let mut x = Vec::new();
        for i in 0..=n {
            for j in 0..2 {
                x.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let w: Vec<f64> = (0..x.len())
            .map(|k| if k < 2 { 0.0 } else { 1.0 })
            .collect();
        let free: Vec<bool> = w.iter().map(|&w| w > 0.0).collect();
        let mut b = BlockBuilder::default();
        // Each square (i, i+1) split along (2i, 2i+3); hinges across every diagonal and every
        // interior rung (2i, 2i+1).
        for i in 0..n {
            let (a, b1, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
            let idx = [b1 as u32, c as u32, a as u32, d as u32];
            if let Some(s) = Isometric::at_rest(&idx.map(|k| x[k as usize])) {
                b.push(idx, 0, s);
            }
            if i + 1 < n {
                let idx = [a as u32, (2 * i + 5) as u32, c as u32, d as u32];
                if let Some(s) = Isometric::at_rest(&idx.map(|k| x[k as usize])) {
                    b.push(idx, 0, s);
                }
            }
        }
        for (k, p) in x.iter_mut().enumerate().skip(2) {
            p.z = 0.05 * p.x * p.x + 0.01 * (k % 3) as f64;
        }
        (x, w, b.finish(&free))
    }

    #[test]
    fn conjugate_gradients_solve_what_one_sweep_leaves_soft() {
        let (x0, w, mut block) = strip(6);
        assert!(block.len() >= 6);
        let params = [FamilyParams {
            enabled: true,
            compliance: 1e-3,
            damping: 0.0,
            pbd_stiffness: 1.0,
            spring_stiffness: 1e3,
            spring_damping: 0.0,
        }];
        let h = 1.0;
        let ratio = block.mean_stiffness_ratio(&x0, &w, &params, h);
        assert!(
            ratio > 100.0 * CG_ABOVE,
            "a stiff strip per substep: {ratio}"
        );
        let mut x = x0.clone();
        let mut cg = CgScratch::default();
        block.solve_cg(&mut x, &x0, &w, &params, h, &mut cg);
        // Isometric bending is linear in the positions: the solve is exact to its tolerance.
        let s = block.residual_sums(&x, &x0, &params, h);
        assert!(cg.iterations > 1 && cg.iterations < CG_MAX_ITERATIONS);
        assert!(
            s.reference > 0.0 && s.residual < 1e-4 * s.reference,
            "{s:?}"
        );
        // The pinned particles stay.
        assert_eq!(x[..2], x0[..2]);
        // The next substep (multipliers cleared) with the same prediction starts from the
        // last one's multipliers: already solved.
        let first = x.clone();
        let iterations = cg.iterations;
        block.reset_multipliers();
        let mut x = x0.clone();
        block.solve_cg(&mut x, &x0, &w, &params, h, &mut cg);
        assert!(
            cg.iterations < iterations.min(2),
            "{} of {iterations}",
            cg.iterations
        );
        assert!(x.iter().zip(&first).all(|(a, b)| a.distance(*b) < 1e-6));
    }
}
