//! A coloured block of constraints of one shape, stored struct-of-arrays and sorted by colour.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use super::Shape;
use super::parts;
use crate::coloring::color;
use crate::params::FamilyParams;

/// Colours with at least this many constraints are computed in parallel (tethers, seams; the
/// dihedrals have their own sweep, `dihedral_sweep.rs`).
///
/// A parallel colour costs one rayon fork–join (a few µs) and a serial pass applying the scratch
/// corrections; a scalar projection costs about 0.1 µs, so 512 of them already outweigh the
/// fork.
const PARALLEL_MIN_BATCH: usize = 512;

/// Smallest number of constraints one parallel task takes from a colour.
const PARALLEL_MIN_CHUNK: usize = 128;

/// How a position-based method turns C and ∇C into a multiplier step Δλ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Rule {
    /// XPBD with substep `h`: Macklin et al. 2016, eq. (18) with the damping of eq. (26).
    Xpbd {
        /// Substep length (s).
        h: f64,
    },
    /// PBD: Müller et al. 2007, eq. (10), scaled by the family's stiffness k.
    Pbd,
}

impl Rule {
    /// XPBD's time-step compliance α̃ = α/h² and damping γ = α̃ β̃ / h = α β / h (with
    /// β̃ = h² β) of one family at substep `h` (Macklin et al. 2016, eqs. 4 and 26).
    #[inline]
    pub(crate) fn xpbd_terms(p: &FamilyParams, h: f64) -> (f64, f64) {
        (p.compliance / (h * h), p.compliance * p.damping / h)
    }
}

/// Constraints of one shape, sorted by colour; arrays are indexed by constraint.
#[derive(Clone, Debug)]
pub(crate) struct Block<const N: usize, S> {
    /// Global particle indices of each constraint.
    pub particles: Vec<[u32; N]>,
    /// Parameter group of each constraint: `cloth * Family::COUNT + family`.
    pub group: Vec<u32>,
    /// Rest data of each constraint.
    pub shapes: Vec<S>,
    /// XPBD Lagrange multipliers, reset each substep ([`Shape::MULTIPLIERS`] per constraint).
    pub lambda: Vec<f64>,
    /// Contiguous range of each colour.
    pub colors: Vec<Range<usize>>,
    /// Insertion index of each constraint (before sorting by colour).
    pub order: Vec<u32>,
    /// Boundaries of the particle parts (see [`parts`]): part p owns particles
    /// `part_bounds[p] .. part_bounds[p + 1]`.
    pub part_bounds: Vec<usize>,
    /// Per colour, the boundaries of its parts' constraints, then of its straddlers: part p's
    /// are `segments[c][p] .. segments[c][p + 1]`, the straddlers the last range.
    pub segments: Vec<Vec<usize>>,
    /// Scratch corrections for the parallel path (one colour at a time).
    deltas: Vec<[DVec3; N]>,
}

impl<const N: usize, S> Default for Block<N, S> {
    fn default() -> Self {
        Self {
            particles: Vec::new(),
            group: Vec::new(),
            shapes: Vec::new(),
            lambda: Vec::new(),
            colors: Vec::new(),
            order: Vec::new(),
            part_bounds: vec![0, 0],
            segments: Vec::new(),
            deltas: Vec::new(),
        }
    }
}

/// Collects constraints of one shape before colouring.
#[derive(Clone, Debug)]
pub(crate) struct BlockBuilder<const N: usize, S> {
    particles: Vec<[u32; N]>,
    group: Vec<u32>,
    shapes: Vec<S>,
}

impl<const N: usize, S> Default for BlockBuilder<N, S> {
    fn default() -> Self {
        Self {
            particles: Vec::new(),
            group: Vec::new(),
            shapes: Vec::new(),
        }
    }
}

impl<const N: usize, S: Shape<N>> BlockBuilder<N, S> {
    /// Adds one constraint.
    pub fn push(&mut self, particles: [u32; N], group: u32, shape: S) {
        self.particles.push(particles);
        self.group.push(group);
        self.shapes.push(shape);
    }

    /// The constraints as added, uncoloured: enough for a single pass over them (the
    /// stability bound), not for a solver's sweeps.
    pub fn unordered(self) -> Block<N, S> {
        Block {
            particles: self.particles,
            group: self.group,
            shapes: self.shapes,
            ..Block::default()
        }
    }

