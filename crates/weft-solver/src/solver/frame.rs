//! One frame of the step loop, in its two forms: fused (every substep phase inside the
//! domains' parallel regions) and general (every phase on the particle store, the hook in
//! between). Both do the same arithmetic in the same order, so they give the same bits.

use std::sync::atomic::Ordering;

use glam::DVec3;
use rayon::prelude::*;

use super::{Solver, StepStats};
use crate::chunk::CHUNK;
use crate::constraints::Rule;
use crate::domains::{AosChunk, Domain, Finish, Integration, Start};
use crate::hook::{SubstepContext, SubstepHook};
use crate::methods::ForcePass;

/// How a frame ended.
pub(super) struct Frame {
    /// What the frame did.
    pub stats: StepStats,
    /// False when the stop flag cut it short.
    pub whole: bool,
    /// Every position is known to be finite and within the divergence bound (checked as the
    /// fused frame copied them out); false when unchecked.
    pub within: bool,
}

impl Frame {
    /// A frame stopped before it changed anything.
    fn cut(stats: StepStats) -> Self {
        Self {
            stats,
            whole: false,
            within: false,
        }
    }
}

impl Solver {
    /// Time at the end of substep `k` of the frame (the frame's end after its last).
    pub(super) fn substep_time(&self, k: u32) -> f64 {
        let s = self.settings;
        self.time + s.dt * f64::from(k + 1) / f64::from(s.substeps)
    }

    /// Time at the end of substep `k`, and the pin and grab targets there, into `self.targets`.
    pub(super) fn substep_targets(&mut self, k: u32) -> f64 {
        let time = self.substep_time(k);
        self.targets.clear();
        for pin in &self.pins {
            self.targets
                .push((pin.particle as usize, pin.motion.position(pin.rest, time)));
        }
        self.driven_velocities.clear();
        let (x, v) = &mut self.driven;
        for driver in &self.drivers {
            let ids = driver.particles();
            x.resize(ids.len(), DVec3::ZERO);
            v.resize(ids.len(), DVec3::ZERO);
            driver.drive(time, x, v);
            for (k, &i) in ids.iter().enumerate() {
                self.targets.push((i as usize, x[k]));
                self.driven_velocities.push((i as usize, v[k]));
            }
        }
        if let Some(g) = &self.grab {
            let f = (k + 1) as f64 / self.settings.substeps as f64;
            self.targets.push((g.particle, g.from.lerp(g.target, f)));
        }
        time
    }

