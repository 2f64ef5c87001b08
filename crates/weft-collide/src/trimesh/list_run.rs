//! A mesh's contacts through its candidate lists (`candidates`) for a run of particles side by
//! side, in the mesh's own frame (a mesh whose pose is the identity throughout: a deforming
//! mesh, or a still one too large for a contact grid). Where the mesh certifies its particles
//! (`MeshFrame::certifies`: it moves little over the frame), the certified test (`certified`)
//! screens the run a block at a time and settles most of a resting cloth's particles against
//! the one face under each; a particle it leaves open goes over its face's edge
//! (`edge_contact`), among its face's ring (`MeshFrame::resolve_ring`), or through its lists
//! (`MeshFrame::resolve`), and is certified again. Elsewhere each particle goes through
//! `resolve`.
//!
//! What a lane does depends on that particle alone, the run's last particles (past the last
//! full block) take the same tests a lane at a time, and so does a particle resolved on its
//! own, in the fused frame or the general loop ([`MeshFrame::resolve_listed`]): the bits do not
//! depend on where a particle falls, nor on which loop runs it.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::{Scalar, Simd};
use weft_simd::{LaneKernel, Ops, on_path};
use weft_solver::{Contacts, ParticleRun};

use super::certified::{certified, face_test, screen};
use super::chunk_lists::ChunkLists;
use super::frame::{MeshFrame, Outcome, RunParticle};

impl MeshFrame<'_> {
    /// Whether the block test of [`resolve_list_run`] applies: the mesh's pose is the identity
    /// over the substep (its surface may deform).
    #[inline]
    pub(crate) fn lists_settle(&self) -> bool {
        self.identity && self.still
    }
}

/// Every free particle of `run` (thickness `r`) against the mesh of `frame` (for which
/// [`MeshFrame::lists_settle`] holds), through the run's candidate lists `lists` (indexed
/// from the run's start): the certified test's screen (`screen`) a block at a time, its face
/// test (`face_test`) on the particles the screen sends it packed into full blocks, then the
/// edge, the ring or `MeshFrame::resolve` for each particle they left open. Compiled for the run's
/// kernel path (every path gives the same bits).
pub(crate) fn resolve_list_run(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    on_path(
        run.path,
        Blocks {
            frame,
            lists,
            r,
            run,
        },
    )
}

/// [`resolve_list_run`]'s arguments, a [`LaneKernel`] run on the vectors of whatever [`Simd`]
/// [`on_path`] hands it.
struct Blocks<'f, 'a, 'r, 'c> {
    frame: &'f MeshFrame<'a>,
    lists: &'f mut ChunkLists,
    r: &'f [f64],
    run: &'r mut ParticleRun<'c>,
}

impl LaneKernel for Blocks<'_, '_, '_, '_> {
    type Output = Contacts;

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) -> Contacts {
        run_blocks::<S, L>(Ops(s), self)
    }
}

#[inline(always)]
fn run_blocks<S: Simd, const L: usize>(o: Ops<S>, b: Blocks<'_, '_, '_, '_>) -> Contacts {
    let Blocks {
        frame,
        lists,
        r,
        run,
    } = b;
    let n = run.w.len();
    if !r[..n].iter().any(|&r| frame.certifies(r)) {
        return each_resolved(frame, lists, r, run);
    }
    let full = n - n % L;
    let mut total = Contacts::default();
    // The screen a block at a time; the lanes it sends to the face test are queued, and
    // tested packed into full blocks after (what a lane does depends on that particle
    // alone, so not on which block it is tested in).
    let mut queue = std::mem::take(&mut lists.queue);
    queue.clear();
    for s in (0..full).step_by(L) {
        let (mut x, mut prev, mut rr) = ([[0.0; L]; 3], [[0.0; L]; 3], [0.0; L]);
        for k in 0..3 {
            x[k].copy_from_slice(&run.x[k][s..s + L]);
            prev[k].copy_from_slice(&run.prev[k][s..s + L]);
        }
        rr.copy_from_slice(&r[s..s + L]);
        let live: [bool; L] = std::array::from_fn(|l| run.w[s + l] != 0.0);
        let screened = screen::<S, L>(o, frame, lists, s, (&x, &prev), (&rr, live));
        queue.extend((0..L).filter(|&l| screened.near[l]).map(|l| s + l));
        for l in 0..L {
            if live[l] && !screened.settled[l] && !screened.near[l] {
                let j = s + l;
                total = total.merge(on_particle(run, j, |prev, p| {
                    frame
                        .open(RunParticle::new(lists, j, prev, p, r[j]), false)
                        .into()
                }));
            }
        }
    }
    for block in queue.chunks(L) {
        // A short block's spare lanes repeat its first particle and take no part.
        let j: [usize; L] = std::array::from_fn(|l| block.get(l).copied().unwrap_or(block[0]));
        let near: [bool; L] = std::array::from_fn(|l| l < block.len());
        let (mut x, mut prev, mut rr) = ([[0.0; L]; 3], [[0.0; L]; 3], [0.0; L]);
        for l in 0..L {
            for k in 0..3 {
                x[k][l] = run.x[k][j[l]];
                prev[k][l] = run.prev[k][j[l]];
            }
            rr[l] = r[j[l]];
        }
        let done = face_test::<S, L>(o, frame, lists, &j, (&mut x, &prev), (&rr, near));
        total = total.merge(done.contacts);
        for l in (0..L).filter(|&l| near[l]) {
            for k in 0..3 {
                run.x[k][j[l]] = x[k][l];
            }
            if !done.settled[l] {
                total = total.merge(on_particle(run, j[l], |prev, p| {
                    frame
                        .open(RunParticle::new(lists, j[l], prev, p, rr[l]), done.ring[l])
                        .into()
                }));
            }
        }
    }
    lists.queue = queue;
    for j in full..n {
        if run.w[j] == 0.0 {
            continue;
        }
        total = total.merge(on_particle(run, j, |prev, p| {
            frame
                .resolve_listed(RunParticle::new(lists, j, prev, p, r[j]))
                .into()
        }));
    }
    total
}

