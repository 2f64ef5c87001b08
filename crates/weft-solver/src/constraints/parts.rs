//! Contiguous particle ranges ("parts") that let one colour of a block be projected in parallel
//! with direct writes, without scratch buffers: a constraint whose particles all lie in one part
//! is projected by that part's task on the part's own slice of positions; the others (the
//! straddlers) are projected afterwards, one by one.
//!
//! Inside a colour no two constraints share a free particle, so the order of a colour's
//! constraints does not change a bit; a sweep that runs each part's colours on their own
//! (see `dihedral_sweep.rs`) changes the order across colours, so the number of parts is a
//! function of the constraint count alone ([`count`]), never of the thread count.

/// Most parts a block is split into (one task each). More contiguous ranges cut more
/// constraints, which then run alone: garment panels number their outline samples first, so
/// every further cut also separates some of them from their interior neighbours. On the
/// 10,172-particle T-shirt (panels numbered row by row) 2 ranges leave 663 of its 28,706
/// dihedrals straddling, with 14,021 and 14,022 in the parts; 8 ranges left 12,250 when the
/// panels' interiors were in refinement order.
pub(crate) const MAX_PARTS: usize = 2;

/// Constraints per part, at least: a part is one task of a parallel sweep, worth its fork.
pub(crate) const MIN_PER_PART: usize = 2048;

/// How many parts `constraints` constraints are split into: a function of the count alone,
/// so that the sweep order (and so every bit) never depends on the machine's thread count.
pub(crate) fn count(constraints: usize) -> usize {
    (constraints / MIN_PER_PART).clamp(1, MAX_PARTS)
}

/// Splits particles `0..n` into at most `k` contiguous ranges for `constraints`, boundary by
/// boundary, each where the sweep it leads to is quickest: the parts run in parallel and the
/// constraints a boundary cuts (the straddlers) run alone afterwards, so a boundary at m costs
/// max(this part, an equal share of the rest) + the constraints it cuts, all counted in
/// constraints. That balances the parts where cuts are alike (a grid's rows) and moves a
/// boundary to a panel join when the imbalance costs less than the cut saves. Returns the
/// `parts + 1` boundaries, from 0 to `n`; ties go to the lowest boundary.
pub(crate) fn split<const N: usize>(constraints: &[[u32; N]], n: usize, k: usize) -> Vec<usize> {
    let k = k.clamp(1, MAX_PARTS);
    if k == 1 || constraints.is_empty() || n < 2 * k {
        return vec![0, n];
    }
    // cut[m]: constraints with lo < m ≤ hi (cut by a boundary at m);
    // left[m]: constraints lying wholly below m (hi < m).
    let mut cut = vec![0i64; n + 2];
    let mut left = vec![0i64; n + 2];
    for idx in constraints {
        let lo = idx.iter().min().copied().unwrap_or(0) as usize;
        let hi = idx.iter().max().copied().unwrap_or(0) as usize;
        cut[lo + 1] += 1;
        cut[hi + 1] -= 1;
        left[hi + 1] += 1;
    }
    for m in 1..=n {
        cut[m] += cut[m - 1];
        left[m] += left[m - 1];
    }
    let total = constraints.len() as i64;
    let mut bounds = vec![0];
    for j in 1..k {
        let prev = bounds.last().copied().unwrap_or(0);
        let parts_after = (k - j) as i64;
        // This part: the constraints wholly in prev..m (those below prev are earlier parts'
        // or already cut); the rest: those wholly above m, shared by the parts still to come.
        let cost = |m: usize| {
            let here = left[m] - left[prev];
            let rest = total - left[m] - cut[m];
            here.max((rest + parts_after - 1) / parts_after) + cut[m]
        };
        let best = (prev + 1..n).min_by(|&a, &b| cost(a).cmp(&cost(b)).then(a.cmp(&b)));
        match best {
            Some(m) => bounds.push(m),
            None => break,
        }
    }
    bounds.push(n);
    bounds.dedup();
    bounds
}

