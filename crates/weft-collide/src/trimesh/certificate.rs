//! A particle's certificate against a mesh that keeps candidate lists (a deforming mesh, or a
//! still one too large for a contact grid): what lets the certified test (`certified`) settle
//! most of a resting cloth's particles with the one face under them and no list.
//!
//! A certificate is made by one BVH search about where the particle stood (its anchor): a
//! face F near it and a distance ψ such that every triangle that does not share a corner with
//! F (is off F's ring, `convexity`) lay at least ψ from the anchor; or, where no triangle was
//! within the search's reach, ψ alone (a clear certificate, for a particle outside). Distances
//! move by at most the particle's and the surface's displacements (the surface's bounded by
//! its travel, as a candidate list's skin; Verlet 1967), so while
//!
//! max(|x − anchor|, |from − anchor|) + (travel of the surface since the build) + r ≤ ψ
//!
//! no triangle off F's ring (none at all, for a clear certificate) is within r of the particle
//! or of its path `from → x`. A certificate is made again when it no longer holds, and when
//! the particle comes to rest on another face. One that cannot hold where it is made (a
//! triangle off the ring within r, as in a tight fold), or a particle inside a closed mesh,
//! gets none: the particle goes to the lists until it has moved [`BACKOFF`] r.
//!
//! A particle whose certificate holds with a face, on a short path, that the block test does
//! not settle has its contacts among F and its ring alone ([`MeshFrame::resolve_ring`]).

use glam::DVec3;

use super::MeshGeometry;
use super::bvh::box_distance_squared;
use super::chunk_lists::{CLEAR, ChunkLists, NO_FACE};
use super::closest::{Closest, Feature, closest_on_triangle};
use super::frame::{MeshFrame, Outcome, ROUNDS, RunParticle};

/// How far a certificate's search reaches beyond the particle's thickness r, as a fraction of
/// it (the certificate's skin; 1.0–5.0 were tried on the breathing ball, 2.0–2.5 fastest).
pub(crate) const REACH: f64 = 2.0;

/// How far a clear certificate's search for the nearest triangle reaches, as a multiple of
/// the particle's thickness (50 measured 3 % slower on the breathing ball than 4–8: a far
/// particle's search for its nearest triangle costs more than the builds a longer-lived
/// certificate saves).
const CLEAR_REACH: f64 = 6.0;

/// How far a particle with no certificate moves (a fraction of its thickness, with the
/// surface's travel) before another is tried.
const BACKOFF: f64 = 0.5;

