//! CPU-side geometry: per-frame cloth normals, collider meshes split at sharp edges, cloth
//! edges for the wireframe, and bounds.

use glam::{DVec3, Mat4, Vec3};

use crate::scene::TriMesh;

/// Angle above which two collider faces meeting at a vertex are not smoothed together (a
/// cuboid's corners stay sharp, a sphere's facets blend).
const CREASE_COS: f32 = 0.766; // cos 40°

/// Area-weighted vertex normals: each vertex gets the normalised sum of the (unnormalised)
/// cross products of its triangles, i.e. face normals weighted by twice their area
/// (Gouraud's average with area weights; see Max, "Weights for computing vertex normals
/// from facet normals", JGT 1999). Indices out of range are ignored.
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(positions.len(), Vec3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let (Some(&pa), Some(&pb), Some(&pc)) =
            (positions.get(a), positions.get(b), positions.get(c))
        else {
            continue;
        };
        let n = (pb - pa).cross(pc - pa);
        out[a] += n;
        out[b] += n;
        out[c] += n;
    }
    for n in out.iter_mut() {
        *n = n.normalize_or(Vec3::Y);
    }
}

/// Planar texture coordinates: positions projected on the two axes along which they extend
/// most, scaled so the longer side spans 0..1 (a grid cloth at rest gets its grid's UVs).
pub fn planar_uvs(positions: &[Vec3]) -> Vec<[f32; 2]> {
    let mut b = Bounds::default();
    positions.iter().for_each(|&p| b.add(p));
    if b.is_empty() {
        return vec![[0.0, 0.0]; positions.len()];
    }
    let size = b.max - b.min;
    // The two largest extents, in axis order.
    let drop = if size.x <= size.y && size.x <= size.z {
        0
    } else if size.y <= size.z {
        1
    } else {
        2
    };
    let (a, c) = match drop {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let scale = 1.0 / size[a].max(size[c]).max(1e-6);
    positions
        .iter()
        .map(|p| [(p[a] - b.min[a]) * scale, (p[c] - b.min[c]) * scale])
        .collect()
}

/// f64 solver positions as f32 render positions.
pub fn to_f32(src: &[DVec3], out: &mut Vec<Vec3>) {
    out.clear();
    out.extend(src.iter().map(|p| p.as_vec3()));
}

/// A collider mesh with one vertex per triangle corner, each with a normal averaged over the
/// faces around its vertex that meet it at less than 40° (smooth curves, sharp creases).
#[derive(Clone, Debug, Default)]
pub struct SplitMesh {
    /// Local positions, three per triangle.
    pub positions: Vec<Vec3>,
    /// Local normals, three per triangle.
    pub normals: Vec<Vec3>,
}

impl SplitMesh {
    /// Splits `mesh` (invalid triangles are dropped).
    pub fn new(mesh: &TriMesh) -> Self {
        let n = mesh.positions.len();
        let tris: Vec<[usize; 3]> = mesh
            .indices
            .iter()
            .map(|t| t.map(|i| i as usize))
            .filter(|t| t.iter().all(|&i| i < n))
            .collect();
        let face: Vec<Vec3> = tris
            .iter()
            .map(|&[a, b, c]| {
                let p = &mesh.positions;
                (p[b] - p[a]).cross(p[c] - p[a])
            })
            .collect();
        // Triangles around each vertex (CSR).
        let mut start = vec![0usize; n + 1];
        for t in &tris {
            for &i in t {
                start[i + 1] += 1;
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut around = vec![0usize; start[n]];
        for (f, t) in tris.iter().enumerate() {
            for &i in t {
                around[fill[i]] = f;
                fill[i] += 1;
            }
        }
        let mut out = Self::default();
        for (f, t) in tris.iter().enumerate() {
            let nf = face[f].normalize_or_zero();
            for &i in t {
                let mut sum = Vec3::ZERO;
                for &g in &around[start[i]..start[i + 1]] {
                    if face[g].normalize_or_zero().dot(nf) >= CREASE_COS {
                        sum += face[g];
                    }
                }
                out.positions.push(mesh.positions[i]);
                out.normals.push(sum.normalize_or(nf.normalize_or(Vec3::Y)));
            }
        }
        out
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.positions.len()
    }
}

/// Each undirected edge of `triangles` once.
pub fn unique_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// An axis-aligned box, empty until a point is added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Bounds {
    fn default() -> Self {
        Self {
            min: Vec3::splat(f32::INFINITY),
            max: Vec3::splat(f32::NEG_INFINITY),
        }
    }
}

impl Bounds {
    /// Grows the box to hold `p` (non-finite points are ignored).
    pub fn add(&mut self, p: Vec3) {
        if p.is_finite() {
            self.min = self.min.min(p);
            self.max = self.max.max(p);
        }
    }

    /// Whether no point was added.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// The box grown to hold `other`.
    pub fn union(self, other: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The part of the box inside `clip`.
    pub fn intersect(self, clip: Bounds) -> Bounds {
        Bounds {
            min: self.min.max(clip.min),
            max: self.max.min(clip.max),
        }
    }

    /// Centre and half the diagonal.
    pub fn sphere(&self) -> (Vec3, f32) {
        (
            0.5 * (self.min + self.max),
            0.5 * (self.max - self.min).length(),
        )
    }
}

/// Bounds of `positions` transformed by `pose`.
pub fn transformed_bounds(positions: &[Vec3], pose: &Mat4) -> Bounds {
    let mut b = Bounds::default();
    for p in positions {
        b.add(pose.transform_point3(*p));
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_square_normals_follow_the_winding() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let mut n = Vec::new();
        vertex_normals(&p, &[[0, 1, 2], [0, 2, 3]], &mut n);
        assert!(n.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
        vertex_normals(&p, &[[0, 2, 1], [0, 3, 2]], &mut n);
        assert!(n.iter().all(|n| (*n + Vec3::Z).length() < 1e-6));
    }

    #[test]
    fn folded_strip_normal_bisects_the_fold() {
        // Two unit squares at a right angle along the x axis. Each shared vertex touches two
        // equal-area triangles on one side and one on the other, so its normal is
        // (2 n₁ + n₂) / |…|.
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
        ];
        let tris = [[0, 1, 2], [0, 2, 3], [5, 4, 1], [5, 1, 0]];
        let mut n = Vec::new();
        vertex_normals(&p, &tris, &mut n);
        assert!(
            (n[0] - (2.0 * Vec3::Y + Vec3::Z).normalize()).length() < 1e-6,
            "{:?}",
            n[0]
        );
        assert!(
            (n[1] - (Vec3::Y + 2.0 * Vec3::Z).normalize()).length() < 1e-6,
            "{:?}",
            n[1]
        );
        assert!((n[2] - Vec3::Y).length() < 1e-6);
        assert!((n[4] - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn split_mesh_keeps_cube_corners_sharp() {
        // A unit cube: every split normal is an axis.
        let p: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let indices: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        let s = SplitMesh::new(&TriMesh {
            positions: p,
            indices,
        });
        assert_eq!(s.len(), 36);
        for n in &s.normals {
            assert!((n.abs().max_element() - 1.0).abs() < 1e-6, "{n:?}");
        }
    }

    #[test]
    fn planar_uvs_of_a_vertical_rectangle() {
        // 2 m wide (x), 1 m tall (y), at z = 3: u along x, v along y, longer side 0..1.
        let p = [
            Vec3::new(-1.0, 0.0, 3.0),
            Vec3::new(1.0, 0.0, 3.0),
            Vec3::new(1.0, 1.0, 3.0),
            Vec3::new(0.0, 0.5, 3.0),
        ];
        assert_eq!(
            planar_uvs(&p),
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 0.5], [0.5, 0.25]]
        );
    }

    #[test]
    fn edges_of_two_triangles() {
        let e = unique_edges(&[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(e, vec![[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]);
    }
}
