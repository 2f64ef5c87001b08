//! The contacts of a run of particles, as the solver's fused pass hands them over: one
//! particle ([`ParticleContacts::resolve`]) or a domain's run at a time, through the
//! closed-form colliders, the contact grids of still meshes and the candidate lists of the
//! others.

use super::*;

/// One particle's part of [`SubstepHook::project`] with closed-form colliders and our triangle
/// meshes (no bodies, no self-collision): on the substep's first pass the sweep, then the
/// push-out from each collider in reach, in order — the same calls as `sweep` and
/// `resolve_colliders` make for that particle. The fused pass calls `resolve_run`, one
/// trait-object call per domain.
impl ParticleContacts for CollisionWorld {
    #[inline]
    fn resolve(&self, i: usize, x: &mut DVec3, prev: DVec3, fresh: bool) -> Contacts {
        let frames = self.grid_frames(fresh);
        let all = 0..frames.len();
        match listed(&frames) {
            0 => self.resolve_particle(&frames, all, fresh, (&mut [], i, 0), i, x, prev),
            // The lists of the domain's run holding i, if the fused frame keeps one.
            meshes => {
                let (owned, start) = self.run_lists.lock_holding(i, meshes);
                let mut lists = owned.get();
                self.resolve_particle(&frames, all, fresh, (&mut lists, start, 0), i, x, prev)
            }
        }
    }

    /// [`Self::resolve`] on every free particle of the run, collider by collider (each
    /// particle meets the colliders in the same order, and what one particle meets depends on
    /// that particle alone, so the bits are the same): the substep's sweep first, then each
    /// still half-space or ball a block of particles at a time ([`resolve_still`]), each mesh
    /// still over the substep on its grid a block at a time too ([`resolve_grid_run`]), any
    /// other collider particle by particle (a mesh off a grid through the run's candidate
    /// lists, locked for the pass).
    fn resolve_run(&self, run: ParticleRun<'_>, fresh: bool) -> Contacts {
        let frames = self.grid_frames(fresh);
        let start = run.start;
        let particles = start..start + run.w.len();
        self.with_run_lists(&frames, particles, |lists| {
            self.resolve_run_with(&frames, lists, run, fresh)
        })
    }
}

