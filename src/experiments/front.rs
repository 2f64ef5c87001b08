//! Cost–accuracy fronts: for a plot of an error against a cost (`front = true`), the runs no
//! cheaper run of their series beats, and the summary's table of what each series pays to
//! reach each accuracy.

use std::fmt::Write as _;

use crate::experiments::spec::PlotSpec;

/// One run as a plot's point.
pub struct Point<'a> {
    /// Its series.
    pub series: &'a str,
    /// Its swept values.
    pub label: &'a str,
    /// The plot's x (a cost).
    pub x: f64,
    /// The plot's y (an error).
    pub y: f64,
}

/// The points of `pts` (sorted by x) that no point of lower or equal x beats in y: the
/// cheapest way to each accuracy, when x is a cost and y an error.
pub fn front(pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut best = f64::INFINITY;
    pts.iter()
        .filter(|p| {
            let keep = p.1 < best;
            best = best.min(p.1);
            keep
        })
        .copied()
        .collect()
}

/// Accuracies at every power of ten from the largest error down to the smallest.
fn levels(errors: impl Iterator<Item = f64>) -> Vec<f64> {
    let (lo, hi) = errors
        .filter(|e| e.is_finite() && *e > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(a, b), e| (a.min(e), b.max(e)));
    if hi <= 0.0 {
        return Vec::new();
    }
    let (top, bottom) = (hi.log10().ceil() as i32, lo.log10().ceil() as i32);
    (bottom..=top).rev().map(|e| 10f64.powi(e)).collect()
}

/// A Markdown table: for each accuracy (a power of ten of `spec.y`), each series' cheapest
/// run in `spec.x` that reaches it, with that run's swept values; "—" where none does.
pub fn cheapest_table(spec: &PlotSpec, points: &[Point<'_>]) -> String {
    let mut series: Vec<&str> = Vec::new();
    for p in points {
        if !series.contains(&p.series) {
            series.push(p.series);
        }
    }
    let mut md = format!(
        "\n## Cheapest run to each accuracy ({})\n\n| {} ≤ | {} |\n|---|{}\n",
        spec.file,
        spec.y.name(),
        series.join(" | "),
        "---|".repeat(series.len())
    );
    for level in levels(points.iter().map(|p| p.y)) {
        let cells: Vec<String> = series
            .iter()
            .map(|s| {
                points
                    .iter()
                    .filter(|p| p.series == *s && p.y <= level)
                    .min_by(|a, b| a.x.total_cmp(&b.x))
                    .map_or_else(|| "—".to_owned(), |p| format!("{:.3} ({})", p.x, p.label))
            })
            .collect();
        let _ = writeln!(md, "| {level:.0e} | {} |", cells.join(" | "));
    }
    md
}

#[cfg(test)]
mod tests {
    use super::{front, levels};

    #[test]
    fn the_front_keeps_only_points_no_cheaper_point_beats() {
        let pts = [(1.0, 5.0), (2.0, 6.0), (3.0, 2.0), (4.0, 2.0), (5.0, 1.0)];
        assert_eq!(front(&pts), [(1.0, 5.0), (3.0, 2.0), (5.0, 1.0)]);
        assert!(front(&[]).is_empty());
    }

    #[test]
    fn accuracies_run_by_powers_of_ten_over_the_errors() {
        assert_eq!(
            levels([0.03, 2e-4, f64::NAN].into_iter()),
            [0.1, 0.01, 1e-3]
        );
        assert!(levels([0.0].into_iter()).is_empty());
    }
}
