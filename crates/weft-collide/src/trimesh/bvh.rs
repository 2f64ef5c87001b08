//! A flat bounding-volume hierarchy of axis-aligned boxes in f64, over a mesh's triangles:
//! built once by median splits, refitted (not rebuilt) when the vertices move.

use glam::DVec3;

use super::bvh_node::Node;
use super::wide_bvh::WideBvh;

/// Triangles per leaf at most.
const LEAF: usize = 4;

/// The hierarchy, root first; every child comes after its parent.
#[derive(Clone, Debug, Default)]
pub(crate) struct Bvh {
    /// Nodes in depth-first creation order.
    pub nodes: Vec<Node>,
    /// Its four-wide copy, which the nearest-first searches walk.
    wide: WideBvh,
    /// Per node, a box worked out bottom-up (kept between refits, not to allocate).
    scratch: Vec<(DVec3, DVec3)>,
    /// The same for the boxes of motions.
    scratch_motions: Vec<(DVec3, DVec3)>,
}

/// Squared distance from `x` to the box [lo, hi] (0 inside).
#[inline]
pub(crate) fn box_distance_squared(x: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    let d = (lo - x).max(x - hi).max(DVec3::ZERO);
    d.length_squared()
}

impl Bvh {
    /// Builds a hierarchy over primitives with boxes `boxes`; returns it and the order the
    /// primitives must be stored in (`order[i]` is the original index of the i-th), so that
    /// each leaf holds a contiguous range.
    pub fn build(boxes: &[(DVec3, DVec3)]) -> (Self, Vec<u32>) {
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let centre = |i: u32| 0.5 * (boxes[i as usize].0 + boxes[i as usize].1);
        let mut nodes = vec![Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            first: 0,
            count: 0,
        }];
        // (node, range start, range end)
        let mut work = vec![(0usize, 0usize, boxes.len())];
        while let Some((node, s, e)) = work.pop() {
            if e - s <= LEAF {
                nodes[node].first = s as u32;
                nodes[node].count = (e - s) as u32;
                continue;
            }
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &i in &order[s..e] {
                lo = lo.min(centre(i));
                hi = hi.max(centre(i));
            }
            let extent = hi - lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = (s + e) / 2;
            // Median split; ties broken by index, so the build is a function of the input.
            order[s..e].select_nth_unstable_by(mid - s, |&i, &j| {
                centre(i)[axis].total_cmp(&centre(j)[axis]).then(i.cmp(&j))
            });
            let child = nodes.len();
            nodes[node].first = child as u32;
            nodes[node].count = 0;
            for _ in 0..2 {
                nodes.push(Node {
                    lo: DVec3::ZERO,
                    hi: DVec3::ZERO,
                    first: 0,
                    count: 0,
                });
            }
            work.push((child + 1, mid, e));
            work.push((child, s, mid));
        }
        let mut bvh = Self {
            nodes,
            wide: WideBvh::default(),
            scratch: Vec::new(),
            scratch_motions: Vec::new(),
        };
        bvh.wide = WideBvh::of(&bvh.nodes);
        let stored: Vec<(DVec3, DVec3)> = order.iter().map(|&i| boxes[i as usize]).collect();
        bvh.refit(|i| stored[i]);
        (bvh, order)
    }

    /// Recomputes every box from the primitives' boxes `leaf_box(i)` (i in storage order),
    /// children before parents; the tree's shape is kept.
    pub fn refit(&mut self, leaf_box: impl Fn(usize) -> (DVec3, DVec3)) {
        let mut boxes = std::mem::take(&mut self.scratch);
        self.merge_up(|i| [leaf_box(i)], [&mut boxes]);
        self.set_boxes(&boxes);
        self.scratch = boxes;
    }

    /// [`Self::refit`], and how far the primitives' vertices move over the current frame (for
    /// [`Self::visit_riding`]), in one pass over the tree, from each
    /// primitive's box and box of motions `leaf(i)` (i in storage order).
    pub fn refit_moving(&mut self, leaf: impl Fn(usize) -> [(DVec3, DVec3); 2]) {
        let mut boxes = std::mem::take(&mut self.scratch);
        let mut motions = std::mem::take(&mut self.scratch_motions);
        self.merge_up(leaf, [&mut boxes, &mut motions]);
        self.set_boxes(&boxes);
        self.wide.set_motions(&motions);
        self.scratch = boxes;
        self.scratch_motions = motions;
    }

    /// Sets every node's box to `boxes` (indexed as the nodes) and refits the four-wide copy.
    fn set_boxes(&mut self, boxes: &[(DVec3, DVec3)]) {
        for (node, &(lo, hi)) in self.nodes.iter_mut().zip(boxes) {
            node.lo = lo;
            node.hi = hi;
        }
        let mut wide = std::mem::take(&mut self.wide);
        wide.refit(&self.nodes);
        self.wide = wide;
    }

    /// Every node's `K` boxes of its primitives' boxes `leaf(i)` (box k of each into
    /// `boxes[k]`, indexed as the nodes), children before parents.
    fn merge_up<const K: usize>(
        &self,
        leaf: impl Fn(usize) -> [(DVec3, DVec3); K],
        boxes: [&mut Vec<(DVec3, DVec3)>; K],
    ) {
        let n = self.nodes.len();
        let mut boxes = boxes.map(|b| {
            b.clear();
            b.resize(n, (DVec3::ZERO, DVec3::ZERO));
            b
        });
        for k in (0..n).rev() {
            let node = self.nodes[k];
            let mut acc = [(DVec3::INFINITY, DVec3::NEG_INFINITY); K];
            let mut take = |b: [(DVec3, DVec3); K]| {
                for (a, (l, h)) in acc.iter_mut().zip(b) {
                    a.0 = a.0.min(l);
                    a.1 = a.1.max(h);
                }
            };
            if node.count > 0 {
                (node.first..node.first + node.count).for_each(|i| take(leaf(i as usize)));
            } else {
                for c in [node.first as usize, node.first as usize + 1] {
                    take(std::array::from_fn(|j| boxes[j][c]));
                }
            }
            for (b, a) in boxes.iter_mut().zip(acc) {
                b[k] = a;
            }
        }
    }

    /// [`WideBvh::visit_riding`]: every primitive a riding list about `x` may need, out to
    /// `outer` plus `k` times how far its vertices' motions lie from `motion`.
    pub fn visit_riding(
        &self,
        x: DVec3,
        outer: f64,
        motion: (DVec3, f64),
        leaf: impl FnMut(usize),
    ) {
        self.wide.visit_riding(x, outer, motion, leaf);
    }

    /// The root's box.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.nodes
            .first()
            .map_or((DVec3::ZERO, DVec3::ZERO), |n| (n.lo, n.hi))
    }

    /// Calls `leaf(i)` for every primitive in a leaf whose box, and every ancestor's box,
    /// `keep` accepts; in a fixed order.
    pub fn visit(&self, keep: impl Fn(DVec3, DVec3) -> bool, mut leaf: impl FnMut(usize)) {
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if !keep(node.lo, node.hi) {
                continue;
            }
            if node.count > 0 {
                for i in node.first..node.first + node.count {
                    leaf(i as usize);
                }
            } else {
                stack[top] = node.first + 1;
                stack[top + 1] = node.first;
                top += 2;
            }
        }
    }

    /// Branch and bound: calls `leaf(i)` for every primitive in a leaf whose box, and every
    /// ancestor's box, lies within the current limit of `x` (squared; `limit` at first, then
    /// what the last `leaf` call returned: it may shrink as the search finds nearer
    /// primitives), nearer children first; in an order that is a function of the input.
    pub fn branch_and_bound(&self, x: DVec3, limit: f64, leaf: impl FnMut(usize) -> f64) {
        self.wide.branch_and_bound(x, limit, leaf);
    }

    /// Branch and bound: the primitive minimising `distance_squared(i, bound)` (a value no
    /// less than the squared distance from `x` to its box; `None` if it is certainly no less
    /// than `bound`, the best so far) among those below `limit_squared`; ties keep the first
    /// found, so the answer is a function of the input.
    pub fn nearest<T>(
        &self,
        x: DVec3,
        limit_squared: f64,
        mut distance_squared: impl FnMut(usize, f64) -> Option<(f64, T)>,
    ) -> Option<(usize, f64, T)> {
        let mut best: Option<(usize, f64, T)> = None;
        let mut bound = limit_squared;
        self.branch_and_bound(x, limit_squared, |i| {
            if let Some((d2, info)) = distance_squared(i, bound)
                && d2 < bound
            {
                bound = d2;
                best = Some((i, d2, info));
            }
            bound
        });
        best
    }
}
