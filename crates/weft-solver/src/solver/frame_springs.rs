//! The explicit mass-spring frame by stencil: when the springs form a stencil (a grid's
//! distance springs, see [`SpringStencil`]) and nothing else needs the particle store between a
//! substep's phases, each substep is one parallel pass in which every particle takes its spring
//! force in f32 lanes from the last substep's [`Mirror`] and integrates in f64, writing its
//! next mirror entry. The general loop does the same f64 integration from f64 forces: the two
//! agree to the f32 rounding of the forces, and either gives the same bits on every thread
//! count and kernel path. The frame runs with the pool's workers kept awake (`crate::awake`);
//! its loads, and its write-back with the divergence check, are parallel passes too.

use glam::DVec3;
use rayon::prelude::*;

use super::frame::{Frame, end_velocity};
use super::{Solver, StepStats};
use crate::chunk::CHUNK;
use crate::constraints::{Mirror, SpringStencil};
use crate::methods::{LaneState, Part, Scratch, Step, step_part};
use crate::settings::within_bound;

/// The stencil, the particles' state in lanes, the two mirrors (a substep reads one and
/// writes the other) and each task's working memory.
#[derive(Clone, Debug)]
pub(super) struct StencilFrame {
    stencil: SpringStencil,
    state: LaneState,
    front: Mirror,
    back: Mirror,
    scratch: Vec<Scratch>,
    /// The targets' positions at the substep's start.
    starts: Vec<DVec3>,
}

/// Whether the solver's springs form a stencil, found out on the first explicit frame.
#[derive(Clone, Debug, Default)]
pub(super) enum Stencil {
    /// Not looked at yet.
    #[default]
    Unknown,
    /// The springs form no stencil: the general loop runs.
    Absent,
    /// The springs' stencil.
    Built(Box<StencilFrame>),
}

impl Solver {
    /// Whether an explicit frame can run by stencil: no hook at work, only distance springs
    /// and per-particle external forces ([`Solver::runs_fused`]'s conditions), and springs
    /// that form a stencil (built here on first use).
    pub(super) fn stencil_ready(&mut self) -> bool {
        if !self.fusable() {
            return false;
        }
        if let Stencil::Unknown = self.stencil {
            let n = self.particles.len();
            self.stencil = match SpringStencil::build(&self.constraints.distance, n) {
                Some(stencil) => Stencil::Built(Box::new(StencilFrame {
                    scratch: vec![Scratch::new(&stencil); stencil.stride().div_ceil(CHUNK)],
                    starts: Vec::new(),
                    stencil,
                    state: LaneState::default(),
                    front: Mirror::default(),
                    back: Mirror::default(),
                })),
                None => Stencil::Absent,
            };
        }
        matches!(self.stencil, Stencil::Built(_))
    }

