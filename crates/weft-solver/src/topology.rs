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
    /// Every half-edge (triangle t's edge k is half-edge 3t + k) is bucketed by its smaller
    /// vertex (a counting sort, in order) and each bucket sorted by the other vertex, stably,
    /// so that each edge's uses lie together in the order they appear; edges are then numbered
    /// by their first use, walking the half-edges in order. Linear but for the buckets' few
    /// entries, no hashing and no allocation per edge.
    pub fn new(triangles: &[[u32; 3]]) -> Self {
        let n = triangles
            .iter()
            .flatten()
            .max()
            .map_or(0, |&m| m as usize + 1);
        let ends = |tri: &[u32; 3], k: usize| {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            (a.min(b), a.max(b))
        };
        // bucket[v]..bucket[v + 1]: the half-edges whose smaller vertex is v.
        let mut bucket = vec![0u32; n + 1];
        for tri in triangles {
            for k in 0..3 {
                bucket[ends(tri, k).0 as usize + 1] += 1;
            }
        }
        for v in 0..n {
            bucket[v + 1] += bucket[v];
        }
        let mut fill = bucket.clone();
        // (the larger vertex, the half-edge), by smaller vertex, then larger, then half-edge.
        let mut half = vec![(0u32, 0u32); 3 * triangles.len()];
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (lo, hi) = ends(tri, k);
                half[fill[lo as usize] as usize] = (hi, (3 * t + k) as u32);
                fill[lo as usize] += 1;
            }
        }
        for v in 0..n {
            half[bucket[v] as usize..bucket[v + 1] as usize].sort_by_key(|&(hi, _)| hi);
        }
        // Each edge's run of uses in `half`, found at its first use: walking the half-edges in
        // order then numbers the edges by first use without a second sort.
        let mut run_at = vec![(0u32, 0u32, 0u32); half.len()];
        for v in 0..n {
            let (mut start, end) = (bucket[v] as usize, bucket[v + 1] as usize);
            while start < end {
                let mut stop = start + 1;
                while stop < end && half[stop].0 == half[start].0 {
                    stop += 1;
                }
                run_at[half[start].1 as usize] = (v as u32, start as u32, (stop - start) as u32);
                start = stop;
            }
        }
        // Half-edge h as (its directed edge, the vertex opposite it).
        let use_of = |h: u32| {
            let (t, k) = ((h / 3) as usize, (h % 3) as usize);
            let tri = triangles[t];
            ([tri[k], tri[(k + 1) % 3]], tri[(k + 2) % 3])
        };
        let mut edges = Vec::new();
        let mut wings = Vec::new();
        let mut non_manifold_edges = Vec::new();
        for &(lo, start, len) in run_at.iter().filter(|r| r.2 > 0) {
            let start = start as usize;
            let edge = [lo, half[start].0];
            edges.push(edge);
            match len {
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

    /// The map-based construction this replaces: edges and users in order of appearance.
    fn by_map(triangles: &[[u32; 3]]) -> Topology {
        let mut map = std::collections::HashMap::new();
        let mut users: Vec<Vec<([u32; 2], u32)>> = Vec::new();
        let mut edges = Vec::new();
        for t in triangles {
            for k in 0..3 {
                let (a, b, opp) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let key = (a.min(b), a.max(b));
                let id = *map.entry(key).or_insert_with(|| {
                    edges.push([key.0, key.1]);
                    users.push(Vec::new());
                    edges.len() - 1
                });
                users[id].push(([a, b], opp));
            }
        }
        let mut topo = Topology {
            edges,
            ..Topology::default()
        };
        for (id, u) in users.iter().enumerate() {
            match u.as_slice() {
                [(edge, wing_a), (_, wing_b)] => topo.wings.push(EdgeWings {
                    edge: *edge,
                    wing_a: *wing_a,
                    wing_b: *wing_b,
                }),
                [_] => {}
                _ => topo.non_manifold_edges.push(topo.edges[id]),
            }
        }
        topo
    }

    #[test]
    fn sorting_half_edges_numbers_edges_as_first_seen() {
        // A 9 × 7 grid of quads split both ways, its triangles in a scrambled order, and a
        // fan of three triangles on one edge (non-manifold).
        let n = 10u32;
        let mut tris = Vec::new();
        for j in 0..6 {
            for i in 0..n - 1 {
                let (a, b, c, d) = (
                    j * n + i,
                    j * n + i + 1,
                    (j + 1) * n + i,
                    (j + 1) * n + i + 1,
                );
                if (i + j) % 2 == 0 {
                    tris.extend([[a, b, d], [a, d, c]]);
                } else {
                    tris.extend([[a, b, c], [b, d, c]]);
                }
            }
        }
        let len = tris.len();
        let scrambled: Vec<[u32; 3]> = (0..len).map(|k| tris[(k * 37) % len]).collect();
        let mut all = scrambled;
        all.extend([[200, 201, 202], [201, 200, 203], [200, 201, 204]]);
        let (a, b) = (Topology::new(&all), by_map(&all));
        assert_eq!(a.edges, b.edges);
        assert_eq!(a.wings, b.wings);
        assert_eq!(a.non_manifold_edges, b.non_manifold_edges);
        assert_eq!(a.non_manifold_edges, vec![[200, 201]]);
    }
}
