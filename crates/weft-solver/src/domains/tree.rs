//! The fork–join tree over the domains and the links (constraints across domains) solved at its
//! nodes.

use super::domain::{Domain, Mode};
use super::sweep::{End, project_one};
use crate::constraints::lanes::Coef;

/// Constraints whose particles lie in different domains, for one node of the fork–join tree.
#[derive(Clone, Debug, Default)]
pub(super) struct LinkSet {
    /// Domain and local index of each end.
    pub ends: Vec<[(u32, u32); 2]>,
    /// Rest length (m).
    pub rest: Vec<f64>,
    /// Parameter group.
    pub group: Vec<u32>,
    /// XPBD multiplier.
    pub lambda: Vec<f64>,
}

/// The preorder index of the internal node of the fork–join tree over `count` domains that
/// first separates domains `a` and `b` (the node where a link between them is solved).
pub(super) fn tree_node(a: usize, b: usize, count: usize) -> usize {
    let (a, b) = (a.min(b), a.max(b));
    let (mut lo, mut hi, mut node) = (0, count, 0);
    loop {
        let mid = lo + (hi - lo) / 2;
        if a < mid && b >= mid {
            return node;
        }
        if b < mid {
            node += 1;
            hi = mid;
        } else {
            node += mid - lo;
            lo = mid;
        }
    }
}

/// What every leaf and node of the fork–join tree needs.
pub(super) struct Job<'a, F> {
    /// Runs on each domain before its sweep.
    pub before: &'a F,
    /// Coefficients per parameter group.
    pub coef: &'a [Coef],
    /// Which optional terms to evaluate.
    pub mode: Mode,
    /// Visit the right half of every node first. Alternated from one pass to the next, so a
    /// thread starts a pass on the domain it ended the last one with, still in its cache; the
    /// halves share no particle, so their order changes no bit.
    pub reverse: bool,
    /// Visit both halves on the calling thread (a team worker's share of the tree, see
    /// `team`), never forking.
    pub serial: bool,
}

/// Solves `doms` (domains `first..`) with their `links` (the subtree's internal nodes, in
/// preorder): the two halves in parallel (`rayon::join`, or one after the other when
/// `job.serial`), then the links between them.
///
/// A leaf runs `before` and its own interior constraints. The tree's shape depends only on
/// the number of domains, so the order of every link relative to every domain is fixed: the
/// result does not depend on the thread count. Links are solved where both their domains are
/// finished, so most of them run in parallel too; only the root's are solved alone.
pub(super) fn fork<F>(doms: &mut [Domain], first: usize, links: &mut [LinkSet], job: &Job<'_, F>)
where
    F: Fn(&mut Domain, usize) + Sync,
{
    if let [d] = doms {
        (job.before)(d, first);
        d.project(job.coef, job.mode);
        return;
    }
    let mid = doms.len() / 2;
    let Some((own, below)) = links.split_first_mut() else {
        return;
    };
    let (left_links, right_links) = below.split_at_mut(mid - 1);
    let (left, right) = doms.split_at_mut(mid);
    let mut left = || fork(left, first, left_links, job);
    let mut right = || fork(right, first + mid, right_links, job);
    match (job.serial, job.reverse) {
        (true, false) => {
            left();
            right();
        }
        (true, true) => {
            right();
            left();
        }
        (false, false) => _ = rayon::join(left, right),
        (false, true) => _ = rayon::join(right, left),
    }
    solve_links(doms, first, own, job.coef, job.mode);
}

/// Projects one node's links (`first`: the global index of `list[0]`).
pub(super) fn solve_links(
    list: &mut [Domain],
    first: usize,
    links: &mut LinkSet,
    coef: &[Coef],
    mode: Mode,
) {
    if mode.damped {
        project_links::<true>(list, first, links, coef);
    } else {
        project_links::<false>(list, first, links, coef);
    }
}

/// Projects one node's links serially, in colour order.
fn project_links<const DAMPED: bool>(
    list: &mut [Domain],
    first: usize,
    links: &mut LinkSet,
    coef: &[Coef],
) {
    for k in 0..links.rest.len() {
        let [(dp, ip), (dq, iq)] = links.ends[k];
        let (dp, ip) = (dp as usize - first, ip as usize);
        let (dq, iq) = (dq as usize - first, iq as usize);
        let end = |d: &Domain, i| End::of(&d.x, &d.prev, &d.w, i);
        let (xp, xq) = project_one::<DAMPED>(
            end(&list[dp], ip),
            end(&list[dq], iq),
            links.rest[k],
            coef[links.group[k] as usize],
            &mut links.lambda[k],
        );
        for a in 0..3 {
            list[dp].x[a][ip] = xp[a];
            list[dq].x[a][iq] = xq[a];
        }
    }
}
