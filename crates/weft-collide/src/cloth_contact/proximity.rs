//! One Jacobi sweep of proximity contacts over the listed pairs: a vertex closer to a
//! triangle, or an edge closer to an edge, than the distance the pair keeps is pushed apart
//! along the line between their closest points (Bridson, Fedkiw & Anderson 2002, §7.1 as a
//! position projection: the constraint C = n · (x_a − x_b) − t ≥ 0, with x_a and x_b the
//! closest points as barycentric combinations, solved as XPBD's α = 0 step, Macklin et al.
//! 2016, eq. 18), then Coulomb friction on the pair's relative tangential displacement over
//! the substep (Macklin et al. 2014, eq. 24). Each particle moves by the mean of its
//! corrections (constraint averaging, Macklin et al. 2014, §4.2).
//!
//! The push is along the current direction between the closest points (the fail-safe keeps
//! every substep's end free of crossings, so that direction is the right side), except for a
//! vertex over a face's interior found on the other side of it than at the substep's start,
//! when it was over the interior too: it passed through within the substep's iterations and goes back the way it came.
//!
//! Corrections are computed in parallel but summed in the list's order, so a particle's move
//! does not depend on the thread count.

use glam::DVec3;
use rayon::prelude::*;
use weft_solver::Particles;

use super::broad::Candidates;
use super::geometry::{closest_point, segment_params};
use super::topology::Elements;
use crate::friction::Friction;
use crate::trimesh::closest::Feature;

/// How many times heavier a particle a collider pressed counts in the layers' push. Where a
/// collider pushes two layers onto one surface, pushing them apart by their masses alone moves
/// the lower one back into the collider, and the squeezed pair creeps together substep after
/// substep until the fail-safe freezes it: measured on two 2 mm sheets over a ball, at 1 their
/// closest approach at rest was 0.64 mm with 23 impacts a frame while landing; at 10 it is
/// 1.3 mm with 2.
const PRESSED_WEIGHT: f64 = 10.0;

/// One pair's corrections: four particles (a triangle's pair repeats none; an unused slot has
/// weight zero) and the depth below the distance kept.
type Correction = ([u32; 4], [DVec3; 4], f64);

/// Scratch of a sweep: per particle the summed corrections and their count.
#[derive(Clone, Debug, Default)]
pub(crate) struct Sweep {
    sum: Vec<DVec3>,
    count: Vec<u32>,
    touched: Vec<u32>,
    weights: Vec<f64>,
    /// Positions before the colliders' contacts of this projection.
    before: Vec<DVec3>,
}

/// What a sweep did: contacts and the deepest overlap (m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SweepStats {
    /// Pairs closer than their distance.
    pub contacts: usize,
    /// The deepest of them below their distance (m).
    pub depth: f64,
}

impl Sweep {
    /// Keeps `p`'s positions before the colliders' contacts (see [`Self::weigh`]).
    pub(crate) fn remember(&mut self, p: &Particles) {
        self.before.clear();
        self.before.extend_from_slice(&p.positions);
    }

    /// Inverse masses for the push: a particle a collider moved since [`Self::remember`]
    /// weighs [`PRESSED_WEIGHT`] times its mass, so the layer over it moves out rather than it
    /// into the collider.
    pub(crate) fn weigh(&mut self, p: &Particles) {
        let before = &self.before;
        self.weights.clear();
        self.weights
            .extend(
                (p.inv_masses.iter().zip(&p.positions).enumerate()).map(|(i, (&w, x))| {
                    if before.get(i).is_some_and(|b| b != x) {
                        w / PRESSED_WEIGHT
                    } else {
                        w
                    }
                }),
            );
    }

    /// One sweep over `list`'s pairs at `p`'s positions, with `friction` between the layers
    /// (`list` measured at those positions: [`Candidates::measure_at`]).
    pub(crate) fn run(
        &mut self,
        el: &Elements,
        list: &Candidates,
        p: &mut Particles,
        friction: Friction,
    ) -> SweepStats {
        let n = p.len();
        if self.sum.len() != n {
            self.sum = vec![DVec3::ZERO; n];
            self.count = vec![0; n];
        }
        let (x, prev, w) = (&p.positions, &p.prev_positions, &self.weights);
        let vf: Vec<Correction> = (list.vf.par_iter())
            .filter_map(|l| {
                let tri = el.triangles[l.b as usize];
                let ids = [l.a, tri[0], tri[1], tri[2]];
                // Too far apart to touch (the list's bound at `x`): no distance needed.
                if list.lower_bound(l, &ids, 1) >= l.keep {
                    return None;
                }
                vertex_face(ids, x, prev, w, l.keep, friction)
            })
            .collect();
        let ee: Vec<Correction> = (list.ee.par_iter())
            .filter_map(|l| {
                let ([a0, a1], [b0, b1]) = (el.edges[l.a as usize], el.edges[l.b as usize]);
                let ids = [a0, a1, b0, b1];
                if list.lower_bound(l, &ids, 2) >= l.keep {
                    return None;
                }
                edge_edge(ids, x, prev, w, l.keep, friction)
            })
            .collect();
        let mut stats = SweepStats::default();
        for (ids, d, depth) in vf.iter().chain(&ee) {
            stats.contacts += 1;
            stats.depth = stats.depth.max(*depth);
            for (&i, &d) in ids.iter().zip(d) {
                let i = i as usize;
                if self.count[i] == 0 {
                    self.touched.push(i as u32);
                }
                self.sum[i] += d;
                self.count[i] += 1;
            }
        }
        for &i in &self.touched {
            let i = i as usize;
            p.positions[i] += self.sum[i] / f64::from(self.count[i]);
            self.sum[i] = DVec3::ZERO;
            self.count[i] = 0;
        }
        self.touched.clear();
        stats
    }
}

