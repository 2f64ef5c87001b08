//! Contacts with a still triangle mesh through its contact grid (`contact_grid`), and the
//! little each particle keeps for them: the triangle it touched last, the side of a closed
//! mesh it was last known on, and where its last projection left it.

use std::sync::atomic::{AtomicU8, AtomicU32, AtomicU64, Ordering::Relaxed};

use glam::DVec3;
use pulp::{Scalar, Simd};
use weft_simd::{Ops, V3, load, store};
use weft_solver::Contacts;

use super::MeshPoint;
use super::closest::{Feature, closest_on_triangle};
use super::contact_grid::{ContactGrid, Side};
use super::face_cert::{FaceCert, Placement, Settled};
use super::frame::{MeshFrame, Outcome, ROUNDS};
use super::grid_lanes::{Lanes, Verdict, gather, local, settle, world};
use super::normals::NONE;

/// Triangles a particle's contact walks across from the one it touched last, at most.
const WALK: usize = 4;

/// Per-particle state of the grid path, indexed by global particle index. Relaxed atomics let
/// the fused frame's domains update their own particles through a shared reference; a particle
/// is only ever touched by the one task that owns it, so each holds what a plain array would.
#[derive(Debug, Default)]
pub(crate) struct GridParticles {
    /// The triangle each particle touched (or came nearest to) last; `u32::MAX`: none.
    hint: Vec<AtomicU32>,
    /// 0: side unknown, 1: outside, 2: inside the closed mesh, when last known.
    side: Vec<AtomicU8>,
    /// Where the last projection left each particle (collider frame), as f64 bits.
    last: Vec<[AtomicU64; 3]>,
    /// Each particle's clear ball (collider frame), as f64 bits: a centre and a radius
    /// (NaN: none) such that no point of the ball is within the particle's thickness of the
    /// mesh.
    ball: Vec<[AtomicU64; 4]>,
}

impl GridParticles {
    /// State for `n` particles: no triangle touched, side unknown.
    pub fn new(n: usize) -> Self {
        Self {
            hint: (0..n).map(|_| AtomicU32::new(u32::MAX)).collect(),
            side: (0..n).map(|_| AtomicU8::new(0)).collect(),
            last: (0..n).map(|_| [0; 3].map(AtomicU64::new)).collect(),
            ball: (0..n)
                .map(|_| [0.0, 0.0, 0.0, f64::NAN].map(|v| AtomicU64::new(v.to_bits())))
                .collect(),
        }
    }

    /// Particle `i`'s clear ball: centre and radius (NaN: none).
    pub(super) fn ball(&self, i: usize) -> (DVec3, f64) {
        let [x, y, z, r] = self.ball[i]
            .each_ref()
            .map(|a| f64::from_bits(a.load(Relaxed)));
        (DVec3::new(x, y, z), r)
    }

    fn set_ball(&self, i: usize, at: DVec3, radius: f64) {
        for (slot, v) in self.ball[i].iter().zip([at.x, at.y, at.z, radius]) {
            slot.store(v.to_bits(), Relaxed);
        }
    }

    /// The triangle particle `i` touched last (`u32::MAX`: none).
    pub(super) fn hint(&self, i: usize) -> u32 {
        self.hint[i].load(Relaxed)
    }

    fn set_hint(&self, i: usize, t: u32) {
        self.hint[i].store(t, Relaxed);
    }

    fn side(&self, i: usize) -> Option<bool> {
        match self.side[i].load(Relaxed) {
            0 => None,
            s => Some(s == 2),
        }
    }

    fn set_side(&self, i: usize, inside: Option<bool>) {
        self.side[i].store(inside.map_or(0, |b| 1 + u8::from(b)), Relaxed);
    }

    /// Where the last projection left particle `i`.
    pub(super) fn last(&self, i: usize) -> DVec3 {
        let [x, y, z] = &self.last[i];
        DVec3::new(
            f64::from_bits(x.load(Relaxed)),
            f64::from_bits(y.load(Relaxed)),
            f64::from_bits(z.load(Relaxed)),
        )
    }

    fn set_last(&self, i: usize, at: DVec3) {
        for (slot, v) in self.last[i].iter().zip(at.to_array()) {
            slot.store(v.to_bits(), Relaxed);
        }
    }
}

