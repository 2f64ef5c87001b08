//! A four-wide copy of a binary hierarchy ([`super::bvh`]) for nearest-first searches: each
//! node holds its four children's boxes in f32, rounded outwards, axis by axis, so one pass of four-lane
//! arithmetic bounds the distance to all four; the binary tree stays the authority (it is
//! built and refitted, and this copy follows it).

use glam::{DVec3, Vec4};

use super::bvh_node::Node;

/// Children of a node: four boxes per node, a third of the binary tree's nodes to visit.
const WIDTH: usize = 4;

/// Entries a search's stack holds at most: three per level (four children pushed, one
/// popped) over a tree no deeper than its binary original (at most 32 levels for a
/// median-split tree of fewer than 2³² primitives), and the root.
const STACK: usize = 3 * 32 + 1;

/// The `count` of a child slot that holds nothing.
const EMPTY: u32 = u32::MAX;

/// A node: its children's boxes (f32, each rounded outwards) and what each child is: a node
/// (`count` 0, `at` its index), a leaf's primitives `at .. at + count`, or nothing (`count`
/// [`EMPTY`], never entered).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Wide {
    lo: [[f32; WIDTH]; 3],
    hi: [[f32; WIDTH]; 3],
    at: [u32; WIDTH],
    count: [u32; WIDTH],
}

/// How far a node's children's vertices move over a frame: per child, the centre of the box
/// of their motions and a radius about it (f32, rounded up), so that every motion lies within
/// the radius of the centre.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Motions {
    centre: [[f32; WIDTH]; 3],
    radius: [f32; WIDTH],
}

impl Wide {
    /// The squared f32 distances from the point `p` (per axis, splat) to the four children's
    /// boxes (zero inside).
    #[inline(always)]
    fn distances_squared(&self, p: [Vec4; 3]) -> Vec4 {
        let d = |a: usize| {
            let (lo, hi) = (Vec4::from_array(self.lo[a]), Vec4::from_array(self.hi[a]));
            (lo - p[a]).max(p[a] - hi).max(Vec4::ZERO)
        };
        let (dx, dy, dz) = (d(0), d(1), d(2));
        dx * dx + dy * dy + dz * dz
    }
}

/// `v` in f32 (per axis, splat) and a bound on how far rounding moved it.
fn splat32(v: DVec3) -> ([Vec4; 3], f64) {
    let v32 = v.as_vec3();
    let moved = (v - v32.as_dvec3()).length() * (1.0 + 1e-6);
    ([v32.x, v32.y, v32.z].map(Vec4::splat), moved)
}

/// The four-wide hierarchy, root first, with the binary node behind each child (to refit).
#[derive(Clone, Debug, Default)]
pub(crate) struct WideBvh {
    nodes: Vec<Wide>,
    /// Per node and child, the binary node whose box it copies (`u32::MAX`: none).
    source: Vec<[u32; WIDTH]>,
    /// Per node, its children's motions over the current frame (empty: none known).
    motions: Vec<Motions>,
}

/// The largest f32 no greater than `x`, by integer selects alone (no branch: a refit
/// converts every box once a frame, four children at a time).
#[inline(always)]
fn down(x: f64) -> f32 {
    let f = x as f32;
    let bits = f.to_bits();
    // The next f32 toward −∞: one step down the bits of a positive value (f32::MAX from +∞),
    // one up those of a negative one, and the least negative subnormal from a zero.
    let step = ((bits >> 31) << 1).wrapping_sub(1);
    let lower = if bits << 1 == 0 {
        0x8000_0001
    } else {
        bits.wrapping_add(step)
    };
    f32::from_bits(if f64::from(f) > x { lower } else { bits })
}

/// The smallest f32 no less than `x`.
#[inline(always)]
fn up(x: f64) -> f32 {
    -down(-x)
}

impl WideBvh {
    /// The four-wide copy of `bvh`'s shape: each node takes up to four of the binary tree's
    /// nodes below it, opening the inner one with most primitives first. Its boxes are set by
    /// [`Self::refit`] (`Bvh::build` refits at once).
    pub fn of(nodes: &[Node]) -> Self {
        let mut wide = Self::default();
        if nodes.is_empty() {
            return wide;
        }
        wide.push(nodes, 0);
        wide
    }

