//! A still mesh's contacts on its grid for a run of particles side by side: each particle's
//! first test, against the triangle it touched last, a block of particles at a time (eight
//! on the AVX-512 path, four on AVX2) in explicit vectors (`grid_lanes`). A particle that
//! the triangle settles (clear of the mesh, or pushed out of its face) is done here; the
//! others go on to the walk and the cell of `grid_contacts`, particle by particle. The
//! one-particle path starts with the same test ([`first_test`] with one lane), so the bits do
//! not depend on where a particle falls in a block.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::Simd;
use weft_simd::{LaneKernel, Ops, V3, load_at, on_path};
use weft_solver::{Contacts, ParticleRun};

use super::contact_grid::ContactGrid;
use super::face_cert::{Placement, Settled};
use super::frame::MeshFrame;
use super::grid_contacts::{GridParticles, first_test};

/// Every free particle of `run` against the mesh of `frame`, still over the substep, on
/// `grid`: [`first_test`] a block at a time, each lane taken into the mesh's frame and back,
/// then each particle it left open through `MeshFrame::resolve_in_grid`'s walk, in order.
/// Compiled for the run's kernel path (every path gives the same bits).
pub(crate) fn resolve_grid_run(
    frame: &MeshFrame<'_>,
    grid: (&ContactGrid, &GridParticles),
    r: &[f64],
    run: &mut ParticleRun<'_>,
) -> Contacts {
    on_path(
        run.path,
        Blocks {
            frame,
            grid,
            r,
            run,
        },
    )
}

/// [`resolve_grid_run`]'s arguments, a [`LaneKernel`] run on the vectors of whatever [`Simd`]
/// [`on_path`] hands it.
struct Blocks<'f, 'a, 'r, 'c> {
    frame: &'f MeshFrame<'a>,
    grid: (&'f ContactGrid, &'f GridParticles),
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
        grid: (grid, state),
        r,
        run,
    } = b;
    let start = run.start;
    let n = run.w.len();
    let w = run.w;
    let prev = [&run.prev[0][..n], &run.prev[1][..n], &run.prev[2][..n]];
    let r = &r[..n];
    let [x0, x1, x2] = &mut run.x;
    let x = [&mut x0[..n], &mut x1[..n], &mut x2[..n]];
    let certs = grid.certs();
    let mut total = Contacts::default();
    let full = n - n % L;
    let place = Placement::of(frame);
    for s in (0..full).step_by(L) {
        let wx: V3<S> = std::array::from_fn(|k| load_at::<S, L>(x[k], s));
        let wp: V3<S> = std::array::from_fn(|k| load_at::<S, L>(prev[k], s));
        let wb = load_at::<S, L>(w, s);
        let live = o.not(o.eq(wb, o.c(0.0)));
        let rb = load_at::<S, L>(r, s);
        let tested = first_test::<S, L>(
            o,
            frame,
            (certs, state),
            &place,
            (&wx, &wp),
            rb,
            live,
            start + s,
        );
        total = total.merge(tested.verdict.contacts);
        // The block's own pushes (the other lanes' positions as they were), then the lanes it
        // left to the walk and the cell, one by one (in the world's frame).
        for k in 0..3 {
            x[k][s..s + L].copy_from_slice(&tested.world[k]);
        }
        for l in 0..L {
            let i = start + s + l;
            let out = match tested.verdict.settled[l] {
                Settled::Done => {
                    let ball = tested.verdict.new_ball[l];
                    frame.settled_in_grid(state, i, tested.local_at(l), ball);
                    continue;
                }
                Settled::Open if w[s + l] == 0.0 => continue,
                settled => {
                    let mut p = tested.world_at(l);
                    let start_pos = DVec3::new(prev[0][s + l], prev[1][s + l], prev[2][s + l]);
                    let out = if settled == Settled::Rounds {
                        frame.rounds_after_settle(
                            (grid, state),
                            i,
                            start_pos,
                            (&mut p, tested.local_at(l)),
                            tested.path_start(l),
                            r[s + l],
                        )
                    } else {
                        frame.walk_in_grid((grid, state), i, start_pos, &mut p, r[s + l])
                    };
                    for k in 0..3 {
                        x[k][s + l] = p[k];
                    }
                    out
                }
            };
            total = total.merge(out.into());
        }
    }
    for j in full..n {
        if w[j] == 0.0 {
            continue;
        }
        let mut p = DVec3::new(x[0][j], x[1][j], x[2][j]);
        let before = DVec3::new(prev[0][j], prev[1][j], prev[2][j]);
        let out = frame.resolve_in_grid((grid, state), start + j, before, &mut p, r[j]);
        for k in 0..3 {
            x[k][j] = p[k];
        }
        total = total.merge(out.into());
    }
    total
}

#[cfg(test)]
#[path = "grid_run_tests.rs"]
mod tests;
