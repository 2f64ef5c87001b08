//! Tests of the domain split, the constraint order and the chunk layouts.

use super::layout::QUAD;
use super::*;
use crate::{ClothMesh, ClothParams, Family, Forces, GridDesc, Mass, Settings, SolverBuilder};

/// An `n` × `n` grid with stretch, shear and bend-distance; `shuffle` renumbers its
/// particles pseudo-randomly, so that index offsets stop being regular (the greedy path).
fn block(n: usize, shuffle: bool) -> (Block<2, Distance>, usize) {
    let grid = GridDesc {
        resolution: (n, n),
        ..GridDesc::default()
    }
    .build()
    .expect("valid grid");
    let n = grid.positions.len();
    let perm: Vec<u32> = if shuffle {
        (0..n as u64)
            .map(|i| ((i * 7919 + 13) % n as u64) as u32)
            .collect()
    } else {
        (0..n as u32).collect()
    };
    let mut positions = vec![DVec3::ZERO; n];
    for (i, &j) in perm.iter().enumerate() {
        positions[j as usize] = grid.positions[i];
    }
    let triangles = grid
        .triangles
        .iter()
        .map(|t| t.map(|i| perm[i as usize]))
        .collect();
    let mesh = ClothMesh::from_triangles(positions, triangles, Mass::Total(1.0), vec![])
        .expect("valid mesh");
    let params = ClothParams::default().edit(Family::BendDistance, |p| p.enabled = true);
    let mut b = SolverBuilder::new(Settings::default(), Forces::default()).expect("valid");
    b.add_cloth("c", &mesh, params, 0.0).expect("valid");
    (b.build().constraints().distance.clone(), n)
}

/// Preorder list of the internal nodes' (lo, mid, hi) over `lo..hi`, as `fork` walks them.
fn nodes(lo: usize, hi: usize, out: &mut Vec<(usize, usize, usize)>) {
    if hi - lo < 2 {
        return;
    }
    let mid = lo + (hi - lo) / 2;
    out.push((lo, mid, hi));
    nodes(lo, mid, out);
    nodes(mid, hi, out);
}

#[test]
fn a_link_goes_to_the_tree_node_that_splits_its_two_domains() {
    for count in 1..24 {
        let mut list = Vec::new();
        nodes(0, count, &mut list);
        assert_eq!(list.len(), count - 1);
        for a in 0..count {
            for b in a + 1..count {
                let (lo, mid, hi) = list[tree_node(b, a, count)];
                assert!(
                    lo <= a && a < mid && mid <= b && b < hi,
                    "{a} {b} of {count}"
                );
            }
        }
    }
}

/// Whether entry `k` of a domain's constraints is one: every entry is but a chunk's dead lanes
/// (see `Chunk::live`).
fn is_live(d: &Domain, k: usize) -> bool {
    d.chunks
        .iter()
        .find(|c| (c.start..c.start + LANES).contains(&k))
        .is_none_or(|c| c.live & (1 << (k - c.start)) != 0)
}

fn global(d: &Domain, k: usize) -> (u32, u32) {
    let s = d.start as u32;
    (s + d.pairs.p[k], s + d.pairs.q[k])
}

#[test]
fn every_constraint_is_solved_once_and_no_set_shares_a_particle() {
    for shuffle in [false, true] {
        let (block, n) = block(30, shuffle);
        let domains = Domains::new(&block, n, 200, SimdPath::Scalar);
        assert!(domains.list.len() > 3);
        let mut seen: Vec<(u32, u32)> = Vec::new();
        for d in &domains.list {
            for colour in &d.colours {
                // A dead lane's entry is no constraint (its lane writes back what it reads).
                let live = || colour.clone().filter(|&k| is_live(d, k));
                let mut used: Vec<u32> = live()
                    .flat_map(|k| {
                        let (p, q) = global(d, k);
                        [p, q]
                    })
                    .collect();
                let len = used.len();
                used.sort_unstable();
                used.dedup();
                assert_eq!(
                    used.len(),
                    len,
                    "a set shares a particle (shuffle {shuffle})"
                );
                seen.extend(live().map(|k| global(d, k)));
            }
        }
        let size = domains.size as u32;
        for [(dp, ip), (dq, iq)] in domains.links.iter().flat_map(|l| &l.ends) {
            assert_ne!(dp, dq);
            let (p, q) = (dp * size + ip, dq * size + iq);
            seen.push((p.min(q), p.max(q)));
        }
        let mut expected: Vec<(u32, u32)> = block
            .particles
            .iter()
            .map(|&[p, q]| (p.min(q), p.max(q)))
            .collect();
        expected.sort_unstable();
        seen.sort_unstable();
        assert_eq!(seen, expected, "shuffle {shuffle}");
    }
}

