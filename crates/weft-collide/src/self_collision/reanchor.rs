//! Partial updates of the list: the few members that strayed past half the skin are
//! re-anchored and their new pairs added, without a full build (see
//! [`SelfCollision::refresh`]).

use glam::DVec3;

use super::SelfCollision;
use super::list::pair_key;
use crate::grid::{CellGrid, Queries};

/// A list is rebuilt rather than updated once more than 1/REANCHORED_CAP of the members have
/// strayed since the last build (see `MOVERS_CAP` in `check.rs`).
const REANCHORED_CAP: usize = 8;

/// Scratch of a partial update.
#[derive(Clone, Debug, Default)]
pub(super) struct Movers {
    /// Members (slots) that moved past the limit, a flag per slot for them (false between
    /// re-anchorings), and the pairs found for them.
    pub(super) movers: Vec<u32>,
    pub(super) is_mover: Vec<bool>,
    pub(super) new_pairs: Vec<(u32, u32)>,
    /// Re-anchored members (slots) by anchor, in cells of the grid's size (built at the first
    /// re-anchoring after a build, then updated with each re-anchoring's movers); the movers'
    /// anchors, sorted once by cell for both grids' queries; a query's answer.
    pub(super) recent: CellGrid,
    pub(super) near_points: Vec<DVec3>,
    pub(super) near_queries: Queries,
    pub(super) near: Vec<u32>,
}

impl SelfCollision {
    /// Re-anchors `movers` at xᵢ − c and lists their pairs within R of the new anchors (see
    /// [`SelfCollision::refresh`]); rebuilds instead once many members have been re-anchored.
    pub(super) fn reanchor(&mut self, positions: &[DVec3], thickness: &[f64], c: DVec3, t: f64) {
        self.timed(
            |times| &mut times.reanchor,
            |s| s.reanchor_movers(positions, thickness, c, t),
        );
    }

    /// [`SelfCollision::reanchor`] without its clock.
    fn reanchor_movers(&mut self, positions: &[DVec3], thickness: &[f64], c: DVec3, t: f64) {
        let before = self.list.reanchored.len();
        for &m in &self.moved.movers {
            let m = m as usize;
            self.list.built_at[m] = positions[self.members[m] as usize] - c;
            if !self.list.is_reanchored[m] {
                self.list.is_reanchored[m] = true;
                self.list.reanchored.push(m as u32);
            }
        }
        if self.list.reanchored.len() > (self.members.len() / REANCHORED_CAP).max(64) {
            return self.rebuild(positions, thickness);
        }
        self.tally.updates += 1;
        self.skin.reanchored(self.moved.movers.len());
        let (radius, apart) = (self.radius(t), self.exempt.apart(t));
        let r2 = radius * radius;
        let spacing = self.list.grid.spacing();
        if before == 0 {
            self.moved
                .recent
                .build(&self.list.built_at, &self.list.reanchored, spacing);
        } else {
            // Movers re-anchored before leave their old cells; the others keep their places.
            let mut new_ones = self.list.reanchored[before..].to_vec();
            new_ones.sort_unstable();
            self.moved
                .recent
                .update(&self.list.built_at, &self.moved.movers, |m| {
                    new_ones.binary_search(&m).is_err()
                });
        }
        let new_pairs = &mut self.moved.new_pairs;
        new_pairs.clear();
        // Members never re-anchored sit in the grid at their anchors.
        self.moved.near_points.clear();
        self.moved.near_points.extend(
            self.moved
                .movers
                .iter()
                .map(|&m| self.list.built_at[m as usize]),
        );
        self.moved
            .near_queries
            .sort(&self.moved.near_points, spacing);
        self.moved.is_mover.resize(self.members.len(), false);
        for &m in &self.moved.movers {
            self.moved.is_mover[m as usize] = true;
        }
        let (members, slot_of, is_reanchored) =
            (&self.members, &self.slot_of, &self.list.is_reanchored);
        let (movers, is_mover) = (&self.moved.movers, &self.moved.is_mover);
        self.list.grid.for_each_near_all(
            &self.moved.near_points,
            &self.moved.near_queries,
            radius,
            &mut self.moved.near,
            |k, j| {
                let id = members[movers[k] as usize];
                if j != id && !is_reanchored[slot_of[j as usize] as usize] {
                    new_pairs.push((id.min(j), id.max(j)));
                }
            },
        );
        // Re-anchored members, at their anchors in `recent`. Two movers find each other
        // (the distance test is symmetric): the pair is kept from the lower slot's query, so
        // that no pair is found twice.
        self.moved.recent.for_each_near_all(
            &self.moved.near_points,
            &self.moved.near_queries,
            radius,
            &mut self.moved.near,
            |k, r| {
                let m = movers[k];
                if r != m && (m < r || !is_mover[r as usize]) {
                    let (id, j) = (members[m as usize], members[r as usize]);
                    new_pairs.push((id.min(j), id.max(j)));
                }
            },
        );
        for &m in &self.moved.movers {
            self.moved.is_mover[m as usize] = false;
        }
        for &(a, b) in &self.moved.new_pairs {
            let (sa, sb) = (self.slot_of[a as usize], self.slot_of[b as usize]);
            // Listed at the build (the grid's test, replayed), or added since.
            let built = self.list.built_pos[sa as usize]
                .distance_squared(self.list.built_pos[sb as usize])
                <= r2;
            if built {
                continue;
            }
            if let Some(target) = self.exempt.target(a, b, thickness, apart)
                && self.list.in_extra.insert(pair_key(a, b))
            {
                self.list.extra.push(a, b, target);
            }
        }
    }
}