    /// Adds the node covering binary node `n` (and, below it, its subtree); returns its index.
    fn push(&mut self, nodes: &[Node], n: usize) -> u32 {
        let node = nodes[n];
        let mut children: Vec<usize> = if node.count > 0 {
            vec![n]
        } else {
            vec![node.first as usize, node.first as usize + 1]
        };
        let size = |c: usize| Self::primitives(nodes, c);
        while children.len() < WIDTH {
            // The inner child with most primitives, the first of equals.
            let open = (0..children.len())
                .filter(|&k| nodes[children[k]].count == 0)
                .max_by(|&a, &b| size(children[a]).cmp(&size(children[b])).then(b.cmp(&a)));
            let Some(k) = open else { break };
            let first = nodes[children[k]].first as usize;
            children.splice(k..=k, [first, first + 1]);
        }
        let index = self.nodes.len();
        self.nodes.push(Wide {
            lo: [[f32::INFINITY; WIDTH]; 3],
            hi: [[f32::NEG_INFINITY; WIDTH]; 3],
            at: [0; WIDTH],
            count: [EMPTY; WIDTH],
        });
        self.source.push([u32::MAX; WIDTH]);
        for (k, &c) in children.iter().enumerate() {
            let child = nodes[c];
            self.source[index][k] = c as u32;
            if child.count > 0 {
                self.nodes[index].at[k] = child.first;
                self.nodes[index].count[k] = child.count;
            } else {
                let below = self.push(nodes, c);
                self.nodes[index].at[k] = below;
                self.nodes[index].count[k] = 0;
            }
        }
        index as u32
    }

    /// Primitives below binary node `n`.
    fn primitives(nodes: &[Node], n: usize) -> usize {
        let node = nodes[n];
        if node.count > 0 {
            node.count as usize
        } else {
            Self::primitives(nodes, node.first as usize)
                + Self::primitives(nodes, node.first as usize + 1)
        }
    }

    /// Copies the binary tree's boxes (after its own refit), rounded outwards.
    pub fn refit(&mut self, nodes: &[Node]) {
        for (node, source) in self.nodes.iter_mut().zip(&self.source) {
            // Per axis and child, each side's f64 bound (a child with no source keeps its
            // box: the f64 infinities round to themselves).
            let mut lo = [[0.0f64; WIDTH]; 3];
            let mut hi = [[0.0f64; WIDTH]; 3];
            for (k, &s) in source.iter().enumerate() {
                let b = nodes.get(s as usize);
                for a in 0..3 {
                    lo[a][k] = b.map_or(f64::from(node.lo[a][k]), |b| b.lo[a]);
                    hi[a][k] = b.map_or(f64::from(node.hi[a][k]), |b| b.hi[a]);
                }
            }
            for a in 0..3 {
                node.lo[a] = lo[a].map(down);
                node.hi[a] = hi[a].map(up);
            }
        }
    }

    /// Sets the children's motions over the frame from the binary nodes' boxes of motions
    /// `boxes` (indexed as the binary tree's nodes).
    pub fn set_motions(&mut self, boxes: &[(DVec3, DVec3)]) {
        self.motions.clear();
        for source in &self.source {
            // Per axis and child, the box of motions (a child with none: an empty slot,
            // whose radius stays infinite).
            let (mut lo, mut hi) = ([[0.0f64; WIDTH]; 3], [[0.0f64; WIDTH]; 3]);
            let mut some = [false; WIDTH];
            for (k, &s) in source.iter().enumerate() {
                if let Some(&(l, h)) = boxes.get(s as usize) {
                    some[k] = true;
                    for a in 0..3 {
                        (lo[a][k], hi[a][k]) = (l[a], h[a]);
                    }
                }
            }
            let mut m = Motions {
                centre: [[0.0; WIDTH]; 3],
                radius: [f32::INFINITY; WIDTH],
            };
            // Every motion within the half-diagonal of the centre, and the f32 centre within
            // its rounding of the f64 one (the same operations, in the same order, as on
            // `DVec3`s, lane by lane).
            let (mut half2, mut off2) = ([0.0f64; WIDTH], [0.0f64; WIDTH]);
            for a in 0..3 {
                for k in 0..WIDTH {
                    let centre = 0.5 * (lo[a][k] + hi[a][k]);
                    let c32 = centre as f32;
                    let (d, e) = (hi[a][k] - lo[a][k], centre - f64::from(c32));
                    half2[k] += d * d;
                    off2[k] += e * e;
                    m.centre[a][k] = if some[k] { c32 } else { 0.0 };
                }
            }
            for k in 0..WIDTH {
                let radius = 0.5 * half2[k].sqrt() + off2[k].sqrt();
                let r32 = up(radius * (1.0 + 1e-9));
                m.radius[k] = if some[k] { r32 } else { f32::INFINITY };
            }
            self.motions.push(m);
        }
    }

