//! The grid against brute force: keys, builds, updates, pairs and neighbourhoods.

use glam::DVec3;

use super::keys::{BITS, DIGIT, cell_key};
use super::*;
use crate::test_rand::rand;

#[test]
fn tagged_pairs_are_the_close_pairs_whose_tags_are_apart() {
    let (positions, items) = folded_cloud();
    // Tags: the positions stretched along x, so that some close pairs have close tags
    // and others do not.
    let tags: Vec<DVec3> = positions
        .iter()
        .enumerate()
        .map(|(k, p)| *p * DVec3::new(3.0, 1.0, 1.0) + DVec3::X * 0.01 * (k % 5) as f64)
        .collect();
    let (radius, apart) = (0.04, 0.05);
    let mut grid = CellGrid::default();
    grid.build(&positions, &items, radius);
    grid.tag(&tags);
    let mut found = Vec::new();
    for run in grid.cell_runs(5) {
        let mut row = Vec::new();
        grid.for_each_row_in(run, radius, apart, &mut row, |i, near| {
            found.extend(near.iter().map(|&j| (i.min(j), i.max(j))));
            std::ops::ControlFlow::Continue(())
        });
    }
    found.sort_unstable();
    let (mut brute, mut left_out) = (Vec::new(), 0);
    for (k, &i) in items.iter().enumerate() {
        for &j in &items[k + 1..] {
            let (i, j) = (i as usize, j as usize);
            if positions[i].distance_squared(positions[j]) <= radius * radius {
                if tags[i].distance_squared(tags[j]) > apart * apart {
                    brute.push((i as u32, j as u32));
                } else {
                    left_out += 1;
                }
            }
        }
    }
    assert!(
        brute.len() > 500 && left_out > 500,
        "too one-sided a test: {} kept, {left_out} left out",
        brute.len()
    );
    assert_eq!(found, brute);
}

/// A folded, clustered cloud of 800 points (many per cell, in negative and positive cells)
/// and the two thirds of them that are built into grids.
fn folded_cloud() -> (Vec<DVec3>, Vec<u32>) {
    let positions = (0..800)
        .map(|i| {
            let f = i as f64;
            DVec3::new((f * 0.37).sin(), 0.1 * (f * 0.71).cos(), (f * 0.13).sin()) * 0.3
        })
        .collect();
    (positions, (0..800).filter(|i| i % 3 != 1).collect())
}

#[test]
fn grid_near_query_is_exactly_the_brute_force_neighbourhood() {
    let (positions, items) = folded_cloud();
    let mut grid = CellGrid::default();
    grid.build(&positions, &items, 0.04);
    // At every point (built or not) and at points between them, for two radii.
    let probes: Vec<DVec3> = positions
        .iter()
        .copied()
        .chain(positions.windows(2).map(|w| 0.5 * (w[0] + w[1])))
        .collect();
    let mut total = 0;
    let (mut queries, mut row) = (Queries::default(), Vec::new());
    queries.sort(&probes, grid.spacing());
    for radius in [0.04, 0.015] {
        let mut found = vec![Vec::new(); probes.len()];
        grid.for_each_near_all(&probes, &queries, radius, &mut row, |k, i| found[k].push(i));
        for (p, mut found) in probes.iter().zip(found) {
            let mut brute: Vec<u32> = items
                .iter()
                .copied()
                .filter(|&i| positions[i as usize].distance_squared(*p) <= radius * radius)
                .collect();
            brute.sort_unstable();
            total += found.len();
            found.sort_unstable();
            assert_eq!(found, brute, "at {p} within {radius}");
        }
    }
    assert!(total > 5000, "too sparse a test: {total}");
}

#[test]
fn cell_keys_floor_like_f64_floor() {
    // The key as first written, with `f64::floor`.
    let reference = |p: DVec3, inv: f64| {
        let c = (p * inv).floor();
        let half = f64::from(1u32 << (BITS - 1));
        let max = f64::from((1u32 << BITS) - 2);
        let k = |v: f64| (v + half).clamp(1.0, max) as u64;
        (k(c.x) << (2 * BITS)) | (k(c.y) << BITS) | k(c.z)
    };
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        -0.5,
        1.0 - f64::EPSILON,
        -1.0 + f64::EPSILON,
        -f64::MIN_POSITIVE,
        1e15 + 0.5,
        -1e15 - 0.5,
        2e6,
        -2e6,
        2_097_151.5,
        2_097_152.0,
        -2_097_152.0,
        -2_097_152.5,
        1_048_575.5,
        -1_048_576.5,
        1e300,
        -1e300,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut seed = 9u64;
    values.extend((0..10_000).map(|_| rand(&mut seed) * 100.0));
    for inv in [1.0, 37.5, 1.0 / 0.0071] {
        for &v in &values {
            for p in [
                DVec3::new(v, 0.3, -0.2),
                DVec3::new(0.1, v, 7.0),
                DVec3::new(-3.0, 2.0, v),
            ] {
                assert_eq!(cell_key(p, inv), reference(p, inv), "{p} at {inv}");
            }
        }
    }
    // NaN coordinates share one cell.
    let nan = DVec3::new(f64::NAN, 0.0, 0.0);
    assert_eq!(
        cell_key(nan, 2.0),
        cell_key(DVec3::new(f64::NAN, 0.1, 0.2), 2.0)
    );
}

