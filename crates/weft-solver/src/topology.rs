//! Mesh topology: unique edges and the wing vertices across each interior edge.

/// An interior edge shared by two triangles, with the vertex opposite it in each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeWings {
    /// The shared edge's two vertices, in the winding order of the first triangle.
    pub edge: [u32; 2],
    /// The vertex of the first triangle opposite the edge.
    pub wing_a: u32,
    /// The vertex of the second triangle opposite the edge.
    pub wing_b: u32,
}

/// Edges and interior-edge wings of a triangle mesh, in a deterministic order.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// Every undirected edge once, smaller index first, in order of first appearance.
    pub edges: Vec<[u32; 2]>,
    /// Interior edges shared by exactly two triangles.
    pub wings: Vec<EdgeWings>,
    /// Edges shared by more than two triangles (the mesh is non-manifold there).
    pub non_manifold_edges: Vec<[u32; 2]>,
}

impl Topology {
    /// Builds the topology of `triangles` (indices must be valid; see [`crate::MeshError`]).
    ///
    /// Every half-edge (triangle t's edge k is half-edge 3t + k) is sorted by its undirected
    /// key, so that each edge's uses lie together in the order they appear; edges are then
    /// numbered by their first use. Two sorts, no hashing and no allocation per edge: a 1024²
    /// grid's 6 million half-edges take a fraction of a second.
    pub fn new(triangles: &[[u32; 3]]) -> Self {
        let key = |a: u32, b: u32| (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
        let mut half: Vec<(u64, u32)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                half.push((key(tri[k], tri[(k + 1) % 3]), (3 * t + k) as u32));
            }
        }
        // (key, half-edge) pairs are distinct, so the order is unique.
        half.sort_unstable();
        // Per edge: its first use and its run of uses in `half`.
        let mut runs: Vec<(u32, usize, usize)> = Vec::new();
        let mut start = 0;
        while start < half.len() {
            let mut end = start + 1;
            while end < half.len() && half[end].0 == half[start].0 {
                end += 1;
            }
            runs.push((half[start].1, start, end));
            start = end;
        }
        runs.sort_unstable_by_key(|r| r.0);
        // Half-edge h as (its directed edge, the vertex opposite it).
        let use_of = |h: u32| {
            let (t, k) = ((h / 3) as usize, (h % 3) as usize);
            let tri = triangles[t];
            ([tri[k], tri[(k + 1) % 3]], tri[(k + 2) % 3])
        };
        let mut edges = Vec::with_capacity(runs.len());
        let mut wings = Vec::new();
        let mut non_manifold_edges = Vec::new();
        for &(_, start, end) in &runs {
            let k = half[start].0;
            let edge = [(k >> 32) as u32, k as u32];
            edges.push(edge);
            match end - start {
                1 => {}
                2 => {
                    let (directed, wing_a) = use_of(half[start].1);
                    let (_, wing_b) = use_of(half[start + 1].1);
                    wings.push(EdgeWings {
                        edge: directed,
                        wing_a,
                        wing_b,
                    });
                }
                _ => non_manifold_edges.push(edge),
            }
        }
        Self {
            edges,
            wings,
            non_manifold_edges,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_share_one_interior_edge() {
        let topo = Topology::new(&[[0, 1, 2], [2, 1, 3]]);
        assert_eq!(topo.edges.len(), 5);
        assert_eq!(topo.wings.len(), 1);
        let w = topo.wings[0];
        assert_eq!(w.edge, [1, 2]);
        assert_eq!((w.wing_a, w.wing_b), (0, 3));
        assert!(topo.non_manifold_edges.is_empty());
    }

    #[test]
    fn three_triangles_on_one_edge_are_non_manifold() {
        let topo = Topology::new(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(topo.non_manifold_edges, vec![[0, 1]]);
    }
}
