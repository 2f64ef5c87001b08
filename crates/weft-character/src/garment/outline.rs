//! Sampling panel outlines: every edge cut into pieces no longer than the target length, the
//! two sides of a seam into the same number of pieces so their vertices pair one to one.

use glam::DVec2;

/// Splits `total` pieces over edges of lengths `lengths`, proportionally, at least one each
/// (largest remainder); `total >= lengths.len()`.
pub(crate) fn distribute(total: usize, lengths: &[f64]) -> Vec<usize> {
    let sum: f64 = lengths.iter().sum();
    let ideal: Vec<f64> = lengths.iter().map(|l| total as f64 * l / sum).collect();
    let mut n: Vec<usize> = ideal.iter().map(|x| (x.floor() as usize).max(1)).collect();
    while n.iter().sum::<usize>() < total {
        let k = (0..n.len())
            .max_by(|&i, &j| (ideal[i] - n[i] as f64).total_cmp(&(ideal[j] - n[j] as f64)))
            .unwrap_or(0);
        n[k] += 1;
    }
    while n.iter().sum::<usize>() > total {
        let k = (0..n.len())
            .filter(|&i| n[i] > 1)
            .min_by(|&i, &j| (ideal[i] - n[i] as f64).total_cmp(&(ideal[j] - n[j] as f64)))
            .unwrap_or(0);
        n[k] -= 1;
    }
    n
}

/// The edges of a run `first..=last`, wrapping, for an outline of `m` corners.
pub(crate) fn run(first: usize, last: usize, m: usize) -> Vec<usize> {
    let count = (last + m - first) % m + 1;
    (0..count).map(|i| (first + i) % m).collect()
}

/// Length of each outline edge.
pub(crate) fn edge_lengths(outline: &[DVec2]) -> Vec<f64> {
    let m = outline.len();
    (0..m)
        .map(|k| (outline[(k + 1) % m] - outline[k]).length())
        .collect()
}

/// Outline samples: for edge k, its start corner then `pieces[k] − 1` evenly spaced points.
/// Returns the points and the index of each edge's first sample.
pub(crate) fn samples(outline: &[DVec2], pieces: &[usize]) -> (Vec<DVec2>, Vec<usize>) {
    let m = outline.len();
    let mut points = Vec::with_capacity(pieces.iter().sum());
    let mut starts = Vec::with_capacity(m);
    for k in 0..m {
        starts.push(points.len());
        let (a, b) = (outline[k], outline[(k + 1) % m]);
        for j in 0..pieces[k] {
            points.push(a.lerp(b, j as f64 / pieces[k] as f64));
        }
    }
    (points, starts)
}

/// Sample indices along a run of edges, from its first corner to its last, inclusive.
pub(crate) fn run_vertices(
    edges: &[usize],
    pieces: &[usize],
    starts: &[usize],
    total: usize,
) -> Vec<usize> {
    let mut out = Vec::new();
    for &k in edges {
        out.extend((0..pieces[k]).map(|j| starts[k] + j));
    }
    if let Some(&last) = edges.last() {
        out.push((starts[last] + pieces[last]) % total);
    }
    out
}