    /// One explicit frame by stencil (see the module documentation); the caller has checked
    /// [`Solver::stencil_ready`].
    pub(super) fn frame_springs(&mut self) -> Frame {
        let s = self.settings;
        let h = s.h();
        let inv_h = 1.0 / h;
        let keep = (self.forces.damping > 0.0).then(|| (-self.forces.damping * h).exp());
        let step = Step {
            h,
            inv_h,
            keep: keep.unwrap_or(1.0),
            gravity: self.forces.gravity,
            drag: self.forces.wind.drag,
            wind: self.forces.wind.velocity,
        };
        let path = self.domains.path();
        let Stencil::Built(mut st) = std::mem::take(&mut self.stencil) else {
            unreachable!("frame_springs runs only after stencil_ready");
        };
        let StencilFrame {
            stencil,
            state,
            front,
            back,
            scratch,
            starts,
        } = &mut *st;
        let coef = stencil.coefficients(&self.params);
        let (m, stride) = (stencil.margin(), stencil.stride());
        let p = &self.particles;
        let ((), ()) = rayon::join(
            || stencil.load(front, &p.positions, &p.velocities),
            || state.load(stride, &p.positions, &p.velocities, &p.inv_masses),
        );
        // The pass writes every particle's entry of the next mirror; its margins stay as
        // loaded (zero: finite, as the masked neighbour loads past the ends need).
        back.origin = front.origin;
        for (b, f) in back
            .x
            .iter_mut()
            .chain(&mut back.v)
            .zip(front.x.iter().chain(&front.v))
        {
            b.resize(f.len(), 0.0);
        }
        let mut whole = true;
        let mut ran = false;
        // Whether the last pass kept its start positions (no pass yet: nothing to keep).
        let mut kept = true;
        for k in 0..s.substeps {
            // A stop ends the frame after a pass that kept its start positions: at once, or
            // after one more substep that keeps them.
            let stop = self.stopping();
            if stop && kept {
                whole = false;
                break;
            }
            self.substep_targets(k);
            // The pass keeps the substep's start positions only on the frame's last substep;
            // the targets' velocities need theirs on every one.
            starts.clear();
            starts.extend(self.targets.iter().map(|&(i, _)| state.get(i)[0]));
            let stencil = &*stencil;
            let from = &*front;
            let last_of_frame = k + 1 == s.substeps;
            let last = last_of_frame || stop;
            kept = last;
            parts(state, back, scratch, m, stride, last)
                .into_par_iter()
                .for_each(|mut part| step_part(path, stencil, &coef, from, &step, &mut part));
            ran = true;
            for (&(i, t), &start) in self.targets.iter().zip(&*starts) {
                let v = end_velocity(t, start, state.w[i], inv_h, keep);
                state.set(i, t, v);
            }
            // Driven pins report the velocity of what carries them, not the chord.
            for &(i, v) in &self.driven_velocities {
                let [x, _, _] = state.get(i);
                state.set(i, x, v);
            }
            for &(i, _) in self.targets.iter().chain(&self.driven_velocities) {
                let [x, v, _] = state.get(i);
                back.set(m, i, x, v);
            }
            std::mem::swap(front, back);
            if stop && !last_of_frame {
                whole = false;
                break;
            }
        }
        // The write-back checks the positions against the divergence bound as it goes.
        let mut within = false;
        if ran {
            let p = &mut self.particles;
            let (state, bound) = (&*state, s.divergence_bound);
            within = (p.positions.par_chunks_mut(CHUNK))
                .zip(p.velocities.par_chunks_mut(CHUNK))
                .zip(p.prev_positions.par_chunks_mut(CHUNK))
                .enumerate()
                .map(|(c, ((x, v), prev))| {
                    state.store(c * CHUNK, x, v, prev);
                    // No branch: the chunk just written is still in the nearest cache.
                    x.iter().fold(true, |ok, &x| ok & within_bound(x, bound))
                })
                .reduce(|| true, |a, b| a & b);
        }
        self.stencil = Stencil::Built(st);
        Frame {
            stats: StepStats::default(),
            whole,
            within,
        }
    }
}

/// The state and the next mirror cut into parallel tasks of [`CHUNK`] particles, each with
/// its working memory.
fn parts<'a>(
    state: &'a mut LaneState,
    next: &'a mut Mirror,
    scratch: &'a mut [Scratch],
    m: usize,
    stride: usize,
    last: bool,
) -> Vec<Part<'a>> {
    let [x0, x1, x2] = &mut state.x;
    let [v0, v1, v2] = &mut state.v;
    let [p0, p1, p2] = &mut state.prev;
    let mut f64s = [x0, x1, x2, v0, v1, v2, p0, p1, p2].map(|a| a.chunks_mut(CHUNK));
    let [nx0, nx1, nx2] = &mut next.x;
    let [nv0, nv1, nv2] = &mut next.v;
    let mut f32s = [nx0, nx1, nx2, nv0, nv1, nv2].map(|a| a[m..m + stride].chunks_mut(CHUNK));
    let mut out = Vec::with_capacity(stride.div_ceil(CHUNK));
    for (w, scratch) in state.w.chunks(CHUNK).zip(scratch) {
        let mut d = f64s.each_mut().map(|it| it.next().expect("one length"));
        let mut f = f32s.each_mut().map(|it| it.next().expect("one length"));
        let take = |s: &mut &'a mut [f64]| std::mem::take(s);
        out.push(Part {
            start: out.len() * CHUNK,
            x: [take(&mut d[0]), take(&mut d[1]), take(&mut d[2])],
            v: [take(&mut d[3]), take(&mut d[4]), take(&mut d[5])],
            prev: [take(&mut d[6]), take(&mut d[7]), take(&mut d[8])],
            w,
            next: f.each_mut().map(std::mem::take),
            scratch,
            last,
        });
    }
    out
}
