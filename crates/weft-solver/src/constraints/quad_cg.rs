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
//! The bending solve is only as right as the stretch it bends: one sweep of the distance
//! constraints leaves a stiff cloth stretched by a few per cent at fabric-test sizes (a
//! cotton strip of 8 segments 2.7 % at its clamp, a 30 cm disc 6 %), and a strip that long
//! bends further. So where a bending block is stiff per substep ([`JOINT_ABOVE`]), the
//! distance constraints join the bending in one system (rows of both in one matrix-free
//! product, the domains' sweep skipped): the strip's longest edge falls to 0.5 % and its
//! chord angle lands within 2° of the elastica at 8, 16 and 32 segments, as implicit
//! mass-spring's (`docs/validation.md`). The joint system is stiffer (its condition grows
//! as the cloth's size in rows squared), so it is kept to systems of at most
//! [`JOINT_MAX_ROWS`] rows: a garment of 6,000 particles (116,000 rows) took 170 iterations a
//! substep, 18 times its frame, and keeps the bending solve alone. Rigid rows (α = 0) get a
//! compliance floor ([`RIGID_FLOOR`]) so that redundant ones leave the system definite. A
//! bending block of more than [`CG_MAX_ROWS`] rows keeps its sweep ([`Plan`]): the solve
//! runs on one thread, and a garment's costs many times its frame.
//!
//! Warm-starting the sweep instead (λ carried from the last substep, its force put into the
//! prediction) is unstable: for a slow mode of stiffness k relative to the sweep's diagonal
//! d, the recursion of (x, λ) has a spectral radius of 1.02 (k/d = 10⁻⁴) to 1.15 (k/d = 0.1),
//! and the cantilever strip swings without settling (measured, `docs/validation.md`).

use glam::DVec3;

use super::{Block, Dihedral, Distance, Isometric, Rule, Shape};
use crate::params::FamilyParams;

/// A block is solved by conjugate gradients when its mean s/α̃ (see the module documentation)
/// exceeds this: one sweep would leave its hinges more than about 5 % too soft (about 1° in
/// the cantilever test). Below it the parallel lane sweep is kept: a 1 m cotton sheet at 64²
/// has s/α̃ ≈ 0.014.
pub(crate) const CG_ABOVE: f64 = 0.05;

/// The conjugate gradients stop when the preconditioned residual has fallen to this fraction
/// of the right-hand side's.
pub(crate) const CG_TOLERANCE: f64 = 1e-3;

/// The distance constraints are solved with the bending (see the module documentation) when
/// a bending block's mean s/α̃ exceeds this, i.e. where one sweep would leave its hinges more
/// than 2 % soft: the 20-cell Cusick disc (0.036) drapes 4 points differently with its
/// stretch solved, while a 1 m cotton sheet at 32² (0.014) keeps its sweep, whose stretch a
/// joint solve would take 150 iterations a substep to converge.
pub(crate) const JOINT_ABOVE: f64 = 0.02;

/// The distance constraints join a bending solve (see the module documentation) when the
/// joint system has at most this many rows: a 40-cell Cusick disc has 15,000.
pub(crate) const JOINT_MAX_ROWS: usize = 20_000;

/// A bending block is solved by conjugate gradients alone only when it has at most this many
/// rows; a larger one keeps the parallel lane sweep however soft that leaves it. The solve
/// runs on one thread: the walker's T-shirt (28,807 isometric hinges, 86,421 rows, s/α̃ =
/// 0.25) took 30–65 iterations a frame and its XPBD frame 150 ms instead of the sweep's
/// 9 ms; the sweep leaves its hinges about 25 % soft (compliance α (1 + s/α̃)).
pub(crate) const CG_MAX_ROWS: usize = 20_000;

/// How XPBD solves a frame's bending and distance constraints.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Plan {
    /// The dihedral and the isometric block by conjugate gradients, each alone.
    pub bending: [bool; 2],
    /// The distance constraints and both bending blocks in one conjugate-gradient solve.
    pub joint: bool,
}

