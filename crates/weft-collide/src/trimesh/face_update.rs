//! A moving mesh's faces (corners and unit normal) worked out anew at every substep, and their
//! bounding planes at every frame's end, a block of faces at a time in explicit vectors: the
//! same IEEE operations in the same order as [`Face::at`] and [`Planes::new`] (glam's cross
//! product and `normalize_or_zero`), so the same bits, on every kernel path.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::Simd;
use rayon::prelude::*;
use weft_solver::SimdPath;
use weft_solver::lane_ops::{LaneKernel, Ops, V3, load, on_path, store};

use super::{Face, Planes};

/// Faces a parallel task works out.
const PART: usize = 1024;

/// Sets `faces[i]` to triangle `triangles[i]`'s face at the vertices `end`, as [`Face::at`].
pub(crate) fn update_faces(faces: &mut [Face], triangles: &[[u32; 3]], end: &[DVec3]) {
    let path = SimdPath::resolve(None);
    (faces.par_chunks_mut(PART).zip(triangles.par_chunks(PART))).for_each(|(faces, triangles)| {
        on_path(
            path,
            Part {
                faces,
                triangles,
                end,
            },
        );
    });
}

/// Sets `planes[i]` to triangle `triangles[i]`'s planes at the vertices `end`, as
/// [`Planes::new`] with [`super::normals::face_normal`].
pub(crate) fn update_planes(planes: &mut [Planes], triangles: &[[u32; 3]], end: &[DVec3]) {
    let path = SimdPath::resolve(None);
    (planes.par_chunks_mut(PART).zip(triangles.par_chunks(PART))).for_each(
        |(planes, triangles)| {
            on_path(
                path,
                PlanesPart {
                    planes,
                    triangles,
                    end,
                },
            );
        },
    );
}

/// One task's planes, as a [`LaneKernel`].
struct PlanesPart<'a> {
    planes: &'a mut [Planes],
    triangles: &'a [[u32; 3]],
    end: &'a [DVec3],
}

impl LaneKernel for PlanesPart<'_> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        let PlanesPart {
            planes,
            triangles,
            end,
        } = self;
        let o = Ops(s);
        let full = planes.len() - planes.len() % L;
        for f in (0..full).step_by(L) {
            let tri: &[[u32; 3]; L] = match triangles[f..f + L].first_chunk::<L>() {
                Some(t) => t,
                None => continue,
            };
            let corners = gather::<L>(tri, end);
            let v = |c: usize| -> V3<S> {
                [
                    load::<S, L>(corners[c][0]),
                    load::<S, L>(corners[c][1]),
                    load::<S, L>(corners[c][2]),
                ]
            };
            let (a, b, c) = (v(0), v(1), v(2));
            let n = unit(o, o.cross(&o.dif(&b, &a), &o.dif(&c, &a)));
            // Each plane's unit normal and offset (n · point), per lane: the face's, then
            // edge k's in-plane outward normal (corners k, k + 1) through corner k.
            let ends = [(&b, &a), (&c, &b), (&a, &c)];
            let at = [&a, &a, &b, &c];
            let mut rows = [[[0.0; L]; 4]; 4];
            for k in 0..4 {
                let normal = if k == 0 {
                    n
                } else {
                    let (to, from) = ends[k - 1];
                    unit(o, o.cross(&o.dif(to, from), &n))
                };
                for i in 0..3 {
                    rows[k][i] = store::<S, L>(normal[i]);
                }
                rows[k][3] = store::<S, L>(o.dot(&normal, at[k]));
            }
            for l in 0..L {
                let p = &mut planes[f + l].0;
                for k in 0..4 {
                    for i in 0..4 {
                        p[4 * k + i] = rows[k][i][l] as f32;
                    }
                }
            }
        }
        for (p, t) in planes[full..].iter_mut().zip(&triangles[full..]) {
            let [a, b, c] = t.map(|i| end[i as usize]);
            *p = Planes::new([a, b, c], super::normals::face_normal(a, b, c));
        }
    }
}

/// The corners of the `L` triangles `tri` at the vertices `end`, per corner, axis and lane.
#[inline(always)]
fn gather<const L: usize>(tri: &[[u32; 3]; L], end: &[DVec3]) -> [[[f64; L]; 3]; 3] {
    let mut corners = [[[0.0; L]; 3]; 3];
    for l in 0..L {
        for c in 0..3 {
            let p = end[tri[l][c] as usize];
            for k in 0..3 {
                corners[c][k][l] = p[k];
            }
        }
    }
    corners
}