    /// Branch and bound, as [`Bvh::branch_and_bound`]: calls `leaf(i)` for every primitive
    /// in a leaf whose box, and every ancestor's box, may lie within the current limit of `x`
    /// (squared; `limit` at first, then what the last `leaf` call returned), nearer children
    /// first; in an order that is a function of the input.
    ///
    /// The boxes are f32 and `x` is rounded to f32, so the distances are bounded: with e the
    /// rounding of x, a box is passed over only when its f32 distance exceeds
    /// (√limit + e)² by more than the rounding of that distance (a few f32 ulps), and so
    /// only when the true distance exceeds √limit.
    pub fn branch_and_bound(&self, x: DVec3, limit: f64, mut leaf: impl FnMut(usize) -> f64) {
        if self.nodes.is_empty() {
            return;
        }
        let (p, e) = splat32(x);
        let threshold = |limit: f64| -> f32 {
            if limit.is_nan() {
                return f32::INFINITY;
            }
            let t = limit.max(0.0).sqrt() + e;
            up(t * t * (1.0 + 1e-5) + 1e-37)
        };
        let mut limit = limit;
        let mut cut = threshold(limit);
        // (squared distance, node or first primitive, primitives: 0 for a node)
        let mut stack = [(0f32, 0u32, 0u32); STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (d2, at, count) = stack[top];
            if d2 > cut {
                continue;
            }
            if count > 0 {
                for i in at..at + count {
                    let next = leaf(i as usize);
                    if next != limit {
                        limit = next;
                        cut = threshold(limit);
                    }
                }
                continue;
            }
            let node = &self.nodes[at as usize];
            let d = node.distances_squared(p).to_array();
            // The children within the cut, farthest pushed first (popped last).
            let mut near = [(0f32, 0usize); WIDTH];
            let mut n = 0;
            for (k, &dk) in d.iter().enumerate() {
                if dk <= cut && node.count[k] != EMPTY {
                    // Insertion by (distance, child): a fixed order.
                    let mut j = n;
                    while j > 0 && near[j - 1].0 > dk {
                        near[j] = near[j - 1];
                        j -= 1;
                    }
                    near[j] = (dk, k);
                    n += 1;
                }
            }
            for &(dk, k) in near[..n].iter().rev() {
                stack[top] = (dk, node.at[k], node.count[k]);
                top += 1;
            }
        }
    }
}