#[test]
fn chunk_layouts_match_their_lanes_and_grids_mostly_load_with_unit_stride() {
    // Rows of 32 split into whole chunks (a row of 30 leaves a ragged end of 6 per row).
    let (block, n) = block(32, false);
    let domains = Domains::new(&block, n, 4096, SimdPath::Scalar);
    for d in &domains.list {
        for c in &d.chunks {
            let (p, q) = (&d.pairs.p[c.start..], &d.pairs.q[c.start..]);
            // What the chunk carries for its lanes matches them.
            assert_eq!((c.p0, c.q0), (p[0], q[0]));
            assert_eq!(c.group, d.pairs.group[c.start]);
            let rests = &d.pairs.rest[c.start..c.start + LANES];
            if c.same_rest {
                assert!(
                    rests.iter().all(|&r| r == c.rest),
                    "{rests:?} vs {}",
                    c.rest
                );
            }
            for l in 0..LANES {
                let (ep, eq) = match c.layout {
                    Layout::Contiguous => (p[0] + l as u32, q[0] + l as u32),
                    Layout::Paired => (p[0] + 2 * l as u32, p[0] + 2 * l as u32 + 1),
                    Layout::Quad => (p[0] + QUAD[l] as u32, p[0] + QUAD[l] as u32 + 2),
                    Layout::Strided => (p[0] + 2 * l as u32, q[0] + 2 * l as u32),
                    Layout::Spaced => (p[0] + 4 * l as u32, p[0] + 4 * l as u32 + 2),
                    Layout::Gathered => (p[l], q[l]),
                };
                assert_eq!((p[l], q[l]), (ep, eq), "{:?}", c.layout);
            }
        }
    }
    let s = domains.stats();
    let structured = s.contiguous + s.strided;
    assert!(
        structured as f64 > 0.7 * block.len() as f64,
        "{s:?} of {}",
        block.len()
    );
}

#[test]
fn the_unit_k_form_runs_only_when_every_constrained_group_has_k_one() {
    let (block, n) = block(12, false);
    let mut domains = Domains::new(&block, n, 64, SimdPath::Scalar);
    let params = |edit: &dyn Fn(Family, &mut FamilyParams)| -> Vec<FamilyParams> {
        let families = Family::ALL.map(|f| {
            let mut p = FamilyParams::default_for(f);
            p.enabled |= f == Family::BendDistance;
            edit(f, &mut p);
            p
        });
        let cloth = crate::ClothParams {
            families,
            ..Default::default()
        };
        cloth.groups(1).to_vec()
    };
    let xpbd = Rule::Xpbd { h: 1.0 / 600.0 };
    let cases: [(&str, Vec<FamilyParams>, Rule, bool); 5] = [
        ("XPBD", params(&|_, _| {}), xpbd, true),
        (
            "PBD, every k = 1",
            params(&|_, p| p.pbd_stiffness = 1.0),
            Rule::Pbd,
            true,
        ),
        (
            "PBD, bending k = 0.5",
            params(&|f, p| p.pbd_stiffness = if f == Family::BendDistance { 0.5 } else { 1.0 }),
            Rule::Pbd,
            false,
        ),
        (
            "PBD, k = 0.5 for tethers, which have no constraint here",
            params(&|f, p| p.pbd_stiffness = if f == Family::Tether { 0.5 } else { 1.0 }),
            Rule::Pbd,
            true,
        ),
        (
            "XPBD with bending disabled (k = 0) over its constraints",
            params(&|f, p| p.enabled &= f != Family::BendDistance),
            xpbd,
            false,
        ),
    ];
    for (what, params, rule, unit_k) in cases {
        domains.prepare(&params, rule);
        assert_eq!(domains.mode().unit_k, unit_k, "{what}");
    }
}

#[test]
fn ragged_rows_chunk_with_dead_lanes_that_touch_no_live_lanes_particle() {
    // Rows of 30 leave a ragged end per row and set: without dead lanes 41 % of this grid's
    // constraints (stretch, shear, bend-distance) went to gathered chunks or the remainder;
    // with them 10.5 %, mostly the row-wise bending pairs (quad layout, no holes).
    let (block, n) = block(30, false);
    let domains = Domains::new(&block, n, 4096, SimdPath::Scalar);
    let mut holey = 0;
    for d in &domains.list {
        for c in &d.chunks {
            let lanes = c.start..c.start + LANES;
            let live: Vec<bool> = lanes.clone().map(|k| is_live(d, k)).collect();
            assert!(live[0], "a chunk starts with a constraint");
            if live.iter().all(|&a| a) {
                continue;
            }
            holey += 1;
            assert!(matches!(c.layout, Layout::Contiguous | Layout::Paired));
            let touched: Vec<u32> = lanes
                .clone()
                .filter(|&k| is_live(d, k))
                .flat_map(|k| [d.pairs.p[k], d.pairs.q[k]])
                .collect();
            for k in lanes.filter(|&k| !is_live(d, k)) {
                let (p, q) = (d.pairs.p[k], d.pairs.q[k]);
                assert!(
                    !touched.contains(&p) && !touched.contains(&q),
                    "dead lane {k}"
                );
                assert!((q as usize) < d.len());
            }
        }
    }
    assert!(holey > 20, "{holey} chunks with dead lanes");
    let s = domains.stats();
    assert!(
        (s.gathered + s.remainder) * 8 < block.len(),
        "{s:?} of {}",
        block.len()
    );
}

#[test]
fn a_cloth_of_4096_particles_or_more_is_cut_in_two_at_least() {
    // 63² = 3,969 particles stay one domain of the default size; 64² = 4,096 and 90² = 8,100
    // fit in one as well but are halved, so that two threads share them; 128² = 16,384 takes
    // two by its size alone, and a smaller size still cuts it finer.
    for (side, size, domains) in [
        (63, 8192, 1),
        (64, 8192, 2),
        (90, 8192, 2),
        (90, 100_000, 2),
        (128, 8192, 2),
        (128, 4096, 4),
    ] {
        let (block, n) = block(side, false);
        let d = Domains::new(&block, n, size, SimdPath::Scalar);
        assert_eq!(d.stats().domains, domains, "{side}², size {size}");
        // Every particle lies in exactly one domain.
        assert_eq!(d.list.iter().map(Domain::len).sum::<usize>(), n);
    }
}
