//! The guarantee that no substep creates a crossing: a conservative continuous check of every
//! listed pair over the substep's linear motion `x_prev → x`, with impact zones frozen as the
//! fail-safe (Bridson, Fedkiw & Anderson 2002, §7.4, frozen rather than made rigid).
//!
//! For a vertex v and a triangle f moving linearly over t ∈ [0, 1], the distance d(t) is
//! M-Lipschitz with M = maxᵢ |Δᵥ − Δᵢ| over f's corners (Δ = x − x_prev): for fixed
//! barycentric weights bᵢ ≥ 0 summing to 1, |d/dt (xᵥ − Σ bᵢ xᵢ)| = |Σ bᵢ (Δᵥ − Δᵢ)| ≤ M,
//! and a minimum of M-Lipschitz functions is M-Lipschitz. The same holds for two edges with M
//! over the 2 × 2 pairs of end points. So a pair at d(0) > M stays apart. A pair that may come
//! closer gets conservative advancement (Mirtich 1996; Tang et al. 2009): from t with d(t),
//! no contact before t + (d(t) − η/2) / M, so the step keeps d ≥ η/2 > 0 until t ≥ 1 (safe),
//! or until d(t) ≤ η (an impact), η = min(η₀ · distance kept, d(0) / 2) so that a pair that
//! starts close is not frozen for starting close. Relative motion only: cloth falling or
//! carried together costs one distance per listed pair.
//!
//! Every particle of an impacting pair that is free (nonzero inverse mass) goes back to
//! `x_prev` with zero velocity, frozen for the substep; the pairs that touch it are checked
//! again, until no pair impacts. This ends: each round freezes at least one more particle,
//! and with every free particle frozen only the prescribed particles (pins) move. Then no pair
//! of non-adjacent elements comes to distance 0 during the substep, so no edge passes through
//! a triangle that was not already through it: no crossing is created. A pair that still
//! impacts with all its free particles frozen is driven by prescribed motion (a kinematic pin
//! pushed through cloth): it is counted as forced and left as the pins put it.

use glam::DVec3;
use rayon::prelude::*;
use weft_solver::Particles;

use super::broad::Candidates;
use super::geometry::{point_triangle_distance, segment_distance};
use super::topology::Elements;

/// At most this many advancement steps per pair; past it the pair counts as an impact
/// (conservative).
const MAX_STEPS: usize = 4000;

/// What the check did in one substep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FailSafeStats {
    /// Pairs that would have come within η (before any particle was frozen).
    pub impacts: usize,
    /// Particles frozen at their substep's start.
    pub frozen: usize,
    /// Rounds of the check (1 when nothing impacts).
    pub rounds: usize,
    /// Impacting pairs found with all their free particles already frozen: prescribed motion
    /// (pins) forced them (a pair may count once per round it is checked in).
    pub forced: usize,
}

/// Checks every listed pair over `x_prev → x` and freezes impact zones (see the module doc);
/// `eta` is η₀, the fraction of a pair's distance it may not come within; `list` measured
/// along those paths ([`Candidates::measure`]).
pub(crate) fn enforce(
    el: &Elements,
    list: &Candidates,
    p: &mut Particles,
    eta: f64,
    frozen: &mut Vec<bool>,
) -> FailSafeStats {
    let n = p.len();
    frozen.clear();
    frozen.resize(n, false);
    let mut stats = FailSafeStats::default();
    // Particles frozen in the last round: only pairs touching them can change outcome.
    let mut fresh: Option<Vec<bool>> = None;
    loop {
        stats.rounds += 1;
        let (x, prev) = (&p.positions, &p.prev_positions);
        let recheck = |ids: &[u32]| match &fresh {
            None => true,
            Some(f) => ids.iter().any(|&i| f[i as usize]),
        };
        let vf: Vec<[u32; 4]> = (list.vf.par_iter())
            .filter_map(|l| {
                let tri = el.triangles[l.b as usize];
                let ids = [l.a, tri[0], tri[1], tri[2]];
                let eta = l.keep * eta;
                // Never within η on the substep's paths (the list's bound): no impact.
                (recheck(&ids)
                    && list.lower_bound(l, &ids, 1) <= eta
                    && impact(ids, x, prev, eta, Kind::VertexFace))
                .then_some(ids)
            })
            .collect();
        let ee: Vec<[u32; 4]> = (list.ee.par_iter())
            .filter_map(|l| {
                let ([a0, a1], [b0, b1]) = (el.edges[l.a as usize], el.edges[l.b as usize]);
                let ids = [a0, a1, b0, b1];
                let eta = l.keep * eta;
                (recheck(&ids)
                    && list.lower_bound(l, &ids, 2) <= eta
                    && impact(ids, x, prev, eta, Kind::EdgeEdge))
                .then_some(ids)
            })
            .collect();
        if fresh.is_none() {
            stats.impacts = vf.len() + ee.len();
        }
        let mut newly = vec![false; n];
        let mut any = false;
        for ids in vf.iter().chain(&ee) {
            let stuck = |i: usize| p.inv_masses[i] == 0.0 || (frozen[i] && !newly[i]);
            if ids.iter().all(|&i| stuck(i as usize)) {
                stats.forced += 1;
            }
            for &i in ids {
                let i = i as usize;
                if p.inv_masses[i] != 0.0 && !frozen[i] {
                    frozen[i] = true;
                    newly[i] = true;
                    any = true;
                    stats.frozen += 1;
                    p.positions[i] = p.prev_positions[i];
                    p.velocities[i] = DVec3::ZERO;
                }
            }
        }
        if !any {
            return stats;
        }
        fresh = Some(newly);
    }
}