impl Plan {
    /// The plan for bending blocks of `bending_rows` rows (dihedral, isometric) beside
    /// `distance_rows` distance rows. `ratio(k)` is block k's mean s/α̃, a pass over its
    /// hinges: asked only of a block small enough to be solved, alone ([`CG_MAX_ROWS`]) or
    /// jointly ([`JOINT_MAX_ROWS`]).
    pub(crate) fn new(
        bending_rows: [usize; 2],
        distance_rows: usize,
        mut ratio: impl FnMut(usize) -> f64,
    ) -> Self {
        let all = distance_rows + bending_rows[0] + bending_rows[1];
        let ratios: [f64; 2] = std::array::from_fn(|k| {
            let rows = bending_rows[k];
            if rows > 0 && (rows <= CG_MAX_ROWS || all <= JOINT_MAX_ROWS) {
                ratio(k)
            } else {
                0.0
            }
        });
        Self {
            bending: [0, 1].map(|k| ratios[k] > CG_ABOVE && bending_rows[k] <= CG_MAX_ROWS),
            joint: ratios.iter().any(|&r| r > JOINT_ABOVE) && all <= JOINT_MAX_ROWS,
        }
    }
}

/// The smallest α̃ of a row in the conjugate gradients, relative to its Σ wᵢ|∇ᵢC|²: cotton's
/// stretch at 10 substeps has α̃/s ≈ 3·10⁻⁴, so only rigid rows meet the floor.
pub(crate) const RIGID_FLOOR: f64 = 1e-6;

/// The block id of the distance rows in [`CgScratch`] (each shape keeps its own id, so that
/// its warm start survives a frame that solves it alone or jointly).
pub(crate) const DISTANCE_ROWS: usize = 0;

/// The block id of the dihedral rows in [`CgScratch`].
pub(crate) const DIHEDRAL_ROWS: usize = 1;

/// The block id of the isometric rows in [`CgScratch`].
pub(crate) const ISOMETRIC_ROWS: usize = 2;

/// At most this many conjugate-gradient iterations per solve.
pub(crate) const CG_MAX_ITERATIONS: usize = 400;

/// One scalar row of a constraint of `N` particles: its value and gradient at the current
/// positions.
pub(crate) type Row<const N: usize> = (f64, [DVec3; N]);

/// What the solve and the residual need from a shape beyond [`Shape`].
pub(crate) trait Rows<const N: usize>: Shape<N> {
    /// The constraint's rows (one per multiplier, the rest zero) at `p`, or `None` where it
    /// is degenerate.
    fn rows(&self, p: &[DVec3; N]) -> Option<[Row<N>; 3]>;
}

impl Rows<4> for Dihedral {
    fn rows(&self, p: &[DVec3; 4]) -> Option<[Row<4>; 3]> {
        let row = self.evaluate(p)?;
        Some([row, (0.0, [DVec3::ZERO; 4]), (0.0, [DVec3::ZERO; 4])])
    }
}

impl Rows<4> for Isometric {
    /// ∇ᵢCₐ = kᵢ on axis a, Cₐ the curvature vector's component a.
    fn rows(&self, p: &[DVec3; 4]) -> Option<[Row<4>; 3]> {
        let v = self.curvature(p);
        Some(std::array::from_fn(|a| {
            let e = DVec3::AXES[a];
            (v[a], self.weights.map(|k| e * k))
        }))
    }
}