#[test]
fn a_build_sorts_by_cell_then_item_whichever_sort_it_takes() {
    let (mut positions, items) = folded_cloud();
    let spacing = 0.01;
    let expected = |positions: &[DVec3], items: &[u32]| {
        let mut e: Vec<(u64, u32)> = items
            .iter()
            .map(|&i| (cell_key(positions[i as usize], 1.0 / spacing), i))
            .collect();
        e.sort_unstable();
        e
    };
    let mut grid = CellGrid::default();
    let check = |grid: &mut CellGrid, positions: &[DVec3], items: &[u32], radix: bool| {
        let compact = Compact::of(
            items
                .iter()
                .map(|&i| cell_key(positions[i as usize], 100.0)),
        );
        let ascending = items.windows(2).all(|w| w[0] < w[1]);
        assert_eq!(compact.is_some() && ascending, radix, "the case tested");
        grid.build(positions, items, spacing);
        let e = expected(positions, items);
        assert_eq!(grid.sorted, e);
        let at: Vec<DVec3> = e.iter().map(|&(_, i)| positions[i as usize]).collect();
        assert_eq!(grid.positions, at);
    };
    // Radix: ascending items in a small box (several digits' worth of cells).
    check(&mut grid, &positions, &items, true);
    assert!(
        Compact::of(grid.sorted.iter().map(|&(k, _)| k))
            .expect("a compact packing")
            .bits
            > DIGIT
    );
    // All in one cell: no pass at all, the items' order.
    let one = vec![DVec3::splat(0.001); positions.len()];
    check(&mut grid, &one, &items, true);
    // Items out of order, and cells spread wider than 32 bits: the comparison sort.
    let mut shuffled = items.clone();
    shuffled.reverse();
    check(&mut grid, &positions, &shuffled, false);
    positions[items[3] as usize] = DVec3::new(5e3, -5e3, 5e3);
    check(&mut grid, &positions, &items, false);
}

#[test]
fn an_updated_grid_is_the_grid_built_anew() {
    let (mut positions, items) = folded_cloud();
    let spacing = 0.04;
    let mut grid = CellGrid::default();
    grid.build(&positions, &[], spacing);
    let mut present = vec![false; positions.len()];
    let mut seed = 3u64;
    // A pseudo-random index below m.
    let mut next = |m: usize| ((rand(&mut seed) + 1.0) * 0.5 * m as f64) as usize % m;
    for round in 0..20 {
        // Some items already in the grid and some new ones move.
        let mut moved: Vec<u32> = (0..1 + next(200))
            .map(|_| items[next(items.len())])
            .collect();
        moved.sort_unstable();
        moved.dedup();
        for &i in &moved {
            positions[i as usize].x += 0.03 * (next(100) as f64 / 50.0 - 1.0);
        }
        grid.update(&positions, &moved, |i| present[i as usize]);
        for &i in &moved {
            present[i as usize] = true;
        }
        let union: Vec<u32> = (0..positions.len() as u32)
            .filter(|&i| present[i as usize])
            .collect();
        let mut fresh = CellGrid::default();
        fresh.build(&positions, &union, spacing);
        assert_eq!(grid.sorted, fresh.sorted, "round {round}");
        assert_eq!(grid.positions, fresh.positions, "round {round}");
    }
    assert!(present.iter().filter(|&&p| p).count() > 400);
}

#[test]
fn grid_pairs_are_exactly_the_brute_force_pairs_each_once() {
    let (positions, items) = folded_cloud();
    let radius = 0.04;
    // Tags 1 m apart from each other: no pair is left out by them.
    let (apart, tags): (f64, Vec<DVec3>) = (
        0.5,
        (0..positions.len()).map(|i| DVec3::X * i as f64).collect(),
    );
    let mut grid = CellGrid::default();
    let mut moved = positions.clone();
    // Twice: the second build starts from the first one's order.
    for round in 0..2 {
        grid.build(&moved, &items, radius);
        grid.tag(&tags);
        let mut found = Vec::new();
        grid.for_each_pair(radius, apart, |i, j| found.push((i.min(j), i.max(j))));
        // Split into runs of cells, the runs find the same pairs, each once.
        for parts in [2, 7, 64] {
            let mut split = Vec::new();
            let runs = grid.cell_runs(parts);
            assert!(runs.windows(2).all(|w| w[0].end == w[1].start));
            assert_eq!((runs[0].start, runs[runs.len() - 1].end), (0, items.len()));
            for run in runs {
                grid.for_each_pair_in(run, radius, apart, |i, j| split.push((i.min(j), i.max(j))));
            }
            split.sort_unstable();
            let mut whole = found.clone();
            whole.sort_unstable();
            assert_eq!(split, whole, "round {round}: {parts} runs");
        }
        let count = found.len();
        found.sort_unstable();
        found.dedup();
        assert_eq!(
            found.len(),
            count,
            "round {round}: a pair was reported twice"
        );
        let mut brute = Vec::new();
        for (k, &i) in items.iter().enumerate() {
            for &j in &items[k + 1..] {
                let d2 = moved[i as usize].distance_squared(moved[j as usize]);
                if d2 <= radius * radius {
                    brute.push((i, j));
                }
            }
        }
        assert!(
            brute.len() > 1000,
            "too sparse a test: {} pairs",
            brute.len()
        );
        assert_eq!(found, brute, "round {round}");
        for (k, x) in moved.iter_mut().enumerate() {
            x.x += 0.01 * (k as f64 * 0.9).sin();
        }
    }
}
