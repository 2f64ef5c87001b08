//! A four-wide copy of a [`Bvh`] for nearest-first searches: each node holds its four
//! children's boxes in f32, rounded outwards, axis by axis, so one pass of four-lane
//! arithmetic bounds the distance to all four; the binary tree stays the authority (it is
//! built and refitted, and this copy follows it).

use glam::{DVec3, Vec4};

use super::bvh::Bvh;

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

/// The four-wide hierarchy, root first, with the binary node behind each child (to refit).
#[derive(Clone, Debug, Default)]
pub(crate) struct WideBvh {
    nodes: Vec<Wide>,
    /// Per node and child, the binary node whose box it copies (`u32::MAX`: none).
    source: Vec<[u32; WIDTH]>,
}

/// The largest f32 no greater than `x`.
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) <= x {
        f
    } else {
        next_toward_neg(f)
    }
}

/// The smallest f32 no less than `x`.
fn up(x: f64) -> f32 {
    -down(-x)
}

/// The next f32 below a finite `f`.
fn next_toward_neg(f: f32) -> f32 {
    if f == 0.0 {
        -f32::from_bits(1)
    } else if f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f32::from_bits(f.to_bits() + 1)
    }
}

impl WideBvh {
    /// The four-wide copy of `bvh`: each node takes up to four of the binary tree's nodes
    /// below it, opening the inner one with most primitives first.
    pub fn of(bvh: &Bvh) -> Self {
        let mut wide = Self::default();
        if bvh.nodes.is_empty() {
            return wide;
        }
        wide.push(bvh, 0);
        wide.refit(bvh);
        wide
    }

    /// Adds the node covering binary node `n` (and, below it, its subtree); returns its index.
    fn push(&mut self, bvh: &Bvh, n: usize) -> u32 {
        let node = bvh.nodes[n];
        let mut children: Vec<usize> = if node.count > 0 {
            vec![n]
        } else {
            vec![node.first as usize, node.first as usize + 1]
        };
        let size = |c: usize| Self::primitives(bvh, c);
        while children.len() < WIDTH {
            // The inner child with most primitives, the first of equals.
            let open = (0..children.len())
                .filter(|&k| bvh.nodes[children[k]].count == 0)
                .max_by(|&a, &b| size(children[a]).cmp(&size(children[b])).then(b.cmp(&a)));
            let Some(k) = open else { break };
            let first = bvh.nodes[children[k]].first as usize;
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
            let child = bvh.nodes[c];
            self.source[index][k] = c as u32;
            if child.count > 0 {
                self.nodes[index].at[k] = child.first;
                self.nodes[index].count[k] = child.count;
            } else {
                let below = self.push(bvh, c);
                self.nodes[index].at[k] = below;
                self.nodes[index].count[k] = 0;
            }
        }
        index as u32
    }

    /// Primitives below binary node `n`.
    fn primitives(bvh: &Bvh, n: usize) -> usize {
        let node = bvh.nodes[n];
        if node.count > 0 {
            node.count as usize
        } else {
            Self::primitives(bvh, node.first as usize)
                + Self::primitives(bvh, node.first as usize + 1)
        }
    }

    /// Copies the binary tree's boxes (after its own refit), rounded outwards.
    pub fn refit(&mut self, bvh: &Bvh) {
        for (node, source) in self.nodes.iter_mut().zip(&self.source) {
            for (k, &s) in source.iter().enumerate() {
                let Some(b) = bvh.nodes.get(s as usize) else {
                    continue;
                };
                for a in 0..3 {
                    node.lo[a][k] = down(b.lo[a]);
                    node.hi[a][k] = up(b.hi[a]);
                }
            }
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
        let x32 = x.as_vec3();
        let e = (x - x32.as_dvec3()).length() * (1.0 + 1e-6);
        let threshold = |limit: f64| -> f32 {
            if limit.is_nan() {
                return f32::INFINITY;
            }
            let t = limit.max(0.0).sqrt() + e;
            up(t * t * (1.0 + 1e-5) + 1e-37)
        };
        let mut limit = limit;
        let mut cut = threshold(limit);
        let (px, py, pz) = (Vec4::splat(x32.x), Vec4::splat(x32.y), Vec4::splat(x32.z));
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
            let axis = |a: usize, p: Vec4| {
                let lo = Vec4::from_array(node.lo[a]);
                let hi = Vec4::from_array(node.hi[a]);
                (lo - p).max(p - hi).max(Vec4::ZERO)
            };
            let (dx, dy, dz) = (axis(0, px), axis(1, py), axis(2, pz));
            let d = (dx * dx + dy * dy + dz * dz).to_array();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rand::rand;
    use crate::trimesh::bvh::box_distance_squared;

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