/// Which pair of elements an impact test is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// `ids[0]` against triangle `ids[1..]`.
    VertexFace,
    /// Edge `ids[0] ids[1]` against edge `ids[2] ids[3]`.
    EdgeEdge,
}

/// Whether the pair comes within η (= `eta`, or half its starting distance if less) of
/// touching during the linear motion `prev → x`.
fn impact(ids: [u32; 4], x: &[DVec3], prev: &[DVec3], eta: f64, kind: Kind) -> bool {
    let at = |s: f64| -> [DVec3; 4] {
        std::array::from_fn(|k| {
            let i = ids[k] as usize;
            prev[i].lerp(x[i], s)
        })
    };
    let d: [DVec3; 4] = std::array::from_fn(|k| x[ids[k] as usize] - prev[ids[k] as usize]);
    let m = match kind {
        Kind::VertexFace => (1..4).map(|k| (d[0] - d[k]).length()).fold(0.0, f64::max),
        Kind::EdgeEdge => [(0, 2), (0, 3), (1, 2), (1, 3)]
            .iter()
            .map(|&(a, b)| (d[a] - d[b]).length())
            .fold(0.0, f64::max),
    };
    let distance = |q: [DVec3; 4]| match kind {
        Kind::VertexFace => point_triangle_distance(q[0], [q[1], q[2], q[3]]),
        Kind::EdgeEdge => segment_distance(q[0], q[1], q[2], q[3]),
    };
    let d0 = distance(at(0.0));
    if m == 0.0 {
        return false; // no relative motion: the distance stays d0
    }
    let eta = eta.min(0.5 * d0);
    if d0 - m > eta {
        return false;
    }
    if eta.is_nan() || eta <= 0.0 {
        return true; // touching at the start, and moving
    }
    let (mut t, mut dt) = (0.0, d0);
    for _ in 0..MAX_STEPS {
        if dt <= eta {
            return true;
        }
        t += (dt - 0.5 * eta) / m;
        if t >= 1.0 {
            return false;
        }
        dt = distance(at(t));
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(ids: [u32; 4], prev: &[DVec3], x: &[DVec3], kind: Kind) -> bool {
        impact(ids, x, prev, 1e-4, kind)
    }

    #[test]
    fn a_vertex_through_a_triangle_impacts_and_one_beside_it_does_not() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Z];
        let mut prev = vec![DVec3::new(0.2, 0.1, 0.2)];
        prev.extend(tri);
        let mut x = prev.clone();
        // Through the face in one substep, far faster than the distance kept.
        x[0] = DVec3::new(0.2, -0.1, 0.2);
        assert!(run([0, 1, 2, 3], &prev, &x, Kind::VertexFace));
        // The same path beside the triangle.
        let mut beside = prev.clone();
        beside[0] = DVec3::new(2.0, 0.1, 0.2);
        let mut to = beside.clone();
        to[0] = DVec3::new(2.0, -0.1, 0.2);
        assert!(!run([0, 1, 2, 3], &beside, &to, Kind::VertexFace));
        // Falling together: no relative motion, never an impact.
        let moved: Vec<DVec3> = prev.iter().map(|p| *p - DVec3::Y * 5.0).collect();
        assert!(!run([0, 1, 2, 3], &prev, &moved, Kind::VertexFace));
    }

    #[test]
    fn crossing_edges_impact() {
        let prev = [
            DVec3::new(-1.0, 0.1, 0.0),
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let mut x = prev;
        x[0].y = -0.1;
        x[1].y = -0.1;
        assert!(run([0, 1, 2, 3], &prev, &x, Kind::EdgeEdge));
        // Moving along their own lines, they stay 0.1 apart.
        let mut along = prev;
        along[0].x += 0.5;
        along[1].x += 0.5;
        assert!(!run([0, 1, 2, 3], &prev, &along, Kind::EdgeEdge));
    }
}