impl MeshFrame<'_> {
    /// Whether certificates are worth keeping for particles of thickness `r` on this mesh:
    /// its fastest vertex does not use up a certificate's skin within a few frames (near a
    /// fast limb they would be made again every frame, and the lists' riding certificates
    /// serve better).
    #[inline]
    pub(crate) fn certifies(&self, r: f64) -> bool {
        4.0 * self.geometry.frame_reach <= REACH * r
    }

    /// How far the surface moved over the path a particle takes in this projection: this
    /// substep's travel on its first projection (the path starts at the substep's start),
    /// none on a later one (as `MeshFrame::short_path` counts it).
    #[inline]
    pub(crate) fn surface_travel(&self) -> f64 {
        let g = self.geometry;
        if self.fresh && g.moving {
            g.travel - g.travel_before
        } else {
            0.0
        }
    }

    /// Makes particle `j`'s certificate at `x` on a path from `from` (the mesh's frame), for
    /// thickness `r` (see the module's notes).
    pub(crate) fn certify(&self, lists: &mut ChunkLists, j: usize, x: DVec3, from: DVec3, r: f64) {
        let g = self.geometry;
        let certs = &mut lists.certs;
        certs.builds += 1;
        let substep = g.travel - g.travel_before;
        let path = (from - x).length();
        let reach = r * (1.0 + REACH) + path + substep;
        let old = (certs.face[j], certs.near[j]);
        match certificate(g, x, (reach, CLEAR_REACH * r), old) {
            // It must hold where it is made: ψ past the path and this substep's travel.
            Some(((psi, face), near)) if psi - substep - r >= path => {
                certs.set(j, x, psi * (1.0 - 1e-12) + g.travel_before, (face, near));
            }
            _ => {
                let reach = g.travel_before + r * (1.0 + BACKOFF);
                certs.set(j, x, reach, (NO_FACE, NO_FACE));
            }
        }
    }

    /// After the ring or the lists resolved particle `j` (now at `x`, the mesh's frame): a
    /// new certificate where the particle has come to rest on another face's interior than
    /// its certificate's (a contact with it, within r of it), or hovers in front of another
    /// face across an edge of its certificate's (over a convex edge, where it projects onto
    /// neither face, it keeps its certificate).
    pub(crate) fn recertify(&self, lists: &mut ChunkLists, j: usize, x: DVec3, r: f64) {
        let (face, hint) = (lists.certs.face[j], lists.hint[j]);
        let g = self.geometry;
        if face >= NO_FACE {
            return;
        }
        let moved = if hint != face && (hint as usize) < g.face_count() {
            let [a, b, c] = g.corners(hint as usize);
            let q = closest_on_triangle(x, a, b, c);
            q.feature == Feature::Face && (x - q.point).length_squared() <= r * r * (1.0 + 1e-6)
        } else {
            !over_face(g, face as usize, x)
                && (g.topology.adjacent[face as usize].iter())
                    .any(|&t| (t as usize) < g.face_count() && over_face(g, t as usize, x))
        };
        if moved {
            self.certify(lists, j, x, x, r);
        }
    }

    /// Particle `j` (previous position `prev`, at `x`, thickness `r`), whose certificate
    /// holds with a face and whose path is short: no triangle off the face's ring is within
    /// r of it or of its path, so its contacts are among the face and its ring, made as
    /// `MeshFrame::resolve` makes them (the nearest within r pushed out, with friction, up
    /// to [`ROUNDS`] times). `None`, with `x` as it was, where the pushes carried it out of
    /// its certificate's reach (the lists follow).
    pub(crate) fn resolve_ring(&self, p: RunParticle<'_>) -> Option<Outcome> {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        let g = self.geometry;
        let face = lists.certs.face[j] as usize;
        let (mut xl, from) = self.local_path(*x, prev, || lists.last[j]);
        let start = *x;
        let ring = g.rings.triangles_of(face);
        let (mut keep, mut out, mut hint) = (None, Outcome::default(), lists.hint[j]);
        let r2 = r * r;
        for _ in 0..ROUNDS {
            // The nearest of the face and its ring within r (the face first: it is kept on a
            // tie), each passed over where its planes' bound clears r.
            let mut best: Option<(f64, usize, Closest)> = None;
            let x32 = xl.as_vec3();
            for t in std::iter::once(face).chain(ring.iter().map(|&t| t as usize)) {
                let Some((d2, q)) = g.closest_within(t, xl, (x32, g.margin), r2) else {
                    continue;
                };
                if d2 < r2 && best.is_none_or(|b| d2 < b.0) {
                    best = Some((d2, t, q));
                }
            }
            let Some(best) = best else { break };
            let hit = self.contact(best, xl, from, &mut keep);
            hint = hit.triangle as u32;
            let Some((depth, _)) = self.push(&hit, &mut xl, x, prev, r) else {
                break;
            };
            out.contacts += 1;
            out.depth = out.depth.max(depth);
        }
        // Still within the certificate's reach where it ends.
        if !lists.certs.covers(j, xl, (r, g.travel)) {
            *x = start;
            return None;
        }
        lists.hint[j] = hint;
        lists.last[j] = xl;
        Some(out)
    }
}

/// Whether `x` lies in front of triangle `t`'s face with its projection inside it.
fn over_face(g: &MeshGeometry, t: usize, x: DVec3) -> bool {
    let f = g.face(t);
    let [a, b, c] = f.corners;
    let q = closest_on_triangle(x, a, b, c);
    q.feature == Feature::Face && f.normal.dot(x - a) > 0.0
}

