//! Contacts over a convex edge of a certificate's face, settled without the ring's search:
//! the particles the certified block test (`certified`) leaves to the ring because they
//! project onto neither face of an edge (about 1,450 a frame on the breathing ball).
//!
//! Let F be a particle's certificate face, e = (p, q) the edge of F it projects beyond, and G
//! the face across e, wound as F (G runs e from q to p, as on every edge of a closed mesh),
//! both with usable front lists (`convexity`):
//! every triangle of F's ring but its front ones lies behind F's plane throughout the frame,
//! and every triangle of G's ring but its front ones behind G's plane. The triangles about p
//! or q are in both rings (as are F and G), so all but the front ones lie in the wedge K
//! behind both planes. Where x lies in front of both planes, beyond e within F's plane and
//! beyond e within G's, x − x_L (x_L its projection onto e's line L) lies in the cone of the
//! two normals, which is K's normal cone along L: the point of K nearest x is x_L, and each
//! triangle in K is at least |x − x_L| away. (Across a concave edge no point lies in front of
//! both planes and beyond e in both: the four conditions leave no room.) Where x_L lies within e, that is e's distance d,
//! F's and G's. The front triangles of both and the rest of F's ring (the triangles about its
//! third corner alone) are checked by the planes' bound, else the distance; the rest of G's
//! ring is off F's ring, which the certificate puts at least r away. So e is nearest of all,
//! as `MeshFrame::resolve_ring` finds it, and the particle is pushed to r along x − x_L with
//! friction by the same `MeshFrame::push`. It then lies √(r² + s²) from L (s its slip, across
//! the push); if it is still in the wedge over e, those checked triangles are clear of r, and
//! it is within its certificate's reach, nothing is within r (the ring's next round would
//! find nothing), and it is done. Anything else (a vertex region, a checked triangle too
//! near, a slip out of the wedge, a push beyond the reach) leaves the particle as it was, to
//! the ring.

use glam::DVec3;

use super::MeshPoint;
use super::closest::{Closest, Feature};
use super::convexity::UNUSABLE;
use super::frame::{MeshFrame, Outcome, RunParticle};
use super::normals::NONE;

/// How far inside the wedge's sides, and within the edge's ends (as fractions of the face's
/// and the edge's size), a particle must lie for its edge to settle it: nearer, the ring
/// decides (as the block test's `INSIDE`).
const MARGIN: f64 = 1e-9;

