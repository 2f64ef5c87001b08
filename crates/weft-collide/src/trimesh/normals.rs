//! A mesh's topology (the neighbour across each edge, the triangles around each vertex,
//! whether it is closed) and its angle-weighted pseudo-normals, which tell inside from outside
//! at any closest point of a closed mesh (Bærentzen & Aanæs 2005, "Signed distance computation
//! using the angle weighted pseudonormal", IEEE TVCG 11(3)).

use glam::DVec3;

use super::closest::Feature;

/// No neighbour across an edge (a boundary edge).
pub(crate) const NONE: u32 = u32::MAX;

/// Adjacency of a triangle mesh.
#[derive(Clone, Debug)]
pub(crate) struct Topology {
    /// Per triangle, the triangle across edge k (corners k, k + 1), or [`NONE`].
    pub adjacent: Vec<[u32; 3]>,
    /// Triangles around vertex v: `ring[ring_start[v]..ring_start[v + 1]]`.
    pub ring_start: Vec<u32>,
    /// The triangles around each vertex, vertex by vertex.
    pub ring: Vec<u32>,
    /// Every edge has two triangles that run it in opposite directions: a consistently
    /// oriented closed surface, whose inside the pseudo-normals can tell.
    pub closed: bool,
}

impl Topology {
    /// The topology of `triangles` over `vertices` vertices (at most two triangles per edge,
    /// as mesh validation ensures).
    pub fn new(vertices: usize, triangles: &[[u32; 3]]) -> Self {
        // Directed edges (from, to, triangle, k), sorted by undirected key.
        let mut edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                edges.push((tri[k], tri[(k + 1) % 3], t as u32, k as u8));
            }
        }
        edges.sort_unstable_by_key(|&(a, b, t, k)| (a.min(b), a.max(b), t, k));
        let mut adjacent = vec![[NONE; 3]; triangles.len()];
        let mut closed = true;
        for run in
            edges.chunk_by(|x, y| (x.0.min(x.1), x.0.max(x.1)) == (y.0.min(y.1), y.0.max(y.1)))
        {
            match run {
                [(a0, b0, t0, k0), (a1, b1, t1, k1)] => {
                    adjacent[*t0 as usize][*k0 as usize] = *t1;
                    adjacent[*t1 as usize][*k1 as usize] = *t0;
                    // Opposite directions: consistently wound.
                    closed &= a0 == b1 && b0 == a1;
                }
                _ => closed = false,
            }
        }
        let mut count = vec![0u32; vertices + 1];
        for tri in triangles {
            for &v in tri {
                count[v as usize + 1] += 1;
            }
        }
        for v in 0..vertices {
            count[v + 1] += count[v];
        }
        let ring_start = count.clone();
        let mut fill = count;
        let mut ring = vec![0u32; 3 * triangles.len()];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                ring[fill[v as usize] as usize] = t as u32;
                fill[v as usize] += 1;
            }
        }
        Self {
            adjacent,
            ring_start,
            ring,
            closed,
        }
    }
}

/// Unit normal of triangle (a, b, c), counter-clockwise seen from outside; zero if degenerate.
#[inline]
pub(crate) fn face_normal(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (b - a).cross(c - a).normalize_or_zero()
}

/// The interior angle at `p` between the edges towards `q` and `r`.
fn corner_angle(p: DVec3, q: DVec3, r: DVec3) -> f64 {
    let (u, v) = ((q - p).normalize_or_zero(), (r - p).normalize_or_zero());
    u.dot(v).clamp(-1.0, 1.0).acos()
}

/// The pseudo-normal (not normalised) of `feature` of triangle `t`: the face normal; for an
/// edge the sum of its two faces' normals (each weighted by the angle π); for a vertex the
/// sum of its faces' normals weighted by their angles at it (Bærentzen & Aanæs 2005, eq. 3).
/// `normal(t)` is triangle t's unit normal and `corner(t, k)` its corner k.
pub(crate) fn pseudo_normal(
    topology: &Topology,
    triangles: &[[u32; 3]],
    t: usize,
    feature: Feature,
    normal: impl Fn(usize) -> DVec3,
    corner: impl Fn(usize, usize) -> DVec3,
) -> DVec3 {
    match feature {
        Feature::Face => normal(t),
        Feature::Edge(k) => {
            let other = topology.adjacent[t][k as usize];
            if other == NONE {
                normal(t)
            } else {
                normal(t) + normal(other as usize)
            }
        }
        Feature::Vertex(k) => {
            let v = triangles[t][k as usize];
            let ring = &topology.ring[topology.ring_start[v as usize] as usize
                ..topology.ring_start[v as usize + 1] as usize];
            let mut sum = DVec3::ZERO;
            for &u in ring {
                let u = u as usize;
                let j = triangles[u].iter().position(|&w| w == v).unwrap_or(0);
                let angle =
                    corner_angle(corner(u, j), corner(u, (j + 1) % 3), corner(u, (j + 2) % 3));
                sum += normal(u) * angle;
            }
            sum
        }
    }
}
