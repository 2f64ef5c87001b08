//! The order of a domain's interior constraints: conflict-free sets that chunk well.

use super::domain::Domain;
use super::layout::{Chunk, Layout, structured_layout};
use crate::coloring::color;
use crate::constraints::lanes::LANES;

/// An interior constraint before ordering (local indices, p < q).
#[derive(Clone, Copy, Debug)]
pub(super) struct Interior {
    /// First end (local).
    pub p: u32,
    /// Second end (local).
    pub q: u32,
    /// Rest length (m).
    pub rest: f64,
    /// Parameter group.
    pub group: u32,
}

/// Classes (group, q − p) with at least this many constraints get the structured order.
const MIN_CLASS: usize = 8 * LANES;

impl Domain {
    /// Orders the interior constraints into independent sets ("colours") that chunk well.
    ///
    /// Constraints of one parameter group and one index offset d = q − p (a grid's rows,
    /// columns or diagonals) split into two sets by the parity of ⌊p/d⌋: inside a set no two
    /// constraints share a particle (p and p' = p ± d never have the same parity of ⌊p/d⌋), and
    /// sorted by p their ends mostly run with unit stride (d ≥ 8) or pairwise (d = 1). Smaller
    /// classes (irregular meshes) are coloured greedily. The order is a valid Gauss–Seidel
    /// order and depends only on the mesh and the domain size.
    pub(super) fn order(&mut self, mut cons: Vec<Interior>) {
        cons.sort_by_key(|c| (c.group, c.q - c.p, c.p));
        let mut rest: Vec<Interior> = Vec::new();
        let mut sets: Vec<Vec<Interior>> = Vec::new();
        for class in cons.chunk_by(|a, b| (a.group, a.q - a.p) == (b.group, b.q - b.p)) {
            if class.len() < MIN_CLASS {
                rest.extend_from_slice(class);
                continue;
            }
            let d = class[0].q - class[0].p;
            // A repeated pair (a mesh may give the same bending pair twice) would share both
            // particles with its twin: the repeats go to the greedy colouring.
            let mut even = Vec::new();
            let mut odd = Vec::new();
            for (k, c) in class.iter().enumerate() {
                if k > 0 && class[k - 1].p == c.p {
                    rest.push(*c);
                } else if (c.p / d) % 2 == 0 {
                    even.push(*c);
                } else {
                    odd.push(*c);
                }
            }
            sets.extend([even, odd].into_iter().filter(|s| !s.is_empty()));
        }
        let pairs: Vec<[u32; 2]> = rest.iter().map(|c| [c.p, c.q]).collect();
        let colours = color(&pairs, &vec![true; self.len()]);
        let mut by_colour: Vec<Vec<Interior>> = Vec::new();
        for (c, colour) in rest.iter().zip(colours) {
            let colour = colour as usize;
            if by_colour.len() <= colour {
                by_colour.resize(colour + 1, Vec::new());
            }
            by_colour[colour].push(*c);
        }
        sets.extend(by_colour);
        for set in sets {
            let begin = self.pairs.p.len();
            for c in set {
                self.pairs.push(c.p, c.q, c.rest, c.group);
            }
            self.colours.push(begin..self.pairs.p.len());
        }
        self.plan_chunks();
    }

    /// Splits every colour into full chunks of [`LANES`] (classified by layout) and a remainder.
    fn plan_chunks(&mut self) {
        for c in 0..self.colours.len() {
            let colour = self.colours[c].clone();
            // Greedy scan in particle order: eight constraints that fit a unit-stride layout
            // make a chunk; a constraint that starts no such chunk (a run's ragged end, say at
            // the end of a grid row) waits for the gathered chunks at the end of the set.
            let mut order = Vec::with_capacity(colour.len());
            let mut leftovers = Vec::new();
            let mut layouts = Vec::new();
            let mut k = colour.start;
            while k < colour.end {
                if k + LANES <= colour.end
                    && let Some(layout) =
                        structured_layout(&self.pairs.p[k..k + LANES], &self.pairs.q[k..k + LANES])
                {
                    order.extend(k..k + LANES);
                    layouts.push(layout);
                    k += LANES;
                } else {
                    leftovers.push(k);
                    k += 1;
                }
            }
            order.extend(leftovers);
            let pairs = &mut self.pairs;
            let take = |v: &Vec<u32>| order.iter().map(|&k| v[k]).collect::<Vec<u32>>();
            let (p, q, group) = (take(&pairs.p), take(&pairs.q), take(&pairs.group));
            let rest: Vec<f32> = order.iter().map(|&k| pairs.rest[k]).collect();
            pairs.p[colour.clone()].copy_from_slice(&p);
            pairs.q[colour.clone()].copy_from_slice(&q);
            pairs.group[colour.clone()].copy_from_slice(&group);
            pairs.rest[colour.clone()].copy_from_slice(&rest);
            let first = self.chunks.len();
            let mut k = colour.start;
            let structured = layouts.into_iter().map(Some);
            for layout in structured.chain(std::iter::repeat(None)) {
                if k + LANES > colour.end {
                    break;
                }
                // The chunk carries what its lanes share: a structured chunk of one group reads
                // no per-lane indices or groups, and one whose rest lengths have the same bits
                // no rest lengths either.
                let g = &pairs.group[k..k + LANES];
                let rest = &pairs.rest[k..k + LANES];
                self.chunks.push(Chunk {
                    start: k,
                    layout: layout.unwrap_or(Layout::Gathered),
                    uniform: g.iter().all(|&x| x == g[0]),
                    same_rest: rest.iter().all(|&x| x.to_bits() == rest[0].to_bits()),
                    p0: pairs.p[k],
                    q0: pairs.q[k],
                    group: g[0],
                    rest: rest[0],
                });
                k += LANES;
            }
            self.plan.push((first..self.chunks.len(), k));
        }
    }
}