/// The certificate of a particle at `x` searched out to `reach` (a face's) or `clear` (a
/// particle with no triangle within `reach`): ψ and the face ([`CLEAR`] if none), with the
/// nearest triangle found for a clear one ([`NO_FACE`] if none), or `None` if the particle is
/// inside a closed mesh. `old` is the particle's certificate's face until now and, if that
/// was clear, the nearest triangle it found: unless the face is [`NO_FACE`] the particle was
/// outside, and still is (it cannot cross the surface unseen: a path long enough to is swept
/// by the lists, a shorter one ends within r of the surface, where every contact pushes it
/// out on its side), and a face whose interior it is still over serves again, or else the
/// nearest such face of its ring (any face serves a certificate; the block test decides
/// whether it settles the particle); a clear one's nearest triangle serves as its face did.
fn certificate(
    g: &MeshGeometry,
    x: DVec3,
    (reach, clear): (f64, f64),
    (old, near): (u32, u32),
) -> Option<((f64, u32), u32)> {
    let outside = old != NO_FACE;
    // A clear certificate's nearest triangle, where the particle has most often come in to.
    let old = if old == CLEAR { near } else { old };
    if (old as usize) < g.face_count() {
        // The old face, else the nearest face of its ring whose interior the particle is over
        // (where it has most often gone), saves the search for the nearest triangle.
        let at = (x.as_vec3(), g.margin_at(x));
        let over = |t: usize| {
            g.closest_within(t, x, at, reach * reach)
                .filter(|(d2, q)| q.feature == Feature::Face && *d2 < reach * reach)
                .map(|(d2, _)| (d2, t))
        };
        let ring = g.rings.triangles_of(old as usize).iter();
        let face = over(old as usize).or_else(|| {
            (ring.filter_map(|&t| over(t as usize))).min_by(|a, b| a.0.total_cmp(&b.0))
        });
        if let Some((_, t)) = face {
            return Some(((g.off_ring(x, t, reach), t as u32), NO_FACE));
        }
    }
    let clear = clear.max(reach);
    match g.nearest_unsigned(x, clear) {
        // A particle not known to be outside is signed by its nearest triangle.
        Some((t, d2, q)) if !outside && g.signed(x, t, q, d2).distance < 0.0 => None,
        Some((t, d2, _)) if d2 < reach * reach => {
            Some(((g.off_ring(x, t, reach), t as u32), NO_FACE))
        }
        Some((t, d2, _)) => Some(((d2.sqrt(), CLEAR), t as u32)),
        None => {
            // Nothing within `clear`: outside, unless inside a closed mesh's box (where the
            // side is known, or found by a search for the nearest triangle of all).
            let (lo, hi) = g.bounds();
            let outside_box = box_distance_squared(x, lo, hi).sqrt();
            if outside_box > 0.0 || outside || !g.closed() {
                return Some(((clear.max(outside_box), CLEAR), NO_FACE));
            }
            let p = g.nearest(x, f64::INFINITY)?;
            (p.distance >= 0.0).then_some(((p.distance.max(clear), CLEAR), NO_FACE))
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::{CLEAR, MeshGeometry, NO_FACE, certificate};
    use crate::analytic_vs_parry::Rng;
    use crate::trimesh::closest::closest_on_triangle;
    use crate::trimesh::convexity::share_a_corner;
    use crate::trimesh::vs_parry::{bumpy_sheet, bumpy_sphere};

    /// The distance from `x` to triangle `t`, by its closest point.
    fn distance(g: &MeshGeometry, x: DVec3, t: usize) -> f64 {
        let [a, b, c] = g.corners(t);
        (x - closest_on_triangle(x, a, b, c).point).length()
    }

    /// A certificate holds where it is made: its face lies within the reach, and ψ is no
    /// farther than any triangle off the face's ring (than any triangle, clear of all),
    /// checked against every triangle at points about the bumpy meshes, made from no face
    /// (clear), from the nearest face, and from each face of its ring (which often hands the
    /// certificate to another face of that ring), as a face or as a clear certificate's
    /// nearest triangle (alike); a clear certificate's nearest triangle lies ψ away.
    #[test]
    fn a_certificate_is_no_farther_than_any_triangle_off_its_face_s_ring() {
        for (m, seed) in [(bumpy_sphere(), 7), (bumpy_sheet(), 9)] {
            let g = MeshGeometry::new(&m.vertices, &m.triangles);
            let mut rng = Rng(seed);
            let (mut made, mut handed_on) = (0, 0);
            while made < 2_000 {
                let x = rng.cube(0.7);
                let Some(near) = g.nearest(x, 0.3) else {
                    continue;
                };
                let reach = 0.03 + 0.2 * rng.next();
                let ring = g
                    .rings
                    .triangles_of(near.triangle)
                    .iter()
                    .map(|&t| t as usize);
                for old in std::iter::once(near.triangle).chain(ring) {
                    let old = old as u32;
                    // A clear certificate's triangle serves as a face would, no search.
                    let as_face = certificate(&g, x, (reach, 2.0 * reach), (old, NO_FACE));
                    let as_near = certificate(&g, x, (reach, 2.0 * reach), (CLEAR, old));
                    assert_eq!(as_face, as_near, "{x}: from face {old}");
                    for from in [(old, NO_FACE), (CLEAR, NO_FACE), (CLEAR, old)] {
                        made += 1;
                        let Some(((psi, face), near)) =
                            certificate(&g, x, (reach, 2.0 * reach), from)
                        else {
                            panic!("{x}: called inside though known outside");
                        };
                        if face == CLEAR {
                            for t in 0..g.face_count() {
                                assert!(distance(&g, x, t) >= psi * (1.0 - 1e-12), "{x} {t}");
                            }
                            if near != NO_FACE {
                                let d = distance(&g, x, near as usize);
                                assert!((d - psi).abs() <= 1e-12, "{x}: {near} {d} {psi}");
                            }
                            continue;
                        }
                        let f = face as usize;
                        assert!(psi <= reach && distance(&g, x, f) < reach, "{x}: {f}");
                        handed_on += usize::from(from != (CLEAR, NO_FACE) && face != old);
                        for t in 0..g.face_count() {
                            if !share_a_corner(g.triangles[f], g.triangles[t]) {
                                let d = distance(&g, x, t);
                                assert!(d >= psi * (1.0 - 1e-12), "{x}: {f} {t} {d} < {psi}");
                            }
                        }
                    }
                }
            }
            assert!(
                handed_on > 100,
                "the ring handed on {handed_on} certificates"
            );
        }
    }
}
