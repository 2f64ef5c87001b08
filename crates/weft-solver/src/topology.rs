//! Mesh topology: unique edges and the wing vertices across each interior edge.

use std::collections::HashMap;

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
    pub fn new(triangles: &[[u32; 3]]) -> Self {
        // Edge key → (edge index, triangles using it as (triangle, opposite vertex, directed edge)).
        let mut map: HashMap<(u32, u32), usize> = HashMap::new();
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
        let mut wings = Vec::new();
        let mut non_manifold_edges = Vec::new();
        for (id, u) in users.iter().enumerate() {
            match u.as_slice() {
                [(edge, wing_a), (_, wing_b)] => wings.push(EdgeWings {
                    edge: *edge,
                    wing_a: *wing_a,
                    wing_b: *wing_b,
                }),
                [_] => {}
                _ => non_manifold_edges.push(edges[id]),
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