    /// One frame with every substep phase inside the domains' parallel regions, run by a team
    /// of threads kept for the whole frame, with the hook's per-particle contacts when it is
    /// active; false when the stop flag cut it short. The frame's end copies the positions out
    /// and checks them against the divergence bound (see [`Frame`]).
    pub(super) fn frame_fused(&mut self, rule: Rule, hook: &mut dyn SubstepHook) -> Frame {
        let s = self.settings;
        let h = s.h();
        let inv_h = 1.0 / h;
        let keep = (self.forces.damping > 0.0).then(|| (-self.forces.damping * h).exp());
        let active = hook.is_active();
        self.domains.prepare(&self.params, rule);
        let lambda = self.domains.mode().lambda;
        // Every substep's targets depend on its time alone: worked out before the team starts,
        // so that its workers read them while the frame runs.
        let mut targets = std::mem::take(&mut self.frame_targets);
        targets.resize_with(s.substeps as usize, Vec::new);
        let mut times = Vec::with_capacity(s.substeps as usize);
        for (k, t) in (0..s.substeps).zip(&mut targets) {
            times.push(self.substep_targets(k));
            t.clone_from(&self.targets);
        }
        let frame_end = self.substep_time(s.substeps - 1);
        let forces = &self.forces;
        let work = |k: u32, d: &mut Domain, aos: &AosChunk<'_>| {
            let start = if k == 0 {
                Start::Store(aos)
            } else {
                Start::Finish(Finish { inv_h, keep })
            };
            let step = Integration {
                h,
                forces,
                pins: &targets[k as usize],
            };
            d.integrate(&step, start, lambda);
        };
        let stop = self.stop.as_deref();
        let p = &self.particles;
        let (stats, done) =
            self.domains
                .team(&p.positions, &p.velocities, &p.inv_masses, &work, |team| {
                    let mut stats = StepStats::default();
                    for k in 0..s.substeps {
                        if stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
                            return (stats, k);
                        }
                        if active {
                            let ctx = SubstepContext {
                                method: s.method,
                                time: times[k as usize],
                                h,
                                substep: k,
                                frame_end,
                            };
                            hook.begin_substep(&ctx, p);
                        }
                        team.integrate_and_project(k);
                        for it in 0..s.iterations {
                            if it > 0 {
                                team.project();
                            }
                            if active && let Some(contacts) = hook.particle_contacts() {
                                let totals = team.collide(contacts, it == 0);
                                stats.contacts = hook.fused_pass(it == 0, totals);
                            }
                        }
                    }
                    (stats, s.substeps)
                });
        self.frame_targets = targets;
        if done == 0 {
            // Nothing loaded into the domains yet: the store is as it was.
            return Frame::cut(stats);
        }
        if done < s.substeps {
            // The driven velocities of the last substep run.
            self.substep_targets(done - 1);
        }
        let p = &mut self.particles;
        let within = self.domains.finish(
            Finish { inv_h, keep },
            s.divergence_bound,
            &mut p.positions,
            &mut p.prev_positions,
            &mut p.velocities,
        );
        // The last substep's driven velocities, as the general loop leaves them.
        for &(i, v) in &self.driven_velocities {
            p.velocities[i] = v;
        }
        Frame {
            stats,
            whole: done == s.substeps,
            within,
        }
    }

    /// One frame of the general loop: every phase on the particle store, the hook in between;
    /// false when the stop flag cut it short.
    pub(super) fn frame_general(&mut self, hook: &mut dyn SubstepHook) -> Frame {
        let s = self.settings;
        let h = s.h();
        let strategy = s.method.strategy();
        let mut stats = StepStats::default();
        self.spring_work.iterations = 0;
        self.spring_work.worst = 0.0;
        let rule = strategy.rule(h);
        if let Some(rule) = rule {
            self.domains.prepare(&self.params, rule);
            let (x, w) = (&self.particles.positions, &self.particles.inv_masses);
            self.constraints.prepare_sweeps(x, w, &self.params, rule);
        }
        let path = self.domains.path();
        let mut whole = true;
        // External accelerations inside the integration pass when each particle's depends on
        // its own velocity alone; and then, for a hook that never looks at velocities, each
        // substep's velocity pass waits for the next substep's integration pass: one pass over
        // the particles instead of two, the same arithmetic per particle.
        let inline_accel = self.forces.per_particle() && !strategy.has_internal_forces();
        let defer = inline_accel && !hook.uses_velocities();
        let inv_h = 1.0 / h;
        let keep = (self.forces.damping > 0.0).then(|| (-self.forces.damping * h).exp());
        // The last substep's velocities (and its driven pins') are still to be computed.
        let mut pending = false;
        let mut cg_iterations = 0;
        for k in 0..s.substeps {
            if self.stopping() {
                if pending {
                    self.finish_velocities(inv_h, keep);
                }
                whole = false;
                break;
            }
            let time = self.substep_targets(k);
            // Seams pull towards the rest length of the substep's end.
            self.constraints.set_seam_time(time);
            let ctx = SubstepContext {
                method: s.method,
                time,
                h,
                substep: k,
                frame_end: self.substep_time(s.substeps - 1),
            };
            // External and (mass-spring) internal accelerations at the start of the substep.
            if !inline_accel {
                self.forces
                    .accelerations(&self.particles, &self.all_triangles, &mut self.accel);
                let pass = ForcePass {
                    h,
                    cg: s.cg_limits(),
                    stop: self.stop.as_deref(),
                    simd: path,
                };
                strategy.add_internal_forces(
                    &self.constraints,
                    &self.particles,
                    &self.params,
                    pass,
                    &mut self.spring_work,
                    &mut self.accel,
                );
            }
            // Semi-implicit Euler: v ← v + h a, x ← x + h v (for PBD/XPBD, the prediction), after
            // the last substep's velocity update when it waited for this pass.
            let p = &mut self.particles;
            let forces = &self.forces;
            let finish = std::mem::take(&mut pending);
            p.positions
                .par_chunks_mut(CHUNK)
                .zip(p.prev_positions.par_chunks_mut(CHUNK))
                .zip(p.velocities.par_chunks_mut(CHUNK))
                .zip(p.inv_masses.par_chunks(CHUNK))
                .zip(self.accel.par_chunks(CHUNK))
                .for_each(|((((x, prev), v), w), a)| {
                    for j in 0..x.len() {
                        if finish {
                            v[j] = end_velocity(x[j], prev[j], w[j], inv_h, keep);
                        }
                        prev[j] = x[j];
                        if w[j] > 0.0 {
                            let a = if inline_accel {
                                forces.acceleration_of(v[j])
                            } else {
                                a[j]
                            };
                            v[j] += a * h;
                            x[j] += v[j] * h;
                        }
                    }
                });
            for &(i, x) in &self.targets {
                p.positions[i] = x;
            }
            hook.begin_substep(&ctx, p);
            strategy.begin_substep(&mut self.constraints);
            match rule {
                Some(rule) => {
                    let joint = self.constraints.solves_jointly();
                    for it in 0..s.iterations {
                        if !joint {
                            self.domains.project_global(
                                &mut p.positions,
                                &p.prev_positions,
                                &p.inv_masses,
                                it == 0,
                            );
                        }
                        self.constraints.project_others(
                            &mut p.positions,
                            &p.prev_positions,
                            &p.inv_masses,
                            &self.params,
                            rule,
                            path,
                        );
                        cg_iterations += self.constraints.cg_iterations();
                        stats.contacts = hook.project(&ctx, p);
                    }
                    if self.constraints.seam_count() > 0 {
                        self.constraints.hold_seams(
                            &mut p.positions,
                            &p.prev_positions,
                            &p.inv_masses,
                            rule,
                        );
                    }
                }
                None => stats.contacts = hook.project(&ctx, p),
            }
            if defer && k + 1 < s.substeps {
                // The hook looks at no velocity until the frame ends: the next integration
                // pass computes these (its driven pins hold still in between, w = 0).
                pending = true;
                continue;
            }
            self.finish_velocities(inv_h, keep);
            hook.end_substep(&ctx, &mut self.particles);
        }
        stats.cg_iterations = self.spring_work.iterations + cg_iterations as u32;
        stats.cg_residual = self.spring_work.worst;
        Frame {
            stats,
            whole,
            within: false,
        }
    }

    /// Every particle's velocity from its substep's positions ([`end_velocity`]), in parallel,
    /// then the driven pins' velocities.
    fn finish_velocities(&mut self, inv_h: f64, keep: Option<f64>) {
        let p = &mut self.particles;
        p.velocities
            .par_chunks_mut(CHUNK)
            .zip(p.positions.par_chunks(CHUNK))
            .zip(p.prev_positions.par_chunks(CHUNK))
            .zip(p.inv_masses.par_chunks(CHUNK))
            .for_each(|(((v, x), prev), w)| {
                for j in 0..v.len() {
                    v[j] = end_velocity(x[j], prev[j], w[j], inv_h, keep);
                }
            });
        // Driven pins report the velocity of what carries them, not the chord.
        for &(i, v) in &self.driven_velocities {
            p.velocities[i] = v;
        }
    }
}

/// A particle's velocity at the end of a substep: from its positions (the PBD update; for
/// mass-spring it equals v unless a contact moved the particle), then the global damping
/// v ← v·e^(−c h) of a free particle (`keep`), the fused loop's order
/// (`Domain::finish_velocities`).
#[inline(always)]
pub(super) fn end_velocity(x: DVec3, prev: DVec3, w: f64, inv_h: f64, keep: Option<f64>) -> DVec3 {
    let v = (x - prev) * inv_h;
    // Without damping the factor is 1, which changes no bit: a vectorised select then never
    // multiplies by the undefined payload of `None` (a subnormal there cost a floating-point
    // assist per particle, a fifth of an implicit frame).
    let keep = keep.unwrap_or(1.0);
    if w > 0.0 { v * keep } else { v }
}