impl CollisionWorld {
    /// Calls `f` with the candidate lists of the run of particles `particles` (a domain's) for
    /// the meshes of `frames` off a grid (none if there is none), held for the whole call.
    fn with_run_lists<R>(
        &self,
        frames: &[Option<MeshOf<'_>>],
        particles: Range<usize>,
        f: impl FnOnce(&mut [ChunkLists]) -> R,
    ) -> R {
        let meshes = listed(frames);
        if meshes == 0 {
            return f(&mut []);
        }
        let owned = self
            .run_lists
            .lock(particles.start, particles.len(), meshes);
        let mut lists = owned.get();
        f(&mut lists)
    }

    /// [`ParticleContacts::resolve_run`] with the frames of [`Self::grid_frames`] and the run's
    /// candidate lists.
    fn resolve_run_with(
        &self,
        frames: &[Option<MeshOf<'_>>],
        lists: &mut [ChunkLists],
        mut run: ParticleRun<'_>,
        fresh: bool,
    ) -> Contacts {
        let start = run.start;
        let r = &self.thickness[start..start + run.w.len()];
        let n = self.colliders.len();
        let mut total = Contacts::default();
        // Collider j's block form, if it has one.
        let blocked = |j: usize| match still_surface(&self.colliders[j], &self.reach[j]) {
            Some(s) => Some(Blocked::Surface(s)),
            None => match &frames[j] {
                Some((frame, Some(grid))) if frame.settles() => Some(Blocked::Mesh(frame, *grid)),
                _ => None,
            },
        };
        let (mut k, mut sweep) = (0, fresh);
        while k < n || sweep {
            // Colliders `k..stop` particle by particle (after the sweep in the substep's
            // first pass), then collider `stop`, if any, a block at a time.
            let next = (k..n).find_map(|j| blocked(j).map(|b| (j, b)));
            let stop = next.as_ref().map_or(n, |(j, _)| *j);
            if stop > k {
                let slot = listed(&frames[..k]);
                let pass = run.each_free(|i, p, before| {
                    let lists = (&mut *lists, start, slot);
                    self.resolve_particle(frames, k..stop, sweep, lists, i, p, before)
                });
                total = total.merge(pass);
                sweep = false;
            } else if sweep {
                total.swept += self.sweep_run(frames, &mut run, r);
                sweep = false;
            }
            match next {
                Some((_, Blocked::Surface(surface))) => {
                    let [a, b, c] = &mut run.x;
                    let block = Run {
                        x: [&mut **a, &mut **b, &mut **c],
                        prev: run.prev,
                        w: run.w,
                        r,
                    };
                    let friction = self.colliders[stop].friction();
                    total = total.merge(resolve_still(surface, friction, block, run.path));
                }
                Some((_, Blocked::Mesh(frame, grid))) => {
                    total = total.merge(resolve_grid_run(frame, grid, r, &mut run));
                }
                None => {}
            }
            k = stop + 1;
        }
        total
    }
}

/// A collider that a run takes a block of particles at a time.
enum Blocked<'f, 'a> {
    /// A still half-space or ball.
    Surface(Surface),
    /// A mesh still over the substep, on its grid.
    Mesh(&'f MeshFrame<'a>, GridRef<'a>),
}

impl CollisionWorld {
    /// Per collider, the frame of a triangle mesh of ours and its grid if it has one.
    fn grid_frames(&self, fresh: bool) -> Vec<Option<MeshOf<'_>>> {
        (self.colliders.iter().enumerate())
            .map(|(k, c)| {
                let frame = mesh_frame(c, fresh).filter(|_| self.own_mesh(c))?;
                Some((frame, self.grid(k)))
            })
            .collect()
    }

    /// The substep's sweep (as [`sweep_one`]) of every free particle of `run`, thickness `r`,
    /// alone: a particle whose path is shorter than half its thickness (most) costs a few
    /// loads and a comparison, read straight from the run's arrays (no closure per particle).
    fn sweep_run(
        &self,
        frames: &[Option<MeshOf<'_>>],
        run: &mut ParticleRun<'_>,
        r: &[f64],
    ) -> usize {
        let mesh = |k: usize| frames[k].is_some();
        let n = run.w.len();
        let (w, prev, r) = (run.w, run.prev, &r[..n]);
        let [x0, x1, x2] = &mut run.x;
        let (x0, x1, x2) = (&mut x0[..n], &mut x1[..n], &mut x2[..n]);
        let (p0, p1, p2) = (&prev[0][..n], &prev[1][..n], &prev[2][..n]);
        let mut swept = 0;
        // Eight particles' paths measured together first (one vector pass over the run's
        // arrays, as `short_path`); only a block with a long path is walked one by one.
        let mut j = 0;
        while j < n {
            if j % BLOCK == 0 && j + BLOCK <= n {
                let long = (j..j + BLOCK).fold(false, |any, k| {
                    let d = [x0[k] - p0[k], x1[k] - p1[k], x2[k] - p2[k]];
                    let slow = 0.5 * r[k].max(1e-6);
                    let free = w[k] != 0.0;
                    // Not short (`short_path`), NaN included.
                    let short = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= slow * slow;
                    any | (free & !short)
                });
                if !long {
                    j += BLOCK;
                    continue;
                }
            }
            let k = j;
            j += 1;
            let mut x = DVec3::new(x0[k], x1[k], x2[k]);
            let from = DVec3::new(p0[k], p1[k], p2[k]);
            if w[k] == 0.0 || short_path(x, from, r[k]) {
                continue;
            }
            let (colliders, bounds, parry) = (&self.colliders, &self.bounds, self.parry_meshes);
            swept += sweep_path(colliders, bounds, mesh, parry, from, &mut x, r[k]);
            (x0[k], x1[k], x2[k]) = (x.x, x.y, x.z);
        }
        swept
    }

    /// [`ParticleContacts::resolve`] with the frames of [`Self::grid_frames`], against colliders
    /// `range` alone, after the substep's sweep when `sweep`; `lists` are the candidate lists
    /// of the run from particle `lists.1` for the meshes off a grid, the first of `range`'s
    /// at `lists.2`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn resolve_particle(
        &self,
        frames: &[Option<MeshOf<'_>>],
        range: Range<usize>,
        sweep: bool,
        (lists, start, mut slot): (&mut [ChunkLists], usize, usize),
        i: usize,
        x: &mut DVec3,
        prev: DVec3,
    ) -> Contacts {
        let (parry, r) = (self.parry_meshes, self.thickness[i]);
        let mut out = Contacts::default();
        // Meshes (on their grids here) sweep in their own contacts.
        if sweep {
            let mesh = |k: usize| frames[k].is_some();
            out.swept = sweep_one(&self.colliders, &self.bounds, mesh, parry, prev, x, r);
        }
        let colliders = self.colliders[range.clone()].iter();
        for ((c, reach), frame) in colliders
            .zip(&self.reach[range.clone()])
            .zip(&frames[range])
        {
            if let Some((frame, grid)) = frame {
                let o = match grid {
                    Some(grid) => frame.resolve_in_grid(*grid, i, prev, x, r),
                    None => {
                        slot += 1;
                        frame.resolve(RunParticle::new(
                            &mut lists[slot - 1],
                            i - start,
                            prev,
                            x,
                            r,
                        ))
                    }
                };
                out = out.merge(o.into());
            } else if reach.may_touch(*x, r) {
                let (n, depth) = resolve_one(c, parry, prev, x, r);
                out.contacts += n;
                out.depth = out.depth.max(depth);
            }
        }
        out
    }
}