    /// Colours the constraints (ignoring particles that are not `free`) and sorts them by colour,
    /// and inside a colour by particle part (see [`parts`]).
    pub fn finish(self, free: &[bool]) -> Block<N, S> {
        let colours = color(&self.particles, free);
        let part_bounds = parts::split(
            &self.particles,
            free.len(),
            parts::count(self.particles.len()),
        );
        let part: Vec<usize> = (self.particles.iter())
            .map(|idx| parts::part_of(idx, &part_bounds))
            .collect();
        let mut order: Vec<usize> = (0..colours.len()).collect();
        // Stable: keeps insertion order inside a colour's part.
        order.sort_by_key(|&i| (colours[i], part[i]));
        let mut ranges: Vec<Range<usize>> = Vec::new();
        for (pos, &i) in order.iter().enumerate() {
            match ranges.last_mut() {
                Some(r) if colours[order[r.start]] == colours[i] => r.end = pos + 1,
                _ => ranges.push(pos..pos + 1),
            }
        }
        let parts_n = part_bounds.len() - 1;
        let segments = ranges
            .iter()
            .map(|r| {
                (0..=parts_n + 1)
                    .map(|p| r.start + order[r.clone()].partition_point(|&i| part[i] < p))
                    .collect()
            })
            .collect();
        let largest = ranges.iter().map(|r| r.len()).max().unwrap_or(0);
        Block {
            particles: order.iter().map(|&i| self.particles[i]).collect(),
            group: order.iter().map(|&i| self.group[i]).collect(),
            shapes: order.iter().map(|&i| self.shapes[i]).collect(),
            lambda: vec![0.0; order.len() * S::MULTIPLIERS],
            colors: ranges,
            order: order.iter().map(|&i| i as u32).collect(),
            part_bounds,
            segments,
            deltas: vec![[DVec3::ZERO; N]; largest],
        }
    }
}

/// Position corrections Δxᵢ = wᵢ ∇Cᵢ Δλ of one constraint (zeros when it is inactive).
#[inline]
#[allow(clippy::too_many_arguments)]
fn correction<const N: usize, S: Shape<N>>(
    shape: &S,
    idx: &[u32; N],
    group: u32,
    lambda: &mut f64,
    x: &[DVec3],
    prev: &[DVec3],
    w: &[f64],
    params: &[FamilyParams],
    rule: Rule,
) -> [DVec3; N] {
    let p = &params[group as usize];
    let pos = idx.map(|i| x[i as usize]);
    let wi = idx.map(|i| w[i as usize]);
    if !p.enabled {
        return [DVec3::ZERO; N];
    }
    let Some((c, grad)) = shape.evaluate(&pos) else {
        return [DVec3::ZERO; N];
    };
    let w_grad2: f64 = (0..N).map(|k| wi[k] * grad[k].length_squared()).sum();
    let dl = match rule {
        Rule::Xpbd { h } => {
            let (alpha, gamma) = Rule::xpbd_terms(p, h);
            let grad_dx: f64 = if gamma > 0.0 {
                (0..N)
                    .map(|k| grad[k].dot(pos[k] - prev[idx[k] as usize]))
                    .sum()
            } else {
                0.0
            };
            let denom = (1.0 + gamma) * w_grad2 + alpha;
            if denom <= f64::MIN_POSITIVE {
                return [DVec3::ZERO; N];
            }
            let dl = (-c - alpha * *lambda - gamma * grad_dx) / denom;
            *lambda += dl;
            dl
        }
        Rule::Pbd => {
            if w_grad2 <= f64::MIN_POSITIVE {
                return [DVec3::ZERO; N];
            }
            -p.pbd_stiffness * c / w_grad2
        }
    };
    std::array::from_fn(|k| grad[k] * (wi[k] * dl))
}

impl<const N: usize, S: Shape<N>> Block<N, S> {
    /// Number of constraints.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Number of colours.
    pub fn color_count(&self) -> usize {
        self.colors.len()
    }

    /// Clears the XPBD multipliers.
    pub fn reset_multipliers(&mut self) {
        self.lambda.fill(0.0);
    }