impl Clone for GridParticles {
    fn clone(&self) -> Self {
        let copy32 =
            |v: &Vec<AtomicU32>| v.iter().map(|a| AtomicU32::new(a.load(Relaxed))).collect();
        Self {
            hint: copy32(&self.hint),
            side: self
                .side
                .iter()
                .map(|a| AtomicU8::new(a.load(Relaxed)))
                .collect(),
            last: self
                .last
                .iter()
                .map(|l| [0, 1, 2].map(|k| AtomicU64::new(l[k].load(Relaxed))))
                .collect(),
            ball: self
                .ball
                .iter()
                .map(|l| [0, 1, 2, 3].map(|k| AtomicU64::new(l[k].load(Relaxed))))
                .collect(),
        }
    }
}

impl MeshFrame<'_> {
    /// [`MeshFrame::resolve`] through a still mesh's contact grid (particle `i`, global): the
    /// particle's cell lists every triangle within r of it, so nothing is kept per particle
    /// but its path's end, the triangle it touched last and, for a closed mesh, the side it
    /// was last known on.
    ///
    /// Where no triangle is within r, the side is the cell's when the surface does not pass
    /// through the cell, else the one last known: the particle cannot have changed sides
    /// unseen, since a crossing ends within r of the surface unless its path is r/2 or longer,
    /// and such paths are swept.
    pub(crate) fn resolve_in_grid(
        &self,
        (grid, state): (&ContactGrid, &GridParticles),
        i: usize,
        prev: DVec3,
        x: &mut DVec3,
        r: f64,
    ) -> Outcome {
        // The first test, as a block of one (`grid_run`): the same bits as in a run.
        if self.settles() {
            let place = Placement::of(self);
            let (wx, wp) = (x.to_array(), prev.to_array());
            let tested = first_test::<Scalar, 1>(
                Ops(Scalar),
                self,
                (grid.certs(), state),
                &place,
                (&wx, &wp),
                r,
                true,
                i,
            );
            let tally = tested.verdict.contacts;
            match tested.verdict.settled[0] {
                Settled::Open => {}
                Settled::Done => {
                    *x = tested.world_at(0);
                    self.settled_in_grid(state, i, tested.local_at(0), tested.verdict.new_ball[0]);
                    return tally.into();
                }
                Settled::Rounds => {
                    *x = tested.world_at(0);
                    let local = tested.local_at(0);
                    let from = tested.path_start(0);
                    let o = self.rounds_after_settle((grid, state), i, prev, (x, local), from, r);
                    return tally.merge(o.into()).into();
                }
            }
        }
        self.walk_in_grid((grid, state), i, prev, x, r)
    }

    /// Whether the first test of `grid_run` applies: the mesh (its pose and its surface) is
    /// still over the substep.
    #[inline]
    pub(crate) fn settles(&self) -> bool {
        self.still && !self.geometry.moving
    }

    /// Records a particle found clear or settled at `x` (the mesh's frame): outside, left
    /// there, with a new clear ball about `x` of radius `ball` unless NaN.
    #[inline]
    pub(crate) fn settled_in_grid(&self, state: &GridParticles, i: usize, x: DVec3, ball: f64) {
        state.set_side(i, Some(false));
        state.set_last(i, x);
        if !ball.is_nan() {
            state.set_ball(i, x, ball);
        }
    }

    /// The cell's contact rounds for a particle that the first test pushed out of its face
    /// (now at world `x`, `xl` in the mesh's frame, on the path from `from`) and that slipped
    /// too far to be settled.
    pub(crate) fn rounds_after_settle(
        &self,
        (grid, state): (&ContactGrid, &GridParticles),
        i: usize,
        prev: DVec3,
        (x, xl): (&mut DVec3, DVec3),
        from: DVec3,
        r: f64,
    ) -> Outcome {
        state.set_side(i, Some(false));
        self.rounds_in_grid(
            (grid, state),
            i,
            prev,
            x,
            xl,
            (from, None),
            r,
            Outcome::default(),
        )
    }

    /// [`Self::resolve_in_grid`] past the first test: the sweep of a long path, the walk from
    /// the triangle touched last, then the cell.
    pub(crate) fn walk_in_grid(
        &self,
        (grid, state): (&ContactGrid, &GridParticles),
        i: usize,
        prev: DVec3,
        x: &mut DVec3,
        r: f64,
    ) -> Outcome {
        let g = self.geometry;
        let mut out = Outcome::default();
        let (mut xl, from) = self.local_path(*x, prev, || state.last(i));
        // Continuous: a path shorter than r/2 cannot cross the surface from r away, where the
        // last projection left the particle; a longer one is swept through the BVH.
        let short = 0.5 * r;
        let mut keep = None;
        if (xl - from).length_squared() > short * short
            && let Some((t, n, side)) = g.sweep_sided(from, xl)
        {
            let to = from + (xl - from) * t + n * r;
            self.move_to(&mut xl, x, to);
            state.set_side(i, Some(false));
            out.swept += 1;
            if !g.closed() {
                // Held to the side it came from (see `contact`).
                keep = Some(side);
            }
        }
        // The triangle touched last, or one a few edges across from it towards the particle,
        // settles the contact alone where its face is nearest and no triangle in front of its
        // plane is near (see `ContactGrid::clearance`).
        // A particle whose cell lists no triangle, outside, is clear (most that reach here
        // away from the surface): no walk.
        let cell = grid.cell(xl);
        if grid.side(cell) == Side::Outside && cell.is_none_or(|c| grid.list(c).is_empty()) {
            self.clear_in_cell((grid, state), i, cell, xl, r);
            return out;
        }
        let hint = state.hint(i) as usize;
        let mut t = hint;
        // The walk settles a particle in front of the faces only: one held behind an open
        // surface goes to the rounds.
        let walk = if keep.is_some_and(|side| side < 0.0) {
            0
        } else {
            WALK
        };
        for _ in 0..walk {
            let Some(f) = g.face_get(t) else { break };
            let [a, b, c] = f.corners;
            // Clear of everything without the closest point: r or more in front of the plane
            // (so r from every triangle behind it), and near enough to a corner that the
            // triangles in front are beyond r.
            let (s, to_a) = (f.normal.dot(xl - a), (xl - a).length_squared());
            if s >= r && {
                let room = grid.clearance(t) - r;
                room >= 0.0 && to_a <= room * room
            } {
                self.settled_in_grid(state, i, xl, f64::NAN);
                if t != hint {
                    // Where the next substep's first test starts.
                    state.set_hint(i, t as u32);
                }
                return out;
            }
            let q = closest_on_triangle(xl, a, b, c);
            let adjacent = g.topology.adjacent[t];
            // The nearest point of the mesh, if this triangle settles it, with the clearance
            // that covers it: inside the face, from in front; or inside an edge that the
            // neighbour across it gives too (then x − q lies in the cone of the two faces'
            // normals, so it is the nearest point of the wedge behind both planes, where every
            // triangle near both of them lies).
            let settled = match q.feature {
                Feature::Face => (f.normal.dot(xl - q.point) > 0.0).then(|| grid.clearance(t)),
                Feature::Edge(k) => match adjacent[usize::from(k)] {
                    NONE => None,
                    u => g.face_get(u as usize).and_then(|fu| {
                        let [ua, ub, uc] = fu.corners;
                        let across = closest_on_triangle(xl, ua, ub, uc);
                        let shared = matches!(across.feature,
                            Feature::Edge(ku) if g.topology.adjacent[u as usize][usize::from(ku)] as usize == t);
                        shared.then(|| grid.clearance(t).min(grid.clearance(u as usize)))
                    }),
                },
                Feature::Vertex(_) => None,
            };
            let k = match (q.feature, settled) {
                (_, Some(clear)) => {
                    let delta = xl - q.point;
                    let d2 = delta.length_squared();
                    let d = d2.sqrt();
                    if d <= 1e-12 || d.max(r) + r > clear {
                        break;
                    }
                    state.set_side(i, Some(false));
                    state.set_hint(i, t as u32);
                    if d < r {
                        // Outside, off the surface, nearest here: what `signed` gives.
                        let hit = MeshPoint {
                            triangle: t,
                            closest: q,
                            distance: d,
                            normal: delta / d,
                        };
                        if let Some((depth, slip)) = self.push(&hit, &mut xl, x, prev, r) {
                            out.contacts += 1;
                            out.depth = depth;
                            // Pushed to r off the face or edge, then slipped across its
                            // normal: still clear if within the clearance less r.
                            if 2.0 * r + slip > clear {
                                return self.rounds_in_grid(
                                    (grid, state),
                                    i,
                                    prev,
                                    x,
                                    xl,
                                    (from, keep),
                                    r,
                                    out,
                                );
                            }
                        }
                    }
                    state.set_last(i, xl);
                    return out;
                }
                (Feature::Face, None) => break,
                (Feature::Edge(k) | Feature::Vertex(k), None) => k,
            };
            // Across the edge (from a corner, across its first edge) towards the particle.
            match adjacent[usize::from(k)] {
                NONE => break,
                u => t = u as usize,
            }
        }
        self.rounds_in_grid((grid, state), i, prev, x, xl, (from, keep), r, out)
    }

    /// Records particle `i` at `xl` (thickness `r`) clear in `cell`, which lists no triangle
    /// and lies outside: outside, left there, with a clear ball while it stays within its
    /// cell's distance from the mesh, less r.
    fn clear_in_cell(
        &self,
        (grid, state): (&ContactGrid, &GridParticles),
        i: usize,
        cell: Option<usize>,
        xl: DVec3,
        r: f64,
    ) {
        let clear = grid.clear_distance(cell, xl) - r;
        let ball = if clear > 0.0 { clear } else { f64::NAN };
        self.settled_in_grid(state, i, xl, ball);
    }

    /// The contact rounds of [`Self::resolve_in_grid`] through the particle's cell, from
    /// local position `xl` on the path from `from`, held to side `keep` of an open surface if
    /// known (see `MeshFrame::contact`), adding to `out`.
    #[allow(clippy::too_many_arguments)]
    fn rounds_in_grid(
        &self,
        (grid, state): (&ContactGrid, &GridParticles),
        i: usize,
        prev: DVec3,
        x: &mut DVec3,
        mut xl: DVec3,
        (from, mut keep): (DVec3, Option<f64>),
        r: f64,
        mut out: Outcome,
    ) -> Outcome {
        let g = self.geometry;
        let mut cell = grid.cell(xl);
        for _ in 0..ROUNDS {
            let list = cell.map_or(&[][..], |c| grid.list(c));
            let side = grid.side(cell);
            if list.is_empty() && side == Side::Outside {
                self.clear_in_cell((grid, state), i, cell, xl, r);
                return out;
            }
            let scan = self.scan(list, state.hint(i), xl, r);
            let scanned_at = xl;
            let hit = match scan.best {
                Some(best) => self.contact(best, xl, from, &mut keep),
                None => {
                    let inside = g.closed()
                        && match side {
                            Side::Outside => false,
                            Side::Inside => true,
                            Side::Surface => state.side(i).unwrap_or_else(|| {
                                g.nearest(xl, f64::INFINITY)
                                    .is_some_and(|p| p.distance < 0.0)
                            }),
                        };
                    state.set_side(i, Some(inside));
                    if !inside {
                        // The nearest-looking triangle, where the next contact starts.
                        state.set_hint(i, scan.least);
                        break;
                    }
                    // Deep inside a closed mesh: out through the nearest surface.
                    match g.nearest(xl, f64::INFINITY) {
                        Some(p) if p.distance < r => p,
                        _ => break,
                    }
                }
            };
            // Within r of the surface or pushed out of it: outside from here.
            state.set_side(i, Some(false));
            state.set_hint(i, hit.triangle as u32);
            let Some((depth, slip)) = self.push(&hit, &mut xl, x, prev, r) else {
                break;
            };
            out.contacts += 1;
            out.depth = out.depth.max(depth);
            let now = grid.cell(xl);
            // In another cell, triangles this one did not list may be within r.
            let again = now != cell
                || self.look_again(&scan, &hit, (depth, slip), (scanned_at, xl), r, || true);
            if !again {
                break;
            }
            cell = now;
        }
        state.set_last(i, xl);
        out
    }
}