/// `m` / |m| per lane, or zero where that is not finite (glam's `normalize_or_zero`).
#[inline(always)]
fn unit<S: Simd>(o: Ops<S>, m: V3<S>) -> V3<S> {
    let rcp = o.div(o.c(1.0), o.sqrt(o.dot(&m, &m)));
    let ok = o.and(o.lt(rcp, o.c(f64::INFINITY)), o.gt(rcp, o.c(0.0)));
    let mut n = m;
    for k in 0..3 {
        n[k] = o.sel(ok, o.mul(m[k], rcp), o.c(0.0));
    }
    n
}

/// One task's faces, as a [`LaneKernel`].
struct Part<'a> {
    faces: &'a mut [Face],
    triangles: &'a [[u32; 3]],
    end: &'a [DVec3],
}

impl LaneKernel for Part<'_> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        let Part {
            faces,
            triangles,
            end,
        } = self;
        let o = Ops(s);
        let full = faces.len() - faces.len() % L;
        for f in (0..full).step_by(L) {
            let tri: &[[u32; 3]; L] = match triangles[f..f + L].first_chunk::<L>() {
                Some(t) => t,
                None => continue,
            };
            let corners = gather::<L>(tri, end);
            let normal = normals::<S, L>(o, &corners);
            for l in 0..L {
                let face = &mut faces[f + l];
                for c in 0..3 {
                    face.corners[c] =
                        DVec3::new(corners[c][0][l], corners[c][1][l], corners[c][2][l]);
                }
                face.normal = DVec3::new(normal[0][l], normal[1][l], normal[2][l]);
            }
        }
        for (face, t) in faces[full..].iter_mut().zip(&triangles[full..]) {
            *face = Face::at(t.map(|i| end[i as usize]));
        }
    }
}

/// Each lane's unit normal (b − a) × (c − a) / |…| from its corners a, b, c per axis, or zero
/// where that is not finite, as glam's `normalize_or_zero` gives it.
#[inline(always)]
fn normals<S: Simd, const L: usize>(o: Ops<S>, corners: &[[[f64; L]; 3]; 3]) -> [[f64; L]; 3] {
    let v = |c: usize| -> V3<S> {
        [
            load::<S, L>(corners[c][0]),
            load::<S, L>(corners[c][1]),
            load::<S, L>(corners[c][2]),
        ]
    };
    let (a, b, c) = (v(0), v(1), v(2));
    let m = unit(o, o.cross(&o.dif(&b, &a), &o.dif(&c, &a)));
    [
        store::<S, L>(m[0]),
        store::<S, L>(m[1]),
        store::<S, L>(m[2]),
    ]
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::{update_faces, update_planes};
    use crate::analytic_vs_parry::Rng;
    use crate::trimesh::normals::face_normal;
    use crate::trimesh::{Face, Planes};

    /// The block updates give every face and its planes the bits `Face::at` and `Planes::new`
    /// give them, degenerate faces (zero normal) and a run's last faces (past the last full
    /// block) included.
    #[test]
    fn faces_and_planes_match_the_one_face_forms_bit_for_bit() {
        let mut rng = Rng(5);
        let mut vertices: Vec<DVec3> = (0..300).map(|_| rng.cube(2.0)).collect();
        vertices[7] = vertices[3]; // a degenerate triangle below
        let mut triangles: Vec<[u32; 3]> = (0..2051)
            .map(|_| [0, 1, 2].map(|_| (rng.next() * 300.0) as u32 % 300))
            .collect();
        triangles[11] = [3, 7, 9];
        let mut faces = vec![Face::at([DVec3::ZERO; 3]); triangles.len()];
        update_faces(&mut faces, &triangles, &vertices);
        for (f, t) in faces.iter().zip(&triangles) {
            let want = Face::at(t.map(|i| vertices[i as usize]));
            assert_eq!(f.corners, want.corners);
            assert_eq!(
                f.normal.to_array().map(f64::to_bits),
                want.normal.to_array().map(f64::to_bits)
            );
        }
        assert_eq!(faces[11].normal, DVec3::ZERO);
        let mut planes = vec![Planes::default(); triangles.len()];
        update_planes(&mut planes, &triangles, &vertices);
        for (p, t) in planes.iter().zip(&triangles) {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let want = Planes::new([a, b, c], face_normal(a, b, c));
            assert_eq!(p.0.map(f32::to_bits), want.0.map(f32::to_bits));
        }
    }
}