impl WideBvh {
    /// Calls `leaf(i)` for every primitive in a leaf that the search for a riding list may
    /// need (`super::riding`): a child is passed over only when every primitive in it is
    /// farther from `x` than `outer` plus `k` times how far any of its vertices' motions over
    /// the frame lies from `motion`, by its box (f32 distances bounded as in
    /// [`Self::branch_and_bound`], the motions' bound rounded up). Without motions (before
    /// [`Self::set_motions`]), as [`Self::branch_and_bound`] with the limit `outer`².
    pub fn visit_riding(
        &self,
        x: DVec3,
        outer: f64,
        (motion, k): (DVec3, f64),
        mut leaf: impl FnMut(usize),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        if self.motions.len() != self.nodes.len() {
            self.branch_and_bound(x, outer * outer, |i| {
                leaf(i);
                outer * outer
            });
            return;
        }
        let (p, e) = splat32(x);
        // The reference motion in f32, and how far it was moved by rounding.
        let (m, em) = splat32(motion);
        let base = up((outer + e + k * em) * (1.0 + 1e-5) + 1e-30);
        let k32 = up(k * (1.0 + 1e-6));
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let at = stack[top] as usize;
            let (node, motions) = (&self.nodes[at], &self.motions[at]);
            let d2 = node.distances_squared(p);
            let c = |a: usize| Vec4::from_array(motions.centre[a]) - m[a];
            let (cx, cy, cz) = (c(0), c(1), c(2));
            // How far a child's motions lie from the reference, at most (rounded up a few
            // ulps by the factor), and the reach that child must lie beyond.
            let dev = ((cx * cx + cy * cy + cz * cz).sqrt() + Vec4::from_array(motions.radius))
                * (1.0 + 1e-5);
            let reach = Vec4::splat(base) + Vec4::splat(k32) * dev;
            let cut = (reach * reach * (1.0 + 1e-5)).to_array();
            let d2 = d2.to_array();
            for c in (0..WIDTH).rev() {
                let count = node.count[c];
                if count == EMPTY || d2[c] > cut[c] {
                    continue;
                }
                if count > 0 {
                    let first = node.at[c];
                    for i in first..first + count {
                        leaf(i as usize);
                    }
                } else {
                    stack[top] = node.at[c];
                    top += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rand;
    use crate::trimesh::bvh::{Bvh, box_distance_squared};

    /// Random small boxes in a 2 m cube, off the f32 grid.
    fn boxes(n: usize, s: &mut u64) -> Vec<(DVec3, DVec3)> {
        (0..n)
            .map(|_| {
                let c = DVec3::new(rand(s), rand(s), rand(s));
                let h = DVec3::new(rand(s), rand(s), rand(s)).abs() * 0.05 + DVec3::splat(1e-9);
                (c - h, c + h)
            })
            .collect()
    }

    #[test]
    fn rounding_outwards_is_the_nearest_f32_on_that_side() {
        let mut s = 17;
        let mut values = vec![
            0.0, -0.0, 1e-300, -1e-300, 1e-40, -1e-40, 3.0, -3.0, 1e39, -1e39,
        ];
        values.extend((0..10_000).map(|k| rand(&mut s) * 10f64.powi(k % 9 - 4)));
        for x in values {
            let (d, u) = (down(x), up(x));
            assert!(f64::from(d) <= x && f64::from(u) >= x, "{x}: {d} {u}");
            // Nothing representable strictly between.
            let above = f32::from_bits(if d >= 0.0 {
                d.to_bits() + 1
            } else {
                d.to_bits() - 1
            });
            if d != 0.0 && d.is_finite() {
                assert!(f64::from(above) > x, "{x}: {d} is not the largest below");
            }
            if f64::from(x as f32) == x {
                assert_eq!((d, u), (x as f32, x as f32), "{x} is an f32");
            }
        }
    }

    #[test]
    fn visits_every_box_within_the_limit() {
        let mut s = 7;
        let boxes = boxes(997, &mut s);
        let (bvh, order) = Bvh::build(&boxes);
        let stored: Vec<_> = order.iter().map(|&i| boxes[i as usize]).collect();
        let mut on_the_edge = 0;
        for q in 0..2000 {
            // The limit exactly at one box's distance, so that rounding decides it: half the
            // queries anywhere, half a hair's breadth (up to 0.1 µm) off one of its faces.
            let pick = q % stored.len();
            let (lo, hi) = stored[pick];
            let x = if q % 2 == 0 {
                DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 1.1
            } else {
                let mid = 0.5 * (lo + hi);
                let off = 1e-7 * rand(&mut s).abs();
                match q % 6 {
                    1 => DVec3::new(hi.x + off, mid.y, mid.z),
                    3 => DVec3::new(mid.x, lo.y - off, mid.z),
                    _ => DVec3::new(mid.x, mid.y, hi.z + off),
                }
            };
            let limit = box_distance_squared(x, stored[pick].0, stored[pick].1);
            let mut seen = vec![false; stored.len()];
            bvh.branch_and_bound(x, limit, |i| {
                assert!(!seen[i], "primitive {i} visited twice");
                seen[i] = true;
                limit
            });
            for (i, b) in stored.iter().enumerate() {
                let d2 = box_distance_squared(x, b.0, b.1);
                if d2 <= limit {
                    assert!(
                        seen[i],
                        "query {q}: box {i} at {d2} within {limit} not visited"
                    );
                    on_the_edge += usize::from(d2 == limit && limit > 0.0);
                }
            }
        }
        assert!(on_the_edge > 1000, "{on_the_edge} queries at the limit");
    }

    #[test]
    fn riding_visits_every_box_that_may_come_within_reach() {
        let mut s = 3;
        let boxes = boxes(601, &mut s);
        let (mut bvh, order) = Bvh::build(&boxes);
        let stored: Vec<_> = order.iter().map(|&i| boxes[i as usize]).collect();
        // Each primitive's box of motions: about a drift that varies across space, up to 5 cm
        // wide, or (every other one) a single motion, so that the bound is tight.
        let motions: Vec<(DVec3, DVec3)> = (stored.iter().enumerate())
            .map(|(i, b)| {
                let wobble = DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 0.01;
                let c = 0.1 * (b.0 + b.1) + wobble;
                let h = DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)).abs() * 0.025;
                if i % 2 == 0 { (c, c) } else { (c - h, c + h) }
            })
            .collect();
        bvh.refit_moving(|i| [stored[i], motions[i]]);
        // The farthest a primitive's motions lie from `m`: at a corner of its box.
        let dev = |i: usize, m: DVec3| {
            let (lo, hi) = motions[i];
            (0..8)
                .map(|c| {
                    let p = DVec3::new(
                        if c & 1 == 0 { lo.x } else { hi.x },
                        if c & 2 == 0 { lo.y } else { hi.y },
                        if c & 4 == 0 { lo.z } else { hi.z },
                    );
                    (p - m).length()
                })
                .fold(0.0, f64::max)
        };
        let (mut at_edge, mut pruned) = (0, 0);
        for q in 0..1500 {
            let x = DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 1.1;
            let m = DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 0.05;
            // A third with no motion allowance, so that the reach alone is at the edge.
            let k = if q % 3 == 0 { 0.0 } else { rand(&mut s).abs() };
            // The reach exactly at one primitive's bound, so that rounding decides it.
            let pick = q % stored.len();
            let d = box_distance_squared(x, stored[pick].0, stored[pick].1).sqrt();
            let outer = (d - k * dev(pick, m)).max(0.0);
            let mut seen = vec![false; stored.len()];
            bvh.visit_riding(x, outer, (m, k), |i| seen[i] = true);
            for (i, b) in stored.iter().enumerate() {
                let reach = outer + k * dev(i, m);
                if box_distance_squared(x, b.0, b.1).sqrt() <= reach {
                    assert!(
                        seen[i],
                        "query {q}: primitive {i} within {reach} not visited"
                    );
                    at_edge += usize::from(i == pick);
                } else {
                    pruned += usize::from(!seen[i]);
                }
            }
        }
        assert!(at_edge > 1000, "{at_edge} queries at the edge");
        assert!(
            pruned > 100_000,
            "{pruned} primitives passed over: no pruning"
        );
    }

    #[test]
    fn nearest_first_and_shrinking_limit_finds_the_nearest_box() {
        let mut s = 11;
        let boxes = boxes(500, &mut s);
        let (bvh, order) = Bvh::build(&boxes);
        let stored: Vec<_> = order.iter().map(|&i| boxes[i as usize]).collect();
        for _ in 0..500 {
            let x = DVec3::new(rand(&mut s), rand(&mut s), rand(&mut s)) * 1.5;
            let truth = (stored.iter())
                .map(|b| box_distance_squared(x, b.0, b.1))
                .fold(f64::INFINITY, f64::min);
            let (mut best, mut visits) = (f64::INFINITY, 0);
            bvh.branch_and_bound(x, f64::INFINITY, |i| {
                visits += 1;
                best = best.min(box_distance_squared(x, stored[i].0, stored[i].1));
                best
            });
            assert_eq!(best, truth);
            assert!(visits < stored.len() / 4, "{visits} visits: no pruning");
        }
    }
}