/// Vertex `ids[0]` against triangle `ids[1..]`, keeping distance `t`.
fn vertex_face(
    ids: [u32; 4],
    x: &[DVec3],
    prev: &[DVec3],
    w: &[f64],
    t: f64,
    friction: Friction,
) -> Option<Correction> {
    let g = |s: &[DVec3], k: usize| s[ids[k] as usize];
    let tri = [g(x, 1), g(x, 2), g(x, 3)];
    let c = closest_point(g(x, 0), tri);
    let diff = g(x, 0) - c.point;
    let dist = diff.length();
    if dist >= t {
        return None;
    }
    let nf = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    let mut n = if dist > 1e-12 {
        diff / dist
    } else {
        nf.try_normalize()?
    };
    // Over the face's interior, a vertex found on the other side of the plane than at the
    // substep's start has passed through it within this substep: back the way it came.
    if c.feature == Feature::Face {
        let p0 = [g(prev, 1), g(prev, 2), g(prev, 3)];
        let c0 = closest_point(g(prev, 0), p0);
        let side0 = (g(prev, 0) - c0.point).dot(nf);
        if c0.feature == Feature::Face && (side0 * nf.dot(diff) < 0.0 || dist <= 1e-12) {
            n = nf.try_normalize()? * side0.signum();
        }
    }
    let b = c.bary;
    respond(
        ids,
        [1.0, -b[0], -b[1], -b[2]],
        n,
        diff,
        t,
        x,
        prev,
        w,
        friction,
    )
}

/// Edge `ids[0] ids[1]` against edge `ids[2] ids[3]`, keeping distance `t`.
fn edge_edge(
    ids: [u32; 4],
    x: &[DVec3],
    prev: &[DVec3],
    w: &[f64],
    t: f64,
    friction: Friction,
) -> Option<Correction> {
    let g = |s: &[DVec3], k: usize| s[ids[k] as usize];
    let (a0, a1, b0, b1) = (g(x, 0), g(x, 1), g(x, 2), g(x, 3));
    let (s, u) = segment_params(a0, a1, b0, b1);
    let diff = a0.lerp(a1, s) - b0.lerp(b1, u);
    let dist = diff.length();
    if dist >= t {
        return None;
    }
    let n = if dist > 1e-12 {
        diff / dist
    } else {
        // Touching: apart along the direction they had at the substep's start.
        let (p0, p1, q0, q1) = (g(prev, 0), g(prev, 1), g(prev, 2), g(prev, 3));
        let (s0, u0) = segment_params(p0, p1, q0, q1);
        (p0.lerp(p1, s0) - q0.lerp(q1, u0)).try_normalize()?
    };
    respond(
        ids,
        [1.0 - s, s, u - 1.0, -u],
        n,
        diff,
        t,
        x,
        prev,
        w,
        friction,
    )
}

/// The corrections of constraint C = n · Σ cₖ xₖ − t (coefficients `c`, so Σ cₖ xₖ = `diff`),
/// then friction on the relative tangential displacement since the substep's start.
#[allow(clippy::too_many_arguments)]
fn respond(
    ids: [u32; 4],
    c: [f64; 4],
    n: DVec3,
    diff: DVec3,
    t: f64,
    x: &[DVec3],
    prev: &[DVec3],
    w: &[f64],
    friction: Friction,
) -> Option<Correction> {
    let wk: [f64; 4] = std::array::from_fn(|k| w[ids[k] as usize]);
    let weight: f64 = (0..4).map(|k| c[k] * c[k] * wk[k]).sum();
    let gap = n.dot(diff) - t;
    if weight <= 0.0 || gap >= 0.0 {
        return None;
    }
    let depth = -gap;
    let lambda = depth / weight;
    // Relative tangential displacement over the substep, after the normal push.
    let rel: DVec3 = (0..4)
        .map(|k| c[k] * (x[ids[k] as usize] - prev[ids[k] as usize]))
        .sum::<DVec3>()
        + n * depth;
    let tangential = rel - n * n.dot(rel);
    let slip = friction.correction(tangential, depth) / weight;
    let d = std::array::from_fn(|k| (n * lambda - slip) * (c[k] * wk[k]));
    Some((ids, d, depth))
}
