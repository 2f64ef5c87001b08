//! The order of a domain's interior constraints: conflict-free sets that chunk well.

use super::domain::Domain;
use super::domain::Pairs;
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

    /// Splits every colour into full chunks of [`LANES`] (classified by layout) and a remainder,
    /// rebuilding `pairs` in chunk order.
    ///
    /// Greedy scan in particle order: eight constraints that fit a structured layout make a
    /// chunk; where a window of the contiguous or paired layout has holes (a grid row's end),
    /// its constraints make a chunk with dead lanes (see [`Chunk::live`]); a constraint that
    /// starts neither waits for the gathered chunks at the end of the set.
    fn plan_chunks(&mut self) {
        let old = std::mem::take(&mut self.pairs);
        let colours = std::mem::take(&mut self.colours);
        let n = self.len();
        for colour in colours {
            let begin = self.pairs.p.len();
            let first = self.chunks.len();
            let set: Vec<usize> = colour.collect();
            let mut leftovers = Vec::new();
            let mut i = 0;
            while i < set.len() {
                let ahead = &set[i..];
                let full = (ahead.len() >= LANES)
                    .then(|| {
                        let p: [u32; LANES] = std::array::from_fn(|l| old.p[ahead[l]]);
                        let q: [u32; LANES] = std::array::from_fn(|l| old.q[ahead[l]]);
                        structured_layout(&p, &q)
                    })
                    .flatten();
                if let Some(layout) = full {
                    let lanes = std::array::from_fn(|l| Some(ahead[l]));
                    self.push_chunk(&old, layout, lanes, None);
                    i += LANES;
                } else if let Some(win) = holey_window(&old, ahead, n) {
                    self.push_chunk(&old, win.layout, win.lanes, Some(win.slots));
                    i += win.used;
                } else {
                    leftovers.push(ahead[0]);
                    i += 1;
                }
            }
            let mut rest = leftovers.chunks_exact(LANES);
            for lanes in rest.by_ref() {
                let lanes = std::array::from_fn(|l| Some(lanes[l]));
                self.push_chunk(&old, Layout::Gathered, lanes, None);
            }
            let tail = self.pairs.p.len();
            for &k in rest.remainder() {
                let pairs = &mut self.pairs;
                pairs.push_f32(old.p[k], old.q[k], old.rest[k], old.group[k]);
            }
            self.colours.push(begin..self.pairs.p.len());
            self.plan.push((first..self.chunks.len(), tail));
        }
    }

    /// Appends a chunk: `lanes` gives each lane's constraint in `old`, `None` for a dead lane,
    /// whose particles `slots` gives. The chunk carries what its lanes share: a structured chunk
    /// of one group reads no per-lane indices or groups, and one whose rest lengths have the
    /// same bits no rest lengths either. A dead lane takes the first live lane's group and
    /// rest length, so it breaks neither.
    fn push_chunk(
        &mut self,
        old: &Pairs,
        layout: Layout,
        lanes: [Option<usize>; LANES],
        slots: Option<[(u32, u32); LANES]>,
    ) {
        let start = self.pairs.p.len();
        let lead = lanes.iter().flatten().next().copied().unwrap_or_default();
        let mut live = 0u8;
        for (l, k) in lanes.iter().enumerate() {
            match (k, slots) {
                (Some(k), _) => {
                    live |= 1 << l;
                    let k = *k;
                    self.pairs
                        .push_f32(old.p[k], old.q[k], old.rest[k], old.group[k]);
                }
                (None, Some(slots)) => {
                    let (p, q) = slots[l];
                    self.pairs.push_f32(p, q, old.rest[lead], old.group[lead]);
                }
                (None, None) => unreachable!("a dead lane comes with its window's particles"),
            }
        }
        let g = &self.pairs.group[start..start + LANES];
        let rest = &self.pairs.rest[start..start + LANES];
        self.chunks.push(Chunk {
            start,
            layout,
            uniform: g.iter().all(|&x| x == g[0]),
            same_rest: rest.iter().all(|&x| x.to_bits() == rest[0].to_bits()),
            p0: self.pairs.p[start],
            q0: self.pairs.q[start],
            group: g[0],
            rest: rest[0],
            live,
        });
    }
}

/// A structured window with holes: some lanes hold constraints, the others are dead.
struct Window {
    /// Contiguous or paired.
    layout: Layout,
    /// Each lane's constraint, `None` for a dead lane.
    lanes: [Option<usize>; LANES],
    /// How many constraints it takes.
    used: usize,
    /// Every lane's particles.
    slots: [(u32, u32); LANES],
}

/// A contiguous (q − p ≥ [`LANES`]) or paired (q = p + 1) window that starts at the first of
/// `ahead`'s constraints and holds at least two of them, with the constraints that follow it
/// in `ahead` as live lanes and its other slots dead. The window must lie inside the domain
/// (`n` particles); its slots are distinct particles, so a dead lane shares none with a live
/// one.
fn holey_window(old: &Pairs, ahead: &[usize], n: usize) -> Option<Window> {
    let k0 = *ahead.first()?;
    let (p0, d) = (old.p[k0], old.q[k0] - old.p[k0]);
    let (layout, step, reach) = if d as usize >= LANES {
        (Layout::Contiguous, 1, d as usize + LANES)
    } else if d == 1 {
        (Layout::Paired, 2, 2 * LANES)
    } else {
        return None;
    };
    if p0 as usize + reach > n {
        return None;
    }
    let mut lanes = [None; LANES];
    let mut used = 0;
    for &k in ahead {
        let (p, q) = (old.p[k], old.q[k]);
        let Some(off) = p.checked_sub(p0) else { break };
        let slot = (off / step) as usize;
        if q.checked_sub(p) != Some(d) || off % step != 0 || slot >= LANES || lanes[slot].is_some()
        {
            break;
        }
        lanes[slot] = Some(k);
        used += 1;
    }
    let slots = std::array::from_fn(|l| {
        let p = p0 + (l as u32) * step;
        (p, p + d)
    });
    (used >= 2).then_some(Window {
        layout,
        lanes,
        used,
        slots,
    })
}
