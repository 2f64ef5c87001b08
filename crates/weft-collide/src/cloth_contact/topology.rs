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
    /// Per particle, the vertex it is once sewn: the smallest particle its seams join it to
    /// (itself without seams). Elements that share a vertex so are adjacent, as in one panel.
    pub sewn: Vec<u32>,
}

impl Elements {
    /// Whether the elements with corners `a` and `b` share a vertex, seams joined.
    #[inline]
    pub(crate) fn adjacent(&self, a: &[u32], b: &[u32]) -> bool {
        let s = |i: &u32| self.sewn[*i as usize];
        a.iter().any(|i| b.iter().any(|j| s(i) == s(j)))
    }
}

/// Per particle of `n`, the smallest particle the `seams` join it to.
pub(crate) fn sewn(n: usize, seams: &[[u32; 2]]) -> Vec<u32> {
    let mut rep: Vec<u32> = (0..n as u32).collect();
    fn find(rep: &mut [u32], mut v: u32) -> u32 {
        while rep[v as usize] != v {
            rep[v as usize] = rep[rep[v as usize] as usize];
            v = rep[v as usize];
        }
        v
    }
    for &[a, b] in seams {
        let (ra, rb) = (find(&mut rep, a), find(&mut rep, b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        rep[hi as usize] = lo;
    }
    (0..n as u32).map(|v| find(&mut rep, v)).collect()
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
            sewn: sewn(n, solver.seam_pairs()),
        })
    }
}

/// Each particle's triangles and edges (indices into [`Elements`]' lists), for finding the
/// elements a moved particle belongs to.
#[derive(Clone, Debug, Default)]
pub(crate) struct Incidence {
    triangles: Csr,
    edges: Csr,
}

impl Incidence {
    /// The incidence of `el`'s elements over `n` particles.
    pub(crate) fn new(el: &Elements, n: usize) -> Self {
        Self {
            triangles: Csr::new(n, &el.triangles),
            edges: Csr::new(n, &el.edges),
        }
    }

    /// Particles covered.
    pub(crate) fn len(&self) -> usize {
        self.triangles.starts.len().saturating_sub(1)
    }

    /// The triangles and the edges holding any of `particles`, each ascending and once.
    pub(crate) fn around(&self, particles: &[u32]) -> (Vec<u32>, Vec<u32>) {
        (
            self.triangles.around(particles),
            self.edges.around(particles),
        )
    }
}

/// Per particle, the elements holding it (compressed rows).
#[derive(Clone, Debug, Default)]
struct Csr {
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl Csr {
    /// The rows of `elements` (each a list of particle indices below `n`).
    fn new<const K: usize>(n: usize, elements: &[[u32; K]]) -> Self {
        let mut starts = vec![0u32; n + 1];
        for e in elements {
            for &i in e {
                starts[i as usize + 1] += 1;
            }
        }
        for i in 1..=n {
            starts[i] += starts[i - 1];
        }
        let mut fill = starts.clone();
        let mut items = vec![0u32; starts[n] as usize];
        for (k, e) in (0u32..).zip(elements) {
            for &i in e {
                items[fill[i as usize] as usize] = k;
                fill[i as usize] += 1;
            }
        }
        Self { starts, items }
    }

    /// The elements holding any of `particles`, ascending and once.
    fn around(&self, particles: &[u32]) -> Vec<u32> {
        let mut out: Vec<u32> = (particles.iter())
            .flat_map(|&i| {
                let i = i as usize;
                &self.items[self.starts[i] as usize..self.starts[i + 1] as usize]
            })
            .copied()
            .collect();
        out.sort_unstable();
        out.dedup();
        out
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
