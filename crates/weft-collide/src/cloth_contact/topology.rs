//! What cloth contact collides: the member cloths' particles, triangles and unique edges in
//! global particle indices, with each particle's cloth and the rest positions that bound the
//! distance kept between two elements of one cloth.

use glam::DVec3;
use weft_solver::Solver;

use crate::error::CollideError;

/// The colliding elements of the member cloths.
#[derive(Clone, Debug)]
pub(crate) struct Elements {
    /// Member particles, ascending.
    pub vertices: Vec<u32>,
    /// Every member cloth's triangles (global particle indices).
    pub triangles: Vec<[u32; 3]>,
    /// Every member cloth's unique edges as `[low, high]`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Per particle, its member cloth (`u32::MAX` for non-members).
    pub cloth: Vec<u32>,
    /// Positions when contact was turned on (the rest state).
    pub rest: Vec<DVec3>,
}

impl Elements {
    /// The elements of `cloths` of `solver`, at its current positions as the rest state.
    pub(crate) fn new(solver: &Solver, cloths: &[usize]) -> Result<Self, CollideError> {
        let n = solver.particles().len();
        let mut cloth = vec![u32::MAX; n];
        let mut vertices = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        for &c in cloths {
            let info = solver.cloths().get(c).ok_or(CollideError::NoSuchCloth {
                index: c,
                count: solver.cloths().len(),
            })?;
            for i in info.particles.clone() {
                cloth[i] = c as u32;
                vertices.push(i as u32);
            }
            triangles.extend(
                (info.triangles.iter()).filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]),
            );
        }
        vertices.sort_unstable();
        vertices.dedup();
        triangles.sort_unstable();
        triangles.dedup();
        let edges = edges_of(&triangles);
        Ok(Self {
            vertices,
            triangles,
            edges,
            cloth,
            rest: solver.particles().positions.clone(),
        })
    }
}

/// The edges of `triangles`, each as its two vertices lower first, sorted, once.
pub(crate) fn edges_of(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = (triangles.iter())
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}