impl Rows<2> for Distance {
    fn rows(&self, p: &[DVec3; 2]) -> Option<[Row<2>; 3]> {
        let row = self.evaluate(p)?;
        Some([row, (0.0, [DVec3::ZERO; 2]), (0.0, [DVec3::ZERO; 2])])
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

/// Where a substep's system is linearised: positions, previous positions, inverse masses,
/// parameters and substep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Linearised<'a> {
    /// Positions.
    pub x: &'a [DVec3],
    /// Positions at the start of the substep.
    pub prev: &'a [DVec3],
    /// Inverse masses.
    pub w: &'a [f64],
    /// Parameters of each constraint group.
    pub params: &'a [FamilyParams],
    /// Substep (s).
    pub h: f64,
}

/// One row of the system: particles (unused ones repeat the first with a zero gradient),
/// inverse masses, gradient, α̃/(1 + γ), multiplier slot in its block, and the block.
#[derive(Clone, Copy, Debug)]
struct CgRow {
    idx: [u32; 4],
    w: [f64; 4],
    g: [DVec3; 4],
    alpha: f64,
    slot: u32,
    block: u32,
}

/// Scratch of the conjugate gradients, kept between substeps.
#[derive(Clone, Debug, Default)]
pub(crate) struct CgScratch {
    rows: Vec<CgRow>,
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
    /// Per block, each multiplier's value at the end of the last solve, by slot: the next
    /// substep's initial guess.
    last: Vec<Vec<f64>>,
    /// Iterations of the last solve.
    pub iterations: usize,
    /// Iterations of every solve since it was last set to 0 (the substep's, for the stats).
    pub substep_iterations: usize,
}

impl CgScratch {
    /// Starts a system on `particles` particles.
    pub(crate) fn begin(&mut self, particles: usize) {
        self.rows.clear();
        self.b.clear();
        self.inv_diag.clear();
        self.dl.clear();
        self.iterations = 0;
        if self.u.len() < particles {
            self.u.resize(particles, DVec3::ZERO);
        }
    }

    /// A p for the rows into `q` (A = J W Jᵀ + α̃/(1 + γ) per row).
    fn product(&mut self) {
        let Self { rows, p, q, u, .. } = self;
        for (row, &pr) in rows.iter().zip(p.iter()) {
            for v in 0..4 {
                u[row.idx[v] as usize] += row.g[v] * (row.w[v] * pr);
            }
        }
        for ((row, qr), &pr) in rows.iter().zip(q.iter_mut()).zip(p.iter()) {
            *qr = (0..4)
                .map(|v| row.g[v].dot(u[row.idx[v] as usize]))
                .sum::<f64>()
                + row.alpha * pr;
        }
        for row in rows.iter() {
            for &i in &row.idx {
                u[i as usize] = DVec3::ZERO;
            }
        }
    }