/// The part whose range holds every particle of `idx`, or `bounds.len() − 1` (one past the
/// last part) for a straddler.
pub(crate) fn part_of<const N: usize>(idx: &[u32; N], bounds: &[usize]) -> usize {
    let parts = bounds.len() - 1;
    let find = |i: u32| bounds[1..].partition_point(|&b| b <= i as usize);
    let first = find(idx[0]);
    if idx.iter().all(|&i| find(i) == first) {
        first.min(parts)
    } else {
        parts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dihedral-like stencils of a `cols × rows` grid, row-major.
    fn grid(cols: u32, rows: u32) -> Vec<[u32; 4]> {
        let mut out = Vec::new();
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let i = r * cols + c;
                out.push([i, i + 1, i + cols, i + cols + 1]);
            }
        }
        out
    }

    #[test]
    fn a_grid_splits_between_rows_into_balanced_parts() {
        let cons = grid(40, 40);
        let bounds = split(&cons, 1600, 2);
        assert_eq!(bounds.len(), 3);
        assert_eq!(bounds[0], 0);
        assert_eq!(bounds[2], 1600);
        let straddlers = cons.iter().filter(|c| part_of(c, &bounds) == 2).count();
        // One row of stencils crosses the boundary: 39 of 1,521.
        assert!(straddlers <= 39, "{straddlers}");
        let in0 = cons.iter().filter(|c| part_of(c, &bounds) == 0).count();
        assert!((in0 as f64 - 741.0).abs() < 0.1 * 760.0, "{in0}");
    }

    #[test]
    fn part_of_puts_each_constraint_in_the_range_holding_all_its_particles() {
        let bounds = [0, 10, 20, 30];
        assert_eq!(part_of(&[0, 9], &bounds), 0);
        assert_eq!(part_of(&[10, 19], &bounds), 1);
        assert_eq!(part_of(&[29, 20], &bounds), 2);
        assert_eq!(part_of(&[9, 10], &bounds), 3);
        assert_eq!(part_of(&[0, 29], &bounds), 3);
    }

    #[test]
    fn panels_joined_by_few_constraints_split_at_the_join() {
        // Two 30×30 panels, the second's particles after the first's, joined by 5 stencils;
        // a third of the particles before the join would balance worse but cut nothing more.
        let mut cons = grid(30, 30);
        cons.extend(grid(30, 30).iter().map(|c| c.map(|i| i + 900)));
        cons.extend((0..5).map(|j| [870 + j, 871 + j, 900 + j, 901 + j]));
        let bounds = split(&cons, 1800, 2);
        let straddlers = cons.iter().filter(|c| part_of(c, &bounds) == 2).count();
        assert!(straddlers <= 5, "{straddlers}, bounds {bounds:?}");
    }

    /// The sweep time `split` models for two parts: the larger part plus the straddlers.
    fn two_part_time(cons: &[[u32; 4]], bounds: &[usize]) -> usize {
        let mut count = [0usize; 3];
        for c in cons {
            count[part_of(c, bounds)] += 1;
        }
        count[0].max(count[1]) + count[2]
    }

    #[test]
    fn two_parts_take_the_quickest_boundary_of_all() {
        // A panel numbered boundary first, then interior row by row (as garments are), next
        // to a plain grid: the fewest cuts lie near the join, the balance elsewhere.
        let (cols, rows) = (30u32, 30u32);
        let ring: Vec<u32> = (0..cols * rows)
            .filter(|&i| {
                let (c, r) = (i % cols, i / cols);
                c == 0 || r == 0 || c == cols - 1 || r == rows - 1
            })
            .collect();
        let mut order = vec![0u32; (cols * rows) as usize];
        let inner = (0..cols * rows).filter(|i| !ring.contains(i));
        for (k, i) in ring.iter().copied().chain(inner).enumerate() {
            order[i as usize] = k as u32;
        }
        let mut cons: Vec<[u32; 4]> = grid(cols, rows)
            .iter()
            .map(|c| c.map(|i| order[i as usize]))
            .collect();
        cons.extend(grid(20, 20).iter().map(|c| c.map(|i| i + 900)));
        let n = 1300;
        let bounds = split(&cons, n, 2);
        let got = two_part_time(&cons, &bounds);
        let best = (1..n)
            .map(|m| two_part_time(&cons, &[0, m, n]))
            .min()
            .unwrap_or(0);
        assert_eq!(got, best, "bounds {bounds:?}");
    }

    #[test]
    fn one_part_or_tiny_inputs_keep_everything_together() {
        assert_eq!(split(&grid(5, 5), 25, 1), vec![0, 25]);
        assert_eq!(split::<4>(&[], 25, 4), vec![0, 25]);
        assert_eq!(split(&grid(2, 2), 3, 4), vec![0, 3]);
    }
}