#[cfg(test)]
impl GridParticles {
    /// Every particle's state, as bits, to compare two runs.
    pub(crate) fn snapshot(&self) -> Vec<(u32, u8, [u64; 3], [u64; 4])> {
        (0..self.hint.len())
            .map(|i| {
                (
                    self.hint[i].load(Relaxed),
                    self.side[i].load(Relaxed),
                    self.last[i].each_ref().map(|a| a.load(Relaxed)),
                    self.ball[i].each_ref().map(|a| a.load(Relaxed)),
                )
            })
            .collect()
    }
}

/// A block after its first test: positions in the world's frame and the mesh's, path starts
/// (mesh's frame) and what the test did per lane.
pub(crate) struct Tested<const L: usize> {
    /// Positions in the world's frame (moved where pushed).
    pub world: [[f64; L]; 3],
    /// Positions in the mesh's frame.
    pub local: [[f64; L]; 3],
    /// Path starts in the mesh's frame.
    pub from: [[f64; L]; 3],
    /// What the test did per lane.
    pub verdict: Verdict<L>,
}

impl<const L: usize> Tested<L> {
    /// Lane `l`'s position in the world's frame.
    #[inline(always)]
    pub fn world_at(&self, l: usize) -> DVec3 {
        DVec3::new(self.world[0][l], self.world[1][l], self.world[2][l])
    }

