//! A moving mesh's faces' unit normals worked out anew at every substep (their corners are
//! the vertices themselves), and their bounding planes at every frame's end, a block of
//! faces at a time in explicit vectors: the same IEEE operations in the same order as
//! [`face_normal`] and [`Planes::new`] (glam's cross product and `normalize_or_zero`), so the
//! same bits, on every kernel path.

// Lane and axis loops index several arrays in step; written as index loops on purpose so
// that each compiles to one vector operation per axis.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use pulp::Simd;
use rayon::prelude::*;
use weft_simd::SimdPath;
use weft_simd::{LaneKernel, Ops, V3, load3, on_path, store, store3};

use super::Planes;
use super::normals::face_normal;

/// Faces a parallel task works out.
const PART: usize = 1024;

/// Sets `normals[i]` to triangle `triangles[i]`'s unit normal at the vertices `end`, as
/// [`face_normal`] (its corners are those vertices: `MeshGeometry::face`).
pub(crate) fn update_normals(normals: &mut [DVec3], triangles: &[[u32; 3]], end: &[DVec3]) {
    update(normals, triangles, end);
}

/// Sets `planes[i]` to triangle `triangles[i]`'s planes at the vertices `end`, as
/// [`Planes::new`] with [`super::normals::face_normal`].
pub(crate) fn update_planes(planes: &mut [Planes], triangles: &[[u32; 3]], end: &[DVec3]) {
    update(planes, triangles, end);
}

/// Sets `out[i]` to what triangle `triangles[i]` gives at the vertices `end`, in parallel
/// parts, each a block of triangles at a time on the CPU's kernel path.
fn update<T: OfCorners>(out: &mut [T], triangles: &[[u32; 3]], end: &[DVec3]) {
    let path = SimdPath::resolve(None);
    (out.par_chunks_mut(PART).zip(triangles.par_chunks(PART))).for_each(|(out, triangles)| {
        on_path(
            path,
            Part {
                out,
                triangles,
                end,
            },
        );
    });
}

/// What a triangle's record is worked out from its corners: a block of triangles at a time in
/// vectors, or one alone, with the same bits.
trait OfCorners: Sized + Send {
    /// Sets `out[l]` from the corners of lane l (`corners`: per corner, axis and lane).
    fn block<S: Simd, const L: usize>(o: Ops<S>, corners: &[[[f64; L]; 3]; 3], out: &mut [Self]);

    /// The record of one triangle with `corners`.
    fn one(corners: [DVec3; 3]) -> Self;
}

impl OfCorners for DVec3 {
    #[inline(always)]
    fn block<S: Simd, const L: usize>(o: Ops<S>, corners: &[[[f64; L]; 3]; 3], out: &mut [Self]) {
        let [a, b, c] = load_corners::<S, L>(corners);
        let normal = store3::<S, L>(&unit_normal(o, [&a, &b, &c]));
        for (l, n) in out.iter_mut().enumerate().take(L) {
            *n = DVec3::new(normal[0][l], normal[1][l], normal[2][l]);
        }
    }

    fn one([a, b, c]: [DVec3; 3]) -> Self {
        face_normal(a, b, c)
    }
}

impl OfCorners for Planes {
    #[inline(always)]
    fn block<S: Simd, const L: usize>(o: Ops<S>, corners: &[[[f64; L]; 3]; 3], out: &mut [Self]) {
        let [a, b, c] = load_corners::<S, L>(corners);
        let n = unit_normal(o, [&a, &b, &c]);
        // Each plane's unit normal and offset (n · point), per lane: the face's, then edge
        // k's in-plane outward normal (corners k, k + 1) through corner k.
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
        for (l, p) in out.iter_mut().enumerate().take(L) {
            for k in 0..4 {
                for i in 0..4 {
                    p.0[4 * k + i] = rows[k][i][l] as f32;
                }
            }
        }
    }

    fn one([a, b, c]: [DVec3; 3]) -> Self {
        Planes::new([a, b, c], super::normals::face_normal(a, b, c))
    }
}

/// One task's triangles, as a [`LaneKernel`].
struct Part<'a, T> {
    out: &'a mut [T],
    triangles: &'a [[u32; 3]],
    end: &'a [DVec3],
}

impl<T: OfCorners> LaneKernel for Part<'_, T> {
    type Output = ();

    #[inline(always)]
    fn run<S: Simd, const L: usize>(self, s: S) {
        let Part {
            out,
            triangles,
            end,
        } = self;
        let o = Ops(s);
        let full = out.len() - out.len() % L;
        for f in (0..full).step_by(L) {
            let tri: &[[u32; 3]; L] = match triangles[f..f + L].first_chunk::<L>() {
                Some(t) => t,
                None => continue,
            };
            T::block::<S, L>(o, &gather::<L>(tri, end), &mut out[f..f + L]);
        }
        for (record, t) in out[full..].iter_mut().zip(&triangles[full..]) {
            *record = T::one(t.map(|i| end[i as usize]));
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

/// The corners per corner, axis and lane as vectors.
#[inline(always)]
fn load_corners<S: Simd, const L: usize>(corners: &[[[f64; L]; 3]; 3]) -> [V3<S>; 3] {
    [
        load3::<S, L>(&corners[0]),
        load3::<S, L>(&corners[1]),
        load3::<S, L>(&corners[2]),
    ]
}

/// Each lane's unit normal (b − a) × (c − a) / |…| from its corners a, b, c, or zero where
/// that is not finite, as glam's `normalize_or_zero` gives it.
#[inline(always)]
fn unit_normal<S: Simd>(o: Ops<S>, [a, b, c]: [&V3<S>; 3]) -> V3<S> {
    unit(o, o.cross(&o.dif(b, a), &o.dif(c, a)))
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

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::{update_normals, update_planes};
    use crate::analytic_vs_parry::Rng;
    use crate::trimesh::Planes;
    use crate::trimesh::normals::face_normal;

    /// The block updates give every face's normal and its planes the bits `face_normal` and
    /// `Planes::new` give them, degenerate faces (zero normal) and a run's last faces (past
    /// the last full block) included.
    #[test]
    fn faces_and_planes_match_the_one_face_forms_bit_for_bit() {
        let mut rng = Rng(5);
        let mut vertices: Vec<DVec3> = (0..300).map(|_| rng.cube(2.0)).collect();
        vertices[7] = vertices[3]; // a degenerate triangle below
        let mut triangles: Vec<[u32; 3]> = (0..2051)
            .map(|_| [0, 1, 2].map(|_| (rng.next() * 300.0) as u32 % 300))
            .collect();
        triangles[11] = [3, 7, 9];
        let mut normals = vec![DVec3::NAN; triangles.len()];
        update_normals(&mut normals, &triangles, &vertices);
        for (n, t) in normals.iter().zip(&triangles) {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let want = face_normal(a, b, c);
            assert_eq!(
                n.to_array().map(f64::to_bits),
                want.to_array().map(f64::to_bits)
            );
        }
        assert_eq!(normals[11], DVec3::ZERO);
        let mut planes = vec![Planes::default(); triangles.len()];
        update_planes(&mut planes, &triangles, &vertices);
        for (p, t) in planes.iter().zip(&triangles) {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let want = Planes::new([a, b, c], face_normal(a, b, c));
            assert_eq!(p.0.map(f32::to_bits), want.0.map(f32::to_bits));
        }
    }
}