#[cfg(test)]
thread_local! {
    /// Particles an edge settled on this thread (tests only).
    pub(crate) static EDGES: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// A particle over a convex edge of its face (see the module's notes).
struct OverEdge {
    /// The edge: corners k and k + 1 of the face.
    k: usize,
    /// The face across it.
    other: usize,
    /// The edge's point nearest the particle, its weights of the face's corners, and the
    /// particle less that point.
    point: DVec3,
    bary: [f64; 3],
    delta: DVec3,
}

impl MeshFrame<'_> {
    /// Settles particle `j` (previous position `prev`, at `x`, thickness `r`), whose
    /// certificate holds with a face on a short path and which the block test left to the
    /// ring, by the edge of its face it lies over (see the module's notes), as
    /// [`MeshFrame::resolve_ring`] would; `None`, with `x` as it was, where it cannot.
    pub(crate) fn edge_contact(&self, p: RunParticle<'_>) -> Option<Outcome> {
        let RunParticle {
            lists,
            j,
            prev,
            x,
            r,
        } = p;
        let g = self.geometry;
        let f = lists.certs.face[j] as usize;
        if f >= g.face_count() || g.fronts.count[f] == UNUSABLE {
            return None;
        }
        let (mut xl, _) = self.local_path(*x, prev, || lists.last[j]);
        let over = self.over_edge(f, xl, None)?;
        let d2 = over.delta.length_squared();
        let d = d2.sqrt();
        if d <= 1e-12 || !self.others_clear(f, &over, xl, d2) {
            return None;
        }
        let start = *x;
        let mut out = Outcome::default();
        let mut hint = lists.hint[j];
        if d2 < r * r {
            let hit = MeshPoint {
                triangle: f,
                closest: Closest {
                    point: over.point,
                    bary: over.bary,
                    feature: Feature::Edge(over.k as u8),
                },
                distance: d,
                normal: over.delta / d,
            };
            hint = f as u32;
            if let Some((depth, _)) = self.push(&hit, &mut xl, x, prev, r) {
                out.contacts = 1;
                out.depth = depth;
                // Still over the same edge, the checked triangles clear of r.
                let still = self.over_edge(f, xl, Some(over.k)).is_some_and(|o| {
                    o.delta.length_squared() >= r * r * (1.0 - 1e-9)
                        && self.others_clear(f, &o, xl, r * r)
                });
                if !still {
                    *x = start;
                    return None;
                }
            }
        }
        // Within the certificate's reach where it ends.
        if !lists.certs.covers(j, xl, (r, g.travel)) {
            *x = start;
            return None;
        }
        #[cfg(test)]
        EDGES.with(|e| e.set(e.get() + 1));
        lists.hint[j] = hint;
        lists.last[j] = xl;
        Some(out)
    }

    /// Where `x` lies over a convex edge of face `f` (edge `only`, if given) with a
    /// neighbour across it, wound as `f`, whose front list is usable, well inside the wedge
    /// of the two faces' normals and within the edge's ends; `None` elsewhere.
    fn over_edge(&self, f: usize, x: DVec3, only: Option<usize>) -> Option<OverEdge> {
        let g = self.geometry;
        let face = g.face(f);
        let [a, b, c] = face.corners;
        // With e₁ = b − a, e₂ = c − a, m = e₁ × e₂ and w = x − a, the projection of x is
        // a + β e₁ + γ e₂ with β |m|² = (w × e₂) · m and γ |m|² = (e₁ × w) · m.
        let (e1, e2) = (b - a, c - a);
        let m = e1.cross(e2);
        let m2 = m.dot(m);
        let w = x - a;
        let bm = w.cross(e2).dot(m);
        let gm = e1.cross(w).dot(m);
        let am = m2 - bm - gm;
        let lim = MARGIN * m2;
        // Beyond exactly one edge: the one opposite the corner whose weight is negative.
        let k = match (am < -lim, bm < -lim, gm < -lim) {
            (false, false, true) if am > lim && bm > lim => 0,
            (true, false, false) if bm > lim && gm > lim => 1,
            (false, true, false) if am > lim && gm > lim => 2,
            _ => return None,
        };
        if only.is_some_and(|o| o != k) {
            return None;
        }
        let other = g.topology.adjacent[f][k];
        if other == NONE || g.fronts.count[other as usize] == UNUSABLE {
            return None;
        }
        // Wound as f: it runs the edge the other way (every edge of a closed mesh does).
        if !g.closed() {
            let (vp, vq) = (g.triangles[f][k], g.triangles[f][(k + 1) % 3]);
            let across = g.triangles[other as usize];
            if !(0..3).any(|i| across[i] == vq && across[(i + 1) % 3] == vp) {
                return None;
            }
        }
        let (p, q) = (face.corners[k], face.corners[(k + 1) % 3]);
        let u = q - p;
        let uu = u.dot(u);
        let t = (x - p).dot(u) / uu;
        let ng = g.normals[other as usize];
        let v = x - p;
        // In front of both planes, and beyond e within G's plane (G runs e from q to p, so
        // its outward normal there is (p − q) × n_G).
        let beyond_g = v.dot((p - q).cross(ng));
        let inside = t > MARGIN
            && t < 1.0 - MARGIN
            && face.normal.dot(v) > 0.0
            && ng.dot(v) > 0.0
            && beyond_g > MARGIN * uu;
        if !inside {
            return None;
        }
        let point = p + u * t;
        let mut bary = [0.0; 3];
        bary[k] = 1.0 - t;
        bary[(k + 1) % 3] = t;
        Some(OverEdge {
            k,
            other: other as usize,
            point,
            bary,
            delta: x - point,
        })
    }

    /// Whether every triangle the edge must check (see the module's notes) lies at least
    /// √`d2` from `x`: those of face `f`'s ring about its corner opposite the edge alone
    /// (sharing neither end of it), and the front triangles of `f` and of the face across,
    /// but those two faces.
    fn others_clear(&self, f: usize, over: &OverEdge, x: DVec3, d2: f64) -> bool {
        let g = self.geometry;
        let at = (x.as_vec3(), g.margin_at(x));
        let fronts = [f, over.other].map(|t| {
            let n = usize::from(g.fronts.count[t]);
            &g.fronts.front[t][..n]
        });
        let (third, [of_f, of_other]) = (g.rings.beyond_edge(f, over.k), fronts);
        (third.iter().chain(of_f).chain(of_other))
            .filter(|&&t| t as usize != f && t as usize != over.other)
            .all(|&t| {
                g.closest_within(t as usize, x, at, d2)
                    .is_none_or(|(e2, _)| e2 >= d2)
            })
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use crate::analytic::WorldPose;
    use crate::friction::Friction;
    use crate::trimesh::MeshGeometry;
    use crate::trimesh::chunk_lists::ChunkLists;
    use crate::trimesh::frame::{MeshFrame, RunParticle};

    /// Thickness (m).
    const R: f64 = 0.02;

    /// A ridge along z: face F level (normal +y) to the left of it, face G falling steeply to
    /// the right (normal (3, 1, 0)/√10), and a flap T about F's third corner alone, under F's
    /// plane by `under` and reaching out over G's side. Returns the mesh and F's index.
    fn ridge(under: f64) -> (MeshGeometry, usize) {
        ridge_with(under, None)
    }

    /// [`ridge`], and, where given, a fin from the ridge's end p to the two points `fin`
    /// (in F's and G's rings, in front of F's plane: one of F's front triangles).
    fn ridge_with(under: f64, fin: Option<[DVec3; 2]>) -> (MeshGeometry, usize) {
        let (p, q) = (DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.0, -1.0));
        let (c, d) = (DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, -3.0, 0.0));
        let (s1, s2) = (DVec3::new(0.3, -under, 0.3), DVec3::new(0.3, -under, -0.3));
        let mut vertices = vec![p, q, c, d, s1, s2];
        // F = (p, q, c) runs the ridge from p to q, G = (q, p, d) from q to p; T faces up.
        let mut triangles = vec![[0, 1, 2], [1, 0, 3], [2, 4, 5]];
        if let Some(fin) = fin {
            vertices.extend(fin);
            triangles.push([0, 6, 7]);
        }
        let g = MeshGeometry::new(&vertices, &triangles);
        let f = (g.triangles.iter())
            .position(|t| *t == [0, 1, 2])
            .expect("F stored");
        assert!(g.normals[f].y > 0.999, "F faces up");
        (g, f)
    }

    /// Particle 0 of one-particle lists certified with face `f`, anchored at `x`, every
    /// triangle of the mesh in `f`'s ring (as on the ridge), so any ψ holds.
    fn certified_at(f: usize, x: DVec3) -> ChunkLists {
        let mut lists = ChunkLists::new(1);
        let certs = &mut lists.certs;
        certs.face[0] = f as u32;
        for k in 0..3 {
            certs.anchor[k][0] = x[k];
        }
        certs.reach[0] = 1.0;
        lists
    }

    /// A particle over the ridge, its projection 60° from F's normal (inside the 72° wedge of
    /// the two normals), 0.75 r from it (within r) or 1.2 r (clear of it): with the flap far
    /// below, the ridge is nearest and the edge settles it as `resolve` does (pushed out to
    /// r, or left clear); with the flap nearer than the ridge (just under F's plane, or 0.2 r
    /// under it, within r of the particle clear of the ridge), or farther but within r of
    /// where the push leaves it (0.56 r under F at its end), the edge leaves it, as it is, to the ring,
    /// and `resolve` pushes it off the flap.
    #[test]
    fn an_edge_settles_a_particle_over_it_unless_a_third_corner_triangle_is_nearer() {
        let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
        let angle = 60f64.to_radians();
        let over = |d: f64| DVec3::new(angle.sin(), angle.cos(), 0.1) * d * R;
        for (d, under, settles) in [
            (0.75, 0.5, true),
            (0.75, 1e-4, false),
            (0.75, 0.56 * R, false),
            (1.2, 0.5, true),
            (1.2, 0.2 * R, false),
        ] {
            let (g, f) = ridge(under);
            let frame = MeshFrame::still(&g, &pose, Friction::NONE);
            let x0 = over(d);
            let prev = x0 + DVec3::new(0.0, 0.2 * R, 0.0);
            let (mut x, mut by_resolve) = (x0, x0);
            frame.resolve(RunParticle::new(
                &mut ChunkLists::new(1),
                0,
                prev,
                &mut by_resolve,
                R,
            ));
            let mut lists = certified_at(f, x0);
            let out = frame.edge_contact(RunParticle::new(&mut lists, 0, prev, &mut x, R));
            let case = format!("{d} r over the ridge, the flap {under} m under F");
            assert_eq!(out.is_some(), settles, "{case}");
            if settles {
                let pushed = usize::from(d < 1.0);
                assert_eq!(out.map(|o| o.contacts), Some(pushed), "{case}");
                assert!(
                    (x - by_resolve).length() <= 1e-12,
                    "{case}: {x}, {by_resolve}"
                );
                // Pushed to r (no friction: no slip), or left clear.
                let from_ridge = x.truncate().length();
                assert!((from_ridge - R.max(d * R)).abs() <= 1e-12, "{case}: {x}");
            } else {
                assert_eq!(x, x0, "{case}: left as it was");
                assert!((by_resolve - x0).length() > 1e-3, "{case}: {by_resolve}");
            }
        }
    }

    /// Particles about the ridge's wedge: the edge settles only those inside it, well within
    /// the edge's ends; a particle over F's or G's interior, or beyond an end, is left to the
    /// ring.
    #[test]
    fn an_edge_settles_only_particles_inside_its_wedge() {
        let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
        let (g, f) = ridge(0.5);
        let frame = MeshFrame::still(&g, &pose, Friction::NONE);
        for (degrees, z, settles) in [
            (30.0, 0.0, true),
            (70.0, 0.5, true),
            (-10.0, 0.0, false),
            (80.0, 0.0, false),
            (30.0, 1.2, false),
        ] {
            let a = f64::to_radians(degrees);
            let x0 = DVec3::new(a.sin() * 0.5 * R, a.cos() * 0.5 * R, z);
            let mut x = x0;
            let mut lists = certified_at(f, x0);
            let out = frame.edge_contact(RunParticle::new(&mut lists, 0, x0, &mut x, R));
            assert_eq!(out.is_some(), settles, "{degrees}° at z = {z}");
        }
    }

    /// A fin from the ridge's end down to just above a particle over the ridge, one of F's
    /// front triangles, nearer the particle than the ridge: the edge leaves it to the ring
    /// (and `resolve` pushes it off the fin); with the fin's tip raised out of reach, the
    /// edge settles it as `resolve` does, F's front list notwithstanding.
    #[test]
    fn an_edge_leaves_a_particle_nearer_a_front_triangle_to_the_ring() {
        let pose = WorldPose::new(DVec3::ZERO, DQuat::IDENTITY);
        let angle = 60f64.to_radians();
        let x0 = DVec3::new(angle.sin(), angle.cos(), 0.1) * 0.75 * R;
        for (tip, settles) in [(0.6 * R, false), (5.0 * R, true)] {
            let fin = [-0.01, 0.01].map(|z| DVec3::new(x0.x, x0.y + tip, z));
            let (g, f) = ridge_with(0.5, Some(fin));
            assert!(g.fronts.count[f] > 0, "the fin in front of F");
            let frame = MeshFrame::still(&g, &pose, Friction::NONE);
            let (mut x, mut by_resolve) = (x0, x0);
            frame.resolve(RunParticle::new(
                &mut ChunkLists::new(1),
                0,
                x0,
                &mut by_resolve,
                R,
            ));
            let mut lists = certified_at(f, x0);
            let out = frame.edge_contact(RunParticle::new(&mut lists, 0, x0, &mut x, R));
            assert_eq!(out.is_some(), settles, "fin's tip {tip} above");
            if settles {
                assert!(
                    (x - by_resolve).length() <= 1e-12,
                    "{x} against {by_resolve}"
                );
            } else {
                assert_eq!(x, x0, "left as it was");
                assert!((by_resolve - x0).length() > 1e-3, "{by_resolve}");
            }
        }
    }
}
