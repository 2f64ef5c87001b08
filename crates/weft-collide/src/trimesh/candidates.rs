//! Per-particle candidate lists of a mesh collider, and one particle's contacts through them.
//!
//! Each particle keeps the triangles that were within a radius R of an anchor (its position
//! when the list was built), at their positions then. Every triangle the particle can touch
//! from x (a contact, distance < r) or on its path `from → x` (a crossing) is listed while
//!
//! max(|x − anchor|, |from − anchor|) + (travel of the surface since the build) + r ≤ R,
//!
//! since distances move by at most the particle's and the surface's displacements (a Verlet
//! or skin list; Verlet 1967). The check is a few flops per particle; a particle that fails it
//! gets a new list from the BVH with R = r (1 + skin) + |from − x| + the surface's motion this
//! substep. An empty list records how far the nearest triangle is (or the mesh's box), so far
//! particles are checked as rarely. On a deforming mesh whose fastest vertex would use up a
//! list's skin before the frame ends (a jumping body), a list is built instead with a riding
//! certificate (`riding`), which bounds the triangles' motion relative to the particle's own
//! and lasts to the frame's end. The lists live in arenas of a fixed chunk of particles, each
//! updated by one task: results do not depend on the thread count.

use glam::DVec3;

use super::MeshPoint;
use super::closest::Closest;
#[cfg(test)]
#[path = "candidates_tests.rs"]
mod tests;
use super::bvh::box_distance_squared;
use super::ccd::{Crossing, moving_crossing, segment_crossing};
use super::chunk_lists::ChunkLists;
use super::closest::closest_on_triangle;
use super::frame::{GUARD, MeshFrame, Outcome, ROUNDS, RunParticle, SKIN};
use super::riding::Riding;

/// Triangles near enough to a contact to be checked again after its push, at most.
const NEAR: usize = 16;

/// Triangles whose bounds a scan computes together.
const SCAN_BLOCK: usize = 32;

/// The least cosine between a particle's direction from its closest point on an open surface
/// and that feature's pseudo-normal (or its opposite) that tells which side it is on.
const SIDED: f64 = 0.5;