/// `f` on particle `j` of `run`: its substep start, and its position, moved in place.
#[inline(always)]
fn on_particle(
    run: &mut ParticleRun<'_>,
    j: usize,
    f: impl FnOnce(DVec3, &mut DVec3) -> Contacts,
) -> Contacts {
    let mut p = DVec3::new(run.x[0][j], run.x[1][j], run.x[2][j]);
    let prev = DVec3::new(run.prev[0][j], run.prev[1][j], run.prev[2][j]);
    let made = f(prev, &mut p);
    for k in 0..3 {
        run.x[k][j] = p[k];
    }
    made
}

/// A run none of whose particles the mesh certifies (`MeshFrame::certifies`): each free
/// particle through `resolve`, in order.
#[inline(always)]
fn each_resolved(
    frame: &MeshFrame<'_>,
    lists: &mut ChunkLists,
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    let mut total = Contacts::default();
    for j in 0..run.w.len() {
        if run.w[j] != 0.0 {
            total = total.merge(on_particle(run, j, |prev, p| {
                frame
                    .resolve(RunParticle::new(lists, j, prev, p, r[j]))
                    .into()
            }));
        }
    }
    total
}

impl MeshFrame<'_> {
    /// Particle `j` of `lists` (thickness `r`, previous position `prev`, current `x`) as a
    /// run of one: the certified test first where [`Self::lists_settle`] holds,
    /// else `resolve`. Every particle of a mesh with lists takes this path or a block of the
    /// same tests, so its bits do not depend on which.
    pub(crate) fn resolve_listed(&self, p: RunParticle<'_>) -> Outcome {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        if !self.lists_settle() {
            return self.resolve(RunParticle::new(lists, j, prev, x, r));
        }
        let mut at = [[x.x], [x.y], [x.z]];
        let before = [[prev.x], [prev.y], [prev.z]];
        let done = certified::<Scalar>(
            Ops(Scalar),
            self,
            lists,
            j,
            (&mut at, &before),
            (&[r], [true]),
        );
        *x = DVec3::new(at[0][0], at[1][0], at[2][0]);
        if done.settled[0] {
            return done.contacts.into();
        }
        let out = self.open(RunParticle::new(lists, j, prev, x, r), done.ring[0]);
        Contacts::from(out).merge(done.contacts).into()
    }

    /// Particle `j` left open by the certified test: among its face's ring where its
    /// certificate allows (`ring`), else through the lists; a new certificate where it has
    /// come to rest on another face.
    fn open(&self, p: RunParticle<'_>, ring: bool) -> Outcome {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        // Over a convex edge of its face by that edge, else among the face's ring, else
        // through the lists.
        let settled = if ring {
            (self.edge_contact(RunParticle::new(lists, j, prev, x, r)))
                .or_else(|| self.resolve_ring(RunParticle::new(lists, j, prev, x, r)))
        } else {
            None
        };
        let out = match settled {
            Some(out) => out,
            None => self.resolve(RunParticle::new(lists, j, prev, x, r)),
        };
        // As a run none of whose particles the mesh certifies would (`each_resolved`).
        if self.certifies(r) {
            self.recertify(lists, j, *x, r);
        }
        out
    }
}

#[cfg(test)]
#[path = "list_run_tests.rs"]
mod tests;
