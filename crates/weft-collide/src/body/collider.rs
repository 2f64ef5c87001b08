//! A kinematic body inside the collision world: its parts at the substep's start and end,
//! the broad phase, and the per-chunk contact planes.

use std::sync::Arc;

use glam::DVec3;
use rayon::prelude::*;
use weft_solver::Particles;

use super::contact::{Plane, planes, project, sweep};
use super::grid::PartGrid;
use super::motion::MovingPart;
use super::{BodyPart, KinematicBody};
use crate::friction::Friction;
use crate::world::{CHUNK, moving_views};

/// Preferred edge of the broad phase's cells (m): a few limb radii.
const CELL: f64 = 0.05;

/// Below this many contact planes a substep's projections run on the calling thread.
const SERIAL_PLANES: usize = 4096;

/// A body in the world.
#[derive(Clone, Debug)]
pub(crate) struct BodyCollider {
    body: Arc<dyn KinematicBody>,
    friction: Friction,
    /// Parts at the substep's start and end.
    start: Vec<BodyPart>,
    end: Vec<BodyPart>,
    /// The time `end` was evaluated at.
    end_time: Option<f64>,
    moving: Vec<MovingPart>,
    grid: PartGrid,
    /// Per chunk of particles, the contact planes of this substep, in particle order.
    chunks: Vec<Vec<Plane>>,
    /// Contact planes found this substep.
    plane_count: usize,
}

impl BodyCollider {
    /// A body with its friction, placed at time `t`.
    pub fn new(body: Arc<dyn KinematicBody>, friction: Friction, t: f64) -> Self {
        let mut end = Vec::with_capacity(body.part_count());
        body.parts_at(t, &mut end);
        Self {
            body,
            friction,
            start: end.clone(),
            end,
            end_time: Some(t),
            moving: Vec::new(),
            grid: PartGrid::default(),
            chunks: Vec::new(),
            plane_count: 0,
        }
    }

    /// The parts at the end of the current substep.
    pub fn parts(&self) -> &[BodyPart] {
        &self.end
    }

    /// The friction coefficients.
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// Contact planes found at the last substep's first projection.
    pub fn plane_count(&self) -> usize {
        self.plane_count
    }

    /// Moves the body to its poses at `t0` and `t1` (the substep's ends) and rebuilds the
    /// broad phase for contacts within `reach` (m).
    pub fn set_time(&mut self, t0: f64, t1: f64, reach: f64) {
        // The last substep's end is this one's start (to rounding of the substep times).
        let reuse = self
            .end_time
            .is_some_and(|t| (t - t0).abs() <= 1e-12 * t0.abs().max(1.0));
        if reuse {
            std::mem::swap(&mut self.start, &mut self.end);
        } else {
            self.body.parts_at(t0, &mut self.start);
        }
        self.body.parts_at(t1, &mut self.end);
        self.end_time = Some(t1);
        let extent = reach + CELL;
        self.moving.clear();
        self.moving.extend(
            self.start
                .iter()
                .zip(&self.end)
                .map(|(a, b)| MovingPart::new(a, b, extent)),
        );
        self.grid.build(&self.moving, reach, CELL);
    }

    /// Once per substep, before self-collision: sweeps every free particle's substep path
    /// against the moving parts, then finds its contact planes (every part within twice its
    /// thickness, or holding it) — one broad-phase lookup per particle for both. Returns how
    /// many particles the sweep stopped. In parallel over fixed chunks, each particle on its
    /// own: the same bits on any thread count.
    ///
    /// Self-collision then moves particles by a fraction of a thickness; the planes, supporting
    /// planes of convex parts found within two thicknesses, still hold for them.
    pub fn find(&mut self, p: &mut Particles, thickness: &[f64]) -> usize {
        let chunks = p.len().div_ceil(CHUNK);
        if self.chunks.len() != chunks {
            self.chunks = vec![Vec::new(); chunks];
        }
        let (parts, grid) = (&self.moving, &self.grid);
        let (positions, prev, inv) = moving_views(p);
        let (swept, found) = positions
            .par_chunks_mut(CHUNK)
            .zip(self.chunks.par_iter_mut())
            .enumerate()
            .map(|(k, (xs, list))| {
                list.clear();
                let mut swept = 0;
                for (j, x) in xs.iter_mut().enumerate() {
                    let i = k * CHUNK + j;
                    if inv[i] == 0.0 {
                        continue;
                    }
                    let r = thickness[i];
                    let mut here = grid.candidates(*x);
                    let n = sweep(parts, grid, here, prev[i], x, r);
                    if n > 0 {
                        swept += n;
                        here = grid.candidates(*x);
                    }
                    planes(parts, here, j as u32, *x, 2.0 * r, list);
                }
                (swept, list.len())
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        self.plane_count = found;
        swept
    }

    /// Projects free particles onto this substep's contact planes (see [`Self::find`]), to a
    /// thickness outside, with friction. Returns (contacts, deepest overlap).
    pub fn resolve(&mut self, p: &mut Particles, thickness: &[f64]) -> (usize, f64) {
        if self.chunks.len() != p.len().div_ceil(CHUNK) {
            return (0, 0.0);
        }
        let friction = self.friction;
        let (positions, prev, _) = moving_views(p);
        let chunk = |k: usize, xs: &mut [DVec3], list: &[Plane]| {
            let (mut contacts, mut deepest) = (0, 0.0f64);
            let mut rest = list;
            while let Some(first) = rest.first() {
                let j = first.particle;
                let n = rest.iter().take_while(|q| q.particle == j).count();
                let (mine, others) = rest.split_at(n);
                rest = others;
                let i = k * CHUNK + j as usize;
                let (c, d) = project(mine, prev[i], &mut xs[j as usize], thickness[i], friction);
                contacts += c;
                deepest = deepest.max(d);
            }
            (contacts, deepest)
        };
        let combine = |a: (usize, f64), b: (usize, f64)| (a.0 + b.0, a.1.max(b.1));
        // Each particle's projection depends on it alone, so the order (and the thread count)
        // never changes the result: a few planes are cheaper projected here than handed out.
        if self.plane_count < SERIAL_PLANES {
            positions
                .chunks_mut(CHUNK)
                .zip(&self.chunks)
                .enumerate()
                .map(|(k, (xs, list))| chunk(k, xs, list))
                .fold((0, 0.0), combine)
        } else {
            positions
                .par_chunks_mut(CHUNK)
                .zip(self.chunks.par_iter())
                .enumerate()
                .map(|(k, (xs, list))| chunk(k, xs, list))
                .reduce(|| (0, 0.0), combine)
        }
    }
}
