//! Triangle meshes for mesh colliders, and the checks that make them safe to collide with.

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

use crate::error::MeshError;

/// A validated triangle soup: finite vertices, in-range indices, no degenerate triangle,
/// no edge shared by more than two triangles. Vertices are f64; they are checked, and
/// collided with, as the f32 that parry holds ([`TriangleMesh::vertices_f32`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions (m).
    pub vertices: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from outside (the side particles are pushed to).
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Validates a mesh built in memory (errors name `<memory>` and line 0).
    pub fn new(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        let lines = vec![0; triangles.len()];
        let rounded: Vec<Vec3> = vertices.iter().map(|v| v.as_vec3()).collect();
        validate(Path::new("<memory>"), &rounded, &triangles, &lines, &[])?;
        Ok(Self {
            vertices,
            triangles,
        })
    }

    /// The vertices rounded to f32, as parry holds them.
    pub fn vertices_f32(&self) -> Vec<Vec3> {
        self.vertices.iter().map(|v| v.as_vec3()).collect()
    }

    /// Axis-aligned bounds `(min, max)` of the vertices.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.vertices
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(*v), hi.max(*v))
            })
    }

    /// A sphere of `radius` about the origin as a closed mesh: the icosahedron with each
    /// triangle split in four `subdivisions` times (20 · 4^k triangles), vertices projected
    /// onto the sphere. Its largest distance from the sphere, between vertices, is below
    /// `radius` · (1 − cos θ) with θ the largest edge's angle.
    pub fn icosphere(radius: f64, subdivisions: u32) -> Self {
        let t = (1.0 + 5f64.sqrt()) / 2.0;
        let mut vertices: Vec<glam::DVec3> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| glam::DVec3::new(x, y, z).normalize())
        .collect();
        let mut triangles: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions {
            let mut middle = rustc_hash::FxHashMap::default();
            let mut split = |a: u32, b: u32, vertices: &mut Vec<glam::DVec3>| {
                *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let m = (vertices[a as usize] + vertices[b as usize]).normalize();
                    vertices.push(m);
                    (vertices.len() - 1) as u32
                })
            };
            let mut next = Vec::with_capacity(4 * triangles.len());
            for [a, b, c] in triangles {
                let ab = split(a, b, &mut vertices);
                let bc = split(b, c, &mut vertices);
                let ca = split(c, a, &mut vertices);
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            triangles = next;
        }
        Self {
            vertices: vertices.iter().map(|v| *v * radius).collect(),
            triangles,
        }
    }

    /// A copy scaled by `scale` about the origin, then moved by `offset`.
    pub fn transformed(&self, scale: f64, offset: DVec3) -> Self {
        Self {
            vertices: self.vertices.iter().map(|v| *v * scale + offset).collect(),
            triangles: self.triangles.clone(),
        }
    }
}

/// Checks a mesh; `lines[t]` is the source line of triangle `t`, `vertex_lines[v]` that of
/// vertex `v` (either may be shorter, then 0 is reported).
pub(crate) fn validate(
    path: &Path,
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    lines: &[usize],
    vertex_lines: &[usize],
) -> Result<(), MeshError> {
    let path_buf = || PathBuf::from(path);
    let line_of = |t: usize| lines.get(t).copied().unwrap_or(0);
    if triangles.is_empty() {
        return Err(MeshError::Empty { path: path_buf() });
    }
    if let Some(v) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(MeshError::NonFiniteVertex {
            path: path_buf(),
            line: vertex_lines.get(v).copied().unwrap_or(0),
            vertex: v,
        });
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(MeshError::IndexOutOfRange {
                path: path_buf(),
                line: line_of(t),
                index: i64::from(i),
                vertices: vertices.len(),
            });
        }
        let [a, b, c] = tri.map(|i| vertices[i as usize]);
        let twice_area = (b - a).cross(c - a).length();
        let longest = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared());
        // Relative test: a sliver whose area is tiny against its longest edge is as bad as a
        // repeated vertex for the normal and the BVH.
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || twice_area <= 1e-7 * longest
        {
            return Err(MeshError::DegenerateTriangle {
                path: path_buf(),
                line: line_of(t),
                triangle: t,
            });
        }
    }
    // Non-manifold edges: sort (edge, triangle) so that the report is deterministic.
    let mut edges: Vec<(u32, u32, usize)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (a.min(b), a.max(b), t)
            })
        })
        .collect();
    edges.sort_unstable();
    for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if run.len() > 2 {
            return Err(MeshError::NonManifoldEdge {
                path: path_buf(),
                line: line_of(run[2].2),
                a: run[0].0,
                b: run[0].1,
            });
        }
    }
    Ok(())
}