    /// Lane `l`'s position in the mesh's frame.
    #[inline(always)]
    pub fn local_at(&self, l: usize) -> DVec3 {
        DVec3::new(self.local[0][l], self.local[1][l], self.local[2][l])
    }

    /// Lane `l`'s path start in the mesh's frame.
    #[inline(always)]
    pub fn path_start(&self, l: usize) -> DVec3 {
        DVec3::new(self.from[0][l], self.from[1][l], self.from[2][l])
    }
}

/// The first test of particles `i0 .. i0 + L` (global indices, `L` the f64 lanes of `S`) at
/// world positions `wx`, at `wp` at the substep's start, thickness `r`, taking part where
/// `live`, against the triangles they touched last, with the mesh of `frame` still over the
/// substep ([`settle`]). A block whose every live path lies in its clear ball reads no
/// triangle. The block path and the one-particle path test alike through this.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn first_test<S: Simd, const L: usize>(
    o: Ops<S>,
    frame: &MeshFrame<'_>,
    (certs, state): (&[FaceCert], &GridParticles),
    place: &Placement,
    (wx, wp): (&V3<S>, &V3<S>),
    r: S::f64s,
    live: S::m64s,
    i0: usize,
) -> Tested<L> {
    debug_assert_eq!(L, S::F64_LANES);
    let x = local(o, place, wx);
    let prev = local(o, place, wp);
    let from = if frame.fresh {
        prev
    } else {
        let last: [DVec3; L] = std::array::from_fn(|l| state.last(i0 + l));
        std::array::from_fn(|k| load::<S, L>(last.map(|p| p[k])))
    };
    let balls: [(DVec3, f64); L] = std::array::from_fn(|l| state.ball(i0 + l));
    let t: [usize; L] = std::array::from_fn(|l| state.hint(i0 + l) as usize);
    let mut b = Lanes::<S> {
        x,
        from,
        prev,
        r,
        live,
        anchor: std::array::from_fn(|k| load::<S, L>(balls.map(|(c, _)| c[k]))),
        ball: load::<S, L>(balls.map(|(_, radius)| radius)),
    };
    let in_ball = b.in_ball(o);
    let (verdict, moved) = if o.any(o.and(live, o.not(in_ball))) {
        let f = gather::<S, L>(certs, t);
        let (verdict, push) = settle::<S, L>(o, &mut b, in_ball, &f, frame.friction);
        let moved = if o.any(push) {
            world(o, place, wx, &x, &b.x, push)
        } else {
            *wx
        };
        (verdict, moved)
    } else {
        // Nothing within r of any path: no triangle to read.
        let settled = o
            .bits::<L>(live)
            .map(|l| if l { Settled::Done } else { Settled::Open });
        let verdict = Verdict {
            settled,
            new_ball: [f64::NAN; L],
            contacts: Contacts::default(),
        };
        (verdict, *wx)
    };
    Tested {
        world: moved.map(store::<S, L>),
        local: b.x.map(store::<S, L>),
        from: b.from.map(store::<S, L>),
        verdict,
    }
}