    /// One Gauss–Seidel sweep, colour by colour.
    ///
    /// A colour with at least [`PARALLEL_MIN_BATCH`] constraints is computed in parallel into scratch and then
    /// applied in order; a smaller one is computed and applied constraint by constraint. Inside a
    /// colour no two constraints share a free particle, so both paths read the same inputs, do the
    /// same arithmetic and give bit-identical results, whatever the thread count.
    pub fn project(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
    ) {
        debug_assert_eq!(S::MULTIPLIERS, 1, "a vector constraint has its own sweep");
        let k = self.colors.len();
        self.project_colours(x, prev, w, params, rule, 0..k);
    }

    /// One Gauss–Seidel sweep over the colours in `order`.
    fn project_colours(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
        order: impl Iterator<Item = usize>,
    ) {
        for c in order {
            let r = self.colors[c].clone();
            let idx = &self.particles[r.clone()];
            let shapes = &self.shapes[r.clone()];
            let groups = &self.group[r.clone()];
            let lambda = &mut self.lambda[r.clone()];
            if r.len() >= PARALLEL_MIN_BATCH {
                let xr: &[DVec3] = x;
                let deltas = &mut self.deltas[..r.len()];
                deltas
                    .par_iter_mut()
                    .zip(lambda.par_iter_mut())
                    .enumerate()
                    .with_min_len(PARALLEL_MIN_CHUNK)
                    .for_each(|(k, (d, l))| {
                        *d = correction(
                            &shapes[k], &idx[k], groups[k], l, xr, prev, w, params, rule,
                        );
                    });
                for (ids, d) in idx.iter().zip(deltas.iter()) {
                    for k in 0..N {
                        x[ids[k] as usize] += d[k];
                    }
                }
            } else {
                for k in 0..r.len() {
                    let d = correction(
                        &shapes[k],
                        &idx[k],
                        groups[k],
                        &mut lambda[k],
                        x,
                        prev,
                        w,
                        params,
                        rule,
                    );
                    for (j, dj) in d.iter().enumerate() {
                        x[idx[k][j] as usize] += *dj;
                    }
                }
            }
        }
    }

    /// One sequential Gauss–Seidel sweep, in colour order, over the constraints for which
    /// `keep(shape, positions)` holds.
    pub fn project_where(
        &mut self,
        x: &mut [DVec3],
        prev: &[DVec3],
        w: &[f64],
        params: &[FamilyParams],
        rule: Rule,
        keep: impl Fn(&S, &[DVec3; N]) -> bool,
    ) {
        for k in 0..self.len() {
            let idx = self.particles[k];
            if !keep(&self.shapes[k], &idx.map(|i| x[i as usize])) {
                continue;
            }
            let d = correction(
                &self.shapes[k],
                &idx,
                self.group[k],
                &mut self.lambda[k],
                x,
                prev,
                w,
                params,
                rule,
            );
            for (j, dj) in d.iter().enumerate() {
                x[idx[j] as usize] += *dj;
            }
        }
    }

    /// Adds spring forces fᵢ = −(k C + c Ċ) ∇Cᵢ, with Ċ = Σ ∇Cⱼ·vⱼ, to `forces`.
    #[cfg(test)]
    pub fn spring_forces(
        &self,
        x: &[DVec3],
        v: &[DVec3],
        params: &[FamilyParams],
        forces: &mut [DVec3],
    ) {
        for ((idx, shape), &g) in self.particles.iter().zip(&self.shapes).zip(&self.group) {
            let p = &params[g as usize];
            if !p.enabled {
                continue;
            }
            let Some((c, grad)) = shape.evaluate(&idx.map(|i| x[i as usize])) else {
                continue;
            };
            let c_dot: f64 = (0..N).map(|k| grad[k].dot(v[idx[k] as usize])).sum();
            let f = -(p.spring_stiffness * c + p.spring_damping * c_dot);
            for k in 0..N {
                forces[idx[k] as usize] += grad[k] * f;
            }
        }
    }

    /// C of every active constraint at `x`.
    pub fn residuals<'a>(&'a self, x: &'a [DVec3]) -> impl Iterator<Item = f64> + 'a {
        self.particles
            .iter()
            .zip(&self.shapes)
            .filter_map(|(idx, s)| s.evaluate(&idx.map(|i| x[i as usize])).map(|(c, _)| c))
    }
}