impl MeshFrame<'_> {
    /// Whether particle `j`'s list holds every triangle within `r` of `x` and of the path
    /// `from → x` (local): by its bound on the whole mesh's travel, or by its riding
    /// certificate.
    fn valid(&self, lists: &ChunkLists, j: usize, x: DVec3, from: DVec3, r: f64) -> bool {
        self.valid_by_travel(lists, j, x, from, r)
            || (lists.riding_frame == self.geometry.frame_id
                && lists.riding[j].holds(self.geometry, x, from, self.fresh, r))
    }

    /// [`Self::valid`] by the bound on the whole mesh's travel since the build alone.
    #[inline]
    pub(super) fn valid_by_travel(
        &self,
        lists: &ChunkLists,
        j: usize,
        x: DVec3,
        from: DVec3,
        r: f64,
    ) -> bool {
        let g = self.geometry;
        let anchor = lists.anchor[j];
        // max(|x − anchor|, |from − anchor|) ≤ slack, compared squared.
        let slack = lists.radius[j] - (g.travel - lists.travel[j]) - r;
        slack >= 0.0
            && (x - anchor)
                .length_squared()
                .max((from - anchor).length_squared())
                <= slack * slack
    }

    /// Makes particle `j`'s list valid for position `x` and path start `from` (local).
    pub(super) fn ensure(&self, lists: &mut ChunkLists, j: usize, x: DVec3, from: DVec3, r: f64) {
        if self.valid(lists, j, x, from, r) {
            return;
        }
        let g = self.geometry;
        lists.builds += 1;
        let radius = r * (1.0 + SKIN) + (from - x).length() + (g.travel - g.travel_before);
        let old = lists.range[j];
        lists.live -= (old.1 + lists.guard[j]) as usize;
        let (lo, hi) = g.bounds();
        let outside_box = box_distance_squared(x, lo, hi).sqrt();
        // Inside a closed mesh's box an empty list needs the nearest triangle of all (the
        // inside flag and the clearance): the same search finds it.
        let deep = g.closed() && outside_box == 0.0;
        let start = lists.tris.len();
        let (nearest, guard, riding) = match self.riding_search(lists, (x, from), radius, r, deep) {
            Some(found) => found,
            None => {
                // The nearest triangle lies within its distance at the last build and how far
                // the particle and the surface have moved since: the deep search starts there.
                let beyond = deep.then(|| {
                    let moved = (x - lists.anchor[j]).length() + (g.travel - lists.travel[j]);
                    (lists.nearest[j] + moved) * (1.0 + 1e-9)
                });
                let nearest = g.within(x, radius, beyond, &mut lists.tris);
                (nearest, 0, Riding::NONE)
            }
        };
        let len = lists.tris.len() - start - guard;
        lists.live += len + guard;
        lists.range[j] = (start as u32, len as u32);
        lists.guard[j] = guard as u32;
        // A certificate of an earlier frame no longer holds: left in place where none of
        // this frame is in the chunk.
        if riding.frame != 0 || lists.riding_frame == g.frame_id {
            lists.riding[j] = riding;
            lists.riding_frame = lists.riding_frame.max(riding.frame);
        }
        lists.anchor[j] = x;
        lists.travel[j] = g.travel_before;
        lists.nearest[j] = nearest.map_or(f64::INFINITY, |p| p.distance.abs());
        let (clearance, inside) = match nearest {
            // The nearest listed triangle is the nearest of all (it is within R).
            Some(p) if len > 0 => (radius, p.distance < 0.0),
            Some(p) => (
                radius.max(p.distance.abs() * (1.0 - 1e-12)),
                p.distance < 0.0,
            ),
            None if deep => (radius, false),
            None => (radius.max(outside_box), false),
        };
        lists.radius[j] = clearance;
        lists.inside[j] = inside;
    }

    /// On a deforming mesh, the search for particle `j`'s list at `x` (on a path from `from`)
    /// with `radius` as a riding list (`riding`), riding with the particle's own motion over
    /// the substep, scaled to the frame: the list and then its guard appended to the arena,
    /// and (the nearest listed triangle, the guard's length, the certificate). `None`, and
    /// nothing appended, on the substep's later projections (no motion to ride with), where a
    /// plain list would last the frame out, or where the list is empty and `deep` (inside a
    /// closed mesh's box, where an empty list needs the nearest triangle of all for its side).
    fn riding_search(
        &self,
        lists: &mut ChunkLists,
        (x, from): (DVec3, DVec3),
        radius: f64,
        r: f64,
        deep: bool,
    ) -> Option<(Option<MeshPoint>, usize, Riding)> {
        let g = self.geometry;
        let (w_before, w) = g.frame_span;
        if g.frame_id == 0 || !self.fresh || w <= w_before {
            return None;
        }
        // Only where a plain list would not last the frame out: its skin used up by the
        // particle and the surface each moving as far as the fastest vertex did this substep.
        let substep = g.travel - g.travel_before;
        if r * SKIN * (w - w_before) >= 2.0 * substep * (1.0 - w) {
            return None;
        }
        let motion = (x - from) / (w - w_before);
        if !motion.is_finite() {
            return None;
        }
        let outer = radius + GUARD * r;
        let start = lists.tris.len();
        let mut guard = std::mem::take(&mut lists.scratch);
        guard.clear();
        let (nearest, spread) = g.within_riding(
            x,
            (radius, outer),
            (motion, 1.0 - w),
            &mut lists.tris,
            &mut guard,
        );
        let found = if lists.tris.len() == start && deep {
            None
        } else {
            lists.tris.extend_from_slice(&guard);
            let riding = Riding::new(g, x, motion, spread, (radius, outer));
            Some((nearest, guard.len(), riding))
        };
        lists.scratch = guard;
        found
    }

    /// Whether the path `from → x` is shorter than r/2 relative to the surface (its motion
    /// this substep taken off, on the substep's first projection): it cannot cross the surface
    /// from r away, where the last projection left the particle (as the closed-form shapes'
    /// sweep).
    #[inline]
    pub(super) fn short_path(&self, from: DVec3, x: DVec3, r: f64) -> bool {
        let g = self.geometry;
        let surface = if self.fresh && g.moving {
            g.travel - g.travel_before
        } else {
            0.0
        };
        let short = 0.5 * r - surface;
        short >= 0.0 && (x - from).length_squared() <= short * short
    }

    /// The earliest crossing of the path `from → x` with a listed triangle: (crossing,
    /// triangle).
    fn first_crossing(
        &self,
        list: &[u32],
        from: DVec3,
        x: DVec3,
        r: f64,
    ) -> Option<(Crossing, usize)> {
        let g = self.geometry;
        let closed = g.closed();
        let moving = self.fresh && g.moving;
        if self.short_path(from, x, r) {
            return None;
        }
        let mut best: Option<(Crossing, usize)> = None;
        for &t in list {
            let t = t as usize;
            let f = g.face(t);
            let hit = if moving {
                let start = g.start_corners(t);
                // Cheap reject: the path's box misses the triangle's swept box.
                let (lo, hi) = (from.min(x), from.max(x));
                let tlo = f.corners[0].min(f.corners[1]).min(f.corners[2]);
                let thi = f.corners[0].max(f.corners[1]).max(f.corners[2]);
                let slo = start[0].min(start[1]).min(start[2]).min(tlo);
                let shi = start[0].max(start[1]).max(start[2]).max(thi);
                if lo.cmpgt(shi).any() || hi.cmplt(slo).any() {
                    continue;
                }
                moving_crossing(from, x, start, f.corners, closed)
            } else {
                segment_crossing(from, x, f.corners, f.normal, closed)
            };
            if let Some(c) = hit
                && best.is_none_or(|b| c.t < b.0.t)
            {
                best = Some((c, t));
            }
        }
        best
    }

    /// Particle `j` (thickness `r`, previous position `prev`, current `x`, world space):
    /// stops a crossing of the surface on the side it came from, then pushes it to distance r
    /// from the surface with Coulomb friction against the surface's motion.
    pub fn resolve(&self, p: RunParticle<'_>) -> Outcome {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        let g = self.geometry;
        let mut out = Outcome::default();
        let (mut xl, from) = self.local_path(*x, prev, || lists.last[j]);
        // Continuous: a crossing on the path is undone, the particle left r off the surface
        // (where the surface is at the end of the substep) on the side it came from.
        self.ensure(lists, j, xl, from, r);
        // The list is valid where the particle is (ensure needs calling only after a move).
        let mut listed = true;
        // The side of an open surface the particle is held to (see `contact`).
        let mut keep = None;
        let (s, len) = lists.range[j];
        if len == 0 && !lists.inside[j] {
            // No triangle within r of the particle or its path: nothing to do.
            lists.last[j] = xl;
            return out;
        }
        if let Some((c, t)) =
            self.first_crossing(&lists.tris[s as usize..(s + len) as usize], from, xl, r)
        {
            let f = g.face(t);
            let [a, b, cc] = f.corners;
            let hit = a * c.bary[0] + b * c.bary[1] + cc * c.bary[2];
            self.move_to(&mut xl, x, hit + f.normal * (c.side * r));
            keep = Some(c.side);
            listed = false;
            out.swept += 1;
        }
        // After a push by δ every distance drops by at most δ: a round is needed again only
        // if the runner-up of the last one (a lower bound on its distance) was within r + δ.
        let mut again = true;
        for _ in 0..ROUNDS {
            if !again {
                break;
            }
            if !listed {
                self.ensure(lists, j, xl, from, r);
            }
            listed = false; // a push follows, or the loop ends
            let (s, len) = lists.range[j];
            let scan = self.scan(
                &lists.tris[s as usize..(s + len) as usize],
                lists.hint[j],
                xl,
                r,
            );
            let scanned_at = xl;
            let hit = match scan.best {
                Some(best) => self.contact(best, xl, from, &mut keep),
                None if lists.inside[j] => {
                    // Deep inside a closed mesh: out through the nearest surface.
                    match g.nearest(xl, f64::INFINITY) {
                        Some(p) if p.distance < r => {
                            lists.radius[j] = f64::NAN;
                            lists.riding[j] = Riding::NONE;
                            p
                        }
                        _ => break,
                    }
                }
                None => break,
            };
            lists.hint[j] = hit.triangle as u32;
            let Some((depth, slip)) = self.push(&hit, &mut xl, x, prev, r) else {
                break;
            };
            again = self.look_again(&scan, &hit, (depth, slip), (scanned_at, xl), r, || {
                self.valid(lists, j, xl, from, r)
            });
            out.contacts += 1;
            out.depth = out.depth.max(depth);
        }
        lists.last[j] = xl;
        out
    }

    /// A particle's position `x` and the start of its path in the collider's frame: on the
    /// substep's first projection its position `prev` at the substep's start (at the start
    /// pose), else where the last projection left it (`last`).
    #[inline]
    pub(super) fn local_path(
        &self,
        x: DVec3,
        prev: DVec3,
        last: impl FnOnce() -> DVec3,
    ) -> (DVec3, DVec3) {
        let from = if self.fresh {
            self.to_local(self.prev_pose, prev)
        } else {
            last()
        };
        (self.to_local(self.pose, x), from)
    }

    /// Moves the particle to `to` (local), its world position `x` along.
    pub(super) fn move_to(&self, xl: &mut DVec3, x: &mut DVec3, to: DVec3) {
        *x += self.to_world_vector(to - *xl);
        *xl = to;
    }

    /// The nearest of `list`'s triangles (and `hint`, tested first: it tightens the search)
    /// within r of `xl`, with bounds on the others.
    pub(super) fn scan(&self, list: &[u32], hint: u32, xl: DVec3, r: f64) -> Scan {
        let g = self.geometry;
        let mut best: Option<(f64, usize, Closest)> = None;
        let mut bound = r * r;
        let mut second = f64::INFINITY;
        let x32 = xl.as_vec3();
        // The triangles whose bound is within 2r (a push and a slip of up to r may bring
        // them within r) with that bound, and the least bound of the others (squared).
        let (mut near, mut n_near, mut others) = ([(0u32, 0.0f64); NEAR], 0, f64::INFINITY);
        let mut least = (f64::INFINITY, u32::MAX);
        let mut note = |t: u32, lower: f64| {
            if lower < least.0 {
                least = (lower, t);
            }
            if lower >= 4.0 * r * r {
                others = others.min(lower);
            } else if n_near < NEAR {
                near[n_near] = (t, lower);
                n_near += 1;
            } else {
                others = 0.0; // too many to follow
            }
        };
        if let (Some(f), Some(planes)) = (g.face_get(hint as usize), g.planes.get(hint as usize)) {
            let mut lower = f64::from(planes.distance_squared_bound(x32, g.margin));
            if lower < bound {
                let [a, b, c] = f.corners;
                let q = closest_on_triangle(xl, a, b, c);
                let d2 = (xl - q.point).length_squared();
                lower = d2;
                if d2 < bound {
                    bound = d2;
                    best = Some((d2, hint as usize, q));
                }
            }
            if best.is_none() {
                // Not the nearest: a runner-up like the others.
                second = lower;
            }
            note(hint, lower);
        }
        // The bounds of a block first, with no branch between their loads (they overlap),
        // then the block's triangles in order.
        let mut lowers = [0f32; SCAN_BLOCK];
        for block in list.chunks(SCAN_BLOCK) {
            for (lower, &t) in lowers.iter_mut().zip(block) {
                *lower = g.planes[t as usize].distance_squared_bound(x32, g.margin);
            }
            for (&t, &lower) in block.iter().zip(&lowers) {
                if t == hint {
                    continue;
                }
                // Cheap reject: the plane and edge lines are no farther than the triangle.
                let lower = f64::from(lower);
                if lower >= bound {
                    note(t, lower);
                    second = second.min(lower);
                    continue;
                }
                let [a, b, c] = g.corners(t as usize);
                let q = closest_on_triangle(xl, a, b, c);
                let d2 = (xl - q.point).length_squared();
                note(t, d2);
                if d2 < bound {
                    if best.is_some() {
                        second = second.min(bound);
                    }
                    bound = d2;
                    best = Some((d2, t as usize, q));
                } else {
                    second = second.min(d2);
                }
            }
        }
        Scan {
            best,
            second,
            near,
            n_near,
            others,
            least: least.1,
        }
    }

    /// The contact at the scan's nearest triangle (`d2`, `t`, `q`): signed on a closed mesh.
    /// On an open surface a particle on it goes back to the side its path came from, and
    /// the particle is held to one side, `keep` (+1 in front of the faces' normals, −1
    /// behind): the one its path came from where the sweep stopped it, else the one it was
    /// clearly on at its first contact of the projection (set here). Found clearly on the
    /// other side (a push out of one face beside a sharp fold can carry it through the face
    /// across the fold), it is pushed back through the surface, as from inside a closed mesh.
    pub(super) fn contact(
        &self,
        (d2, t, q): (f64, usize, Closest),
        xl: DVec3,
        from: DVec3,
        keep: &mut Option<f64>,
    ) -> MeshPoint {
        let g = self.geometry;
        let (mut p, pn) = g.signed_with_normal(xl, t, q, d2);
        if g.closed() {
            return p;
        }
        if d2 <= 1e-24 {
            let n = g.normals[t];
            p.normal = if n.dot(from - q.point) < 0.0 { -n } else { n };
        }
        // Clearly on a side: within 60° of the feature's pseudo-normal or its opposite (not
        // level with a boundary edge, where either side is as near).
        let along = p.normal.dot(pn.normalize_or_zero());
        let on = if along >= SIDED {
            1.0
        } else if along <= -SIDED {
            -1.0
        } else {
            return p;
        };
        match *keep {
            None => *keep = Some(on),
            Some(side) if side != on => {
                p.distance = -p.distance;
                p.normal = -p.normal;
            }
            Some(_) => {}
        }
        p
    }

    /// Pushes the particle (local `xl`, world `x`) out to distance r along `hit`'s normal,
    /// then slides it back by Coulomb friction against the surface's motion; returns the
    /// depth and the slip, or `None` if it was within rounding of r already.
    pub(super) fn push(
        &self,
        hit: &MeshPoint,
        xl: &mut DVec3,
        x: &mut DVec3,
        prev: DVec3,
        r: f64,
    ) -> Option<(f64, f64)> {
        let depth = r - hit.distance;
        if depth <= 1e-6 * r.max(1e-3) {
            return None;
        }
        // From outside, a push along the closest direction leaves the (convex) triangle at
        // distance r, and a slip across that direction keeps it there.
        self.move_to(xl, x, *xl + hit.normal * depth);
        // Relative tangential displacement over the substep against the surface's own
        // motion there (Macklin et al. 2014, eq. 24).
        let n = self.to_world_vector(hit.normal);
        let rel = (*x - prev) - self.surface_displacement(hit.triangle, hit.closest.bary);
        let tangential = rel - n * n.dot(rel);
        let correction = self.friction.correction(tangential, depth);
        if correction == DVec3::ZERO {
            return Some((depth, 0.0));
        }
        // A tangential move of |correction| ≤ the slip: distances drop by at most it.
        *x -= correction;
        *xl = self.to_local(self.pose, *x);
        Some((depth, correction.length()))
    }

    /// Whether a contact round must follow a push from `hit` by `depth`, then a slip of
    /// `slip`, that moved the particle from `scanned_at` to `xl`. Pushed from inside (or from
    /// on the surface), yes: the triangle left may still be within r. Otherwise only if the
    /// scan's runner-up may now be within r, and, where the scanned candidates still hold
    /// every triangle within r of `xl` (`listed`) and the others not followed are out of
    /// reach, only if a followed triangle other than the one left is within r.
    pub(super) fn look_again(
        &self,
        scan: &Scan,
        hit: &MeshPoint,
        (depth, slip): (f64, f64),
        (scanned_at, xl): (DVec3, DVec3),
        r: f64,
        listed: impl FnOnce() -> bool,
    ) -> bool {
        let along = scan.along_closest(hit);
        let again = !along || scan.second.sqrt() - depth - slip < r;
        if !(again && along) {
            return again;
        }
        let moved = (xl - scanned_at).length();
        if scan.others.sqrt() - moved >= r && listed() {
            self.may_touch_again(scan, hit.triangle, xl, moved, r)
        } else {
            again
        }
    }

    /// Whether a followed triangle other than `left` may be within r of `xl`, the particle
    /// having moved `moved` since the scan: a bound at the scan less the move, then a bound
    /// here, then the distance.
    pub(super) fn may_touch_again(
        &self,
        scan: &Scan,
        left: usize,
        xl: DVec3,
        moved: f64,
        r: f64,
    ) -> bool {
        let g = self.geometry;
        let x32 = xl.as_vec3();
        scan.near[..scan.n_near].iter().any(|&(t, was)| {
            let t = t as usize;
            t != left
                && was.sqrt() - moved < r
                && g.closest_within(t, xl, (x32, g.margin), r * r)
                    .is_some_and(|(d2, _)| d2 < r * r)
        })
    }
}

/// What one scan of a particle's candidates found.
pub(super) struct Scan {
    /// The nearest triangle within r: squared distance, triangle, closest point.
    pub(super) best: Option<(f64, usize, Closest)>,
    /// The least lower bound on the others' squared distances.
    pub(super) second: f64,
    /// The triangles within 2r (bound or distance) with that squared value, to follow
    /// after a push.
    pub(super) near: [(u32, f64); NEAR],
    /// Entries of `near` in use.
    pub(super) n_near: usize,
    /// The least squared bound of the triangles not followed (0 if too many to follow).
    pub(super) others: f64,
    /// The triangle of least bound or distance (`u32::MAX` if none was scanned).
    pub(super) least: u32,
}

impl Scan {
    /// Whether `hit` came from outside, along the closest direction (then the triangle left
    /// stays at distance r after the push).
    pub(super) fn along_closest(&self, hit: &MeshPoint) -> bool {
        self.best.is_some_and(|b| b.0 > 1e-24) && hit.distance > 0.0
    }
}