    /// Solves the gathered system by Jacobi-preconditioned conjugate gradients from the
    /// gathered initial guess, to [`CG_TOLERANCE`] or [`CG_MAX_ITERATIONS`].
    pub(crate) fn solve(&mut self) {
        let n = self.rows.len();
        if n == 0 {
            return;
        }
        let cg = self;
        cg.p.clone_from(&cg.dl);
        cg.q.clear();
        cg.q.resize(n, 0.0);
        cg.product();
        let bz: f64 = cg.b.iter().zip(&cg.inv_diag).map(|(b, d)| b * b * d).sum();
        cg.r.clear();
        cg.r.extend(cg.b.iter().zip(&cg.q).map(|(b, q)| b - q));
        cg.z.clear();
        cg.z.extend(cg.r.iter().zip(&cg.inv_diag).map(|(r, d)| r * d));
        cg.p.clone_from(&cg.z);
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
        cg.substep_iterations += cg.iterations;
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl<const N: usize, Q: Rows<N>> Block<N, Q> {
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
            let s: f64 = (0..N)
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

    /// Adds this block's enabled rows, linearised at `x` (see the module documentation), to
    /// the system in `cg` as block `id`, each starting from the multiplier it ended the last
    /// substep with.
    pub(crate) fn gather_rows(&self, id: usize, at: &Linearised<'_>, cg: &mut CgScratch) {
        let Linearised {
            x,
            prev,
            w,
            params,
            h,
        } = *at;
        let m = Q::MULTIPLIERS;
        if cg.last.len() <= id {
            cg.last.resize(id + 1, Vec::new());
        }
        if cg.last[id].len() != self.lambda.len() {
            cg.last[id] = vec![0.0; self.lambda.len()];
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
                let s: f64 = (0..N).map(|v| wi[v] * g[v].length_squared()).sum();
                let g2: f64 = g.iter().map(|v| v.length_squared()).sum();
                let w_max = wi.iter().copied().fold(0.0, f64::max);
                // As the sweep: a row its free particles barely move is left alone.
                if s <= 1e-12 * g2 * w_max {
                    continue;
                }
                let moved: f64 = (0..N)
                    .map(|v| g[v].dot(pos[v] - prev[idx[v] as usize]))
                    .sum();
                let slot = k * m + a;
                let b = (-c - alpha * self.lambda[slot] - gamma * moved) / (1.0 + gamma);
                // A rigid row (α = 0) gets a compliance far below any fabric's, so that the
                // system stays positive definite where rigid rows are redundant.
                let alpha_row = (alpha / (1.0 + gamma)).max(RIGID_FLOOR * s);
                let mut row = CgRow {
                    idx: [idx[0]; 4],
                    w: [0.0; 4],
                    g: [DVec3::ZERO; 4],
                    alpha: alpha_row,
                    slot: slot as u32,
                    block: id as u32,
                };
                row.idx[..N].copy_from_slice(idx);
                row.w[..N].copy_from_slice(&wi);
                row.g[..N].copy_from_slice(&g);
                cg.rows.push(row);
                cg.b.push(b);
                cg.inv_diag.push(1.0 / (s + alpha_row));
                cg.dl.push(cg.last[id][slot] - self.lambda[slot]);
            }
        }
    }

    /// Applies the solution in `cg` to this block's rows (block `id`): λ += Δλ and
    /// xᵢ += wᵢ ∇ᵢCᵀΔλ, and keeps λ as the next substep's initial guess.
    pub(crate) fn apply_rows(&mut self, id: usize, x: &mut [DVec3], cg: &mut CgScratch) {
        let last = &mut cg.last[id];
        last.fill(0.0);
        for (row, &dl) in cg.rows.iter().zip(&cg.dl) {
            if row.block as usize != id {
                continue;
            }
            let slot = row.slot as usize;
            self.lambda[slot] += dl;
            last[slot] = self.lambda[slot];
            for v in 0..N {
                x[row.idx[v] as usize] += row.g[v] * (row.w[v] * dl);
            }
        }
    }

    /// One XPBD step of every enabled constraint of this block alone, by conjugate gradients
    /// in `scratch` as its block `id` (see [`Self::gather_rows`]).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn solve_cg(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        h: f64,
        id: usize,
        scratch: &mut CgScratch,
    ) {
        scratch.begin(x.len());
        let at = Linearised {
            x,
            prev,
            w,
            params,
            h,
        };
        self.gather_rows(id, &at, scratch);
        scratch.solve();
        self.apply_rows(id, x, scratch);
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
                let moved: f64 = (0..N)
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

    /// One enabled family of compliance `alpha`.
    fn compliant(alpha: f64) -> [FamilyParams; 1] {
        [FamilyParams {
            enabled: true,
            compliance: alpha,
            damping: 0.0,
            pbd_stiffness: 1.0,
            spring_stiffness: 1e3,
            spring_damping: 0.0,
        }]
    }

    #[test]
    fn a_garment_keeps_its_sweep_and_a_fabric_test_its_solve() {
        // Rows and mean s/α̃ of the shipped scenes' cloths (`weft run`, first frame).
        let shirt = ([0, 86_421], [0.0, 0.254], 29_699);
        let skirt = ([0, 26_892], [0.0, 0.059], 9_258);
        let disc = ([0, 3_888], [0.0, 0.087], 1_392);
        let strip = ([433, 0], [70.9, 0.0], 638);
        let plan = |(rows, ratios, distance): ([usize; 2], [f64; 2], usize)| {
            Plan::new(rows, distance, |k| ratios[k])
        };
        let sweep = Plan::default();
        // The shirt's blocks are too large to be solved: their s/α̃ is never worked out.
        let mut asked = 0;
        Plan::new(shirt.0, shirt.2, |k| {
            asked += 1;
            shirt.1[k]
        });
        assert_eq!(asked, 0);
        assert_eq!(plan(shirt), sweep);
        assert_eq!(plan(skirt), sweep);
        let joint = |bending| Plan {
            bending,
            joint: true,
        };
        assert_eq!(plan(disc), joint([false, true]));
        assert_eq!(plan(strip), joint([true, false]));
        // Alone, up to the bound; jointly, up to its own.
        let alone = ([0, CG_MAX_ROWS], [0.0, 0.3], JOINT_MAX_ROWS);
        assert_eq!(
            plan(alone),
            Plan {
                bending: [false, true],
                joint: false
            }
        );
        let over = ([0, CG_MAX_ROWS + 3], [0.0, 0.3], 0);
        assert_eq!(plan(over), sweep);
        // Soft per substep: swept at any size.
        assert_eq!(plan(([0, 300], [0.0, 0.01], 200)), sweep);
    }

    #[test]
    fn conjugate_gradients_solve_what_one_sweep_leaves_soft() {
        let (x0, w, mut block) = strip(6);
        assert!(block.len() >= 6);
        let params = compliant(1e-3);
        let h = 1.0;
        let ratio = block.mean_stiffness_ratio(&x0, &w, &params, h);
        assert!(
            ratio > 100.0 * CG_ABOVE,
            "a stiff strip per substep: {ratio}"
        );
        let mut x = x0.clone();
        let mut cg = CgScratch::default();
        block.solve_cg(&mut x, &x0, &w, &params, h, 0, &mut cg);
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
        block.solve_cg(&mut x, &x0, &w, &params, h, 0, &mut cg);
        assert!(
            cg.iterations < iterations.min(2),
            "{} of {iterations}",
            cg.iterations
        );
        assert!(x.iter().zip(&first).all(|(a, b)| a.distance(*b) < 1e-6));
    }

    #[test]
    fn a_joint_solve_holds_the_stretch_and_the_bending_at_once() {
        let (x0, w, mut hinges) = strip(6);
        let free: Vec<bool> = w.iter().map(|&w| w > 0.0).collect();
        // The strip's rails and free rungs, 5 % shorter at rest than the folded strip has them.
        let mut b = BlockBuilder::default();
        let pairs = (0..14).flat_map(|k| [(k, k + 2), (k, k + 1)]);
        for (i, j) in pairs.filter(|&(i, j)| j >= 2 && j < x0.len() && (j == i + 2 || i % 2 == 0)) {
            let rest = 0.95 * x0[i].distance(x0[j]);
            b.push([i as u32, j as u32], 0, Distance { rest });
        }
        let mut edges = b.finish(&free);
        let stretched = |x: &[DVec3], e: &Block<2, Distance>| {
            e.residuals(x).fold(0.0f64, |m, c| m.max(c.abs()))
        };
        let before = stretched(&x0, &edges);
        let params = compliant(1e-3);
        let stiff = compliant(1e-8);
        let mut x = x0.clone();
        let mut cg = CgScratch::default();
        for _ in 0..3 {
            // Three Newton steps of one substep: each linearises where the last left off.
            cg.begin(x.len());
            let at = Linearised {
                x: &x,
                prev: &x0,
                w: &w,
                params: &stiff,
                h: 1.0,
            };
            edges.gather_rows(0, &at, &mut cg);
            let at = Linearised {
                params: &params,
                ..at
            };
            hinges.gather_rows(1, &at, &mut cg);
            cg.solve();
            edges.apply_rows(0, &mut x, &mut cg);
            hinges.apply_rows(1, &mut x, &mut cg);
        }
        let after = stretched(&x, &edges);
        assert!(before > 0.04 && after < 1e-3 * before, "{before} → {after}");
        // The hinges hold their own equation with the stretch solved beside them.
        let s = hinges.residual_sums(&x, &x0, &params, 1.0);
        assert!(
            s.reference > 0.0 && s.residual < 1e-3 * s.reference,
            "{s:?}"
        );
        assert_eq!(x[..2], x0[..2]);
    }
}
