//! PNG line plots of one metric against a swept key, one line per series (plotters, with a
//! bundled font so no system fontconfig is needed).

use std::path::Path;
use std::sync::Once;

use anyhow::{Context, bail};
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::experiments::Row;
use crate::experiments::front::{self, Point};
use crate::experiments::metrics::Metric;
use crate::experiments::spec::PlotSpec;

/// DejaVu Sans Mono (see assets/fonts/DejaVu-LICENSE.txt).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");
pub(super) const FAMILY: &str = "sans-serif";

pub(super) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_err() {
            eprintln!("weft: warning: the bundled font did not load; plots will lack text");
        }
    });
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn x_of(spec: &PlotSpec, row: &Row<'_>) -> Option<f64> {
    match row.run.x.get(&spec.x) {
        Some(v) => Some(*v),
        None => {
            let m = Metric::from_name(&spec.x)?;
            row.result.metrics.get(m.name()).copied().flatten()
        }
    }
}

/// The rows that have both of `spec`'s values, as its points.
pub fn points<'a>(spec: &PlotSpec, rows: &'a [Row<'_>]) -> Vec<Point<'a>> {
    rows.iter()
        .filter_map(|row| {
            Some(Point {
                series: row.run.series.as_str(),
                label: row.run.label.as_str(),
                x: x_of(spec, row)?,
                y: row.result.metrics.get(spec.y.name()).copied().flatten()?,
            })
        })
        .collect()
}

/// Draws `spec` from `rows` into `path`.
pub fn draw(spec: &PlotSpec, rows: &[Row<'_>], path: &Path) -> anyhow::Result<()> {
    register_font();
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for Point {
        series: name, x, y, ..
    } in points(spec, rows)
    {
        if (spec.log_x && x <= 0.0) || (spec.log_y && y <= 0.0) {
            continue;
        }
        match series.iter_mut().find(|(n, _)| n == name) {
            Some((_, pts)) => pts.push((x, y)),
            None => series.push((name.to_owned(), vec![(x, y)])),
        }
    }
    for (_, pts) in &mut series {
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let all: Vec<(f64, f64)> = series.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    if all.is_empty() {
        bail!("no data for {} against {}", spec.y.name(), spec.x);
    }
    let (mut x0, mut x1) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    let (mut y0, mut y1) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.1), b.max(p.1))
        });
    let pad = |lo: &mut f64, hi: &mut f64, log: bool| {
        if log {
            *lo /= 1.3;
            *hi *= 1.3;
        } else {
            let d = (*hi - *lo).max(hi.abs() * 0.05).max(1e-12);
            *lo -= 0.08 * d;
            *hi += 0.08 * d;
        }
    };
    pad(&mut x0, &mut x1, spec.log_x);
    pad(&mut y0, &mut y1, spec.log_y);
    if !spec.log_y && y0 > 0.0 && y0 < 0.3 * y1 {
        y0 = 0.0;
    }
    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).context("drawing")?;
    let x_label = spec.x_label.clone().unwrap_or_else(|| spec.x.clone());
    let y_label = spec
        .y_label
        .clone()
        .unwrap_or_else(|| format!("{} ({})", spec.y.name(), spec.y.unit()));
    let legend = match spec.legend.as_deref() {
        Some("upper-left") => SeriesLabelPosition::UpperLeft,
        Some("lower-left") => SeriesLabelPosition::LowerLeft,
        Some("lower-right") => SeriesLabelPosition::LowerRight,
        _ => SeriesLabelPosition::UpperRight,
    };
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&spec.title, (FAMILY, 24))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(90);
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_labels(8)
                .y_labels(8)
                .x_desc(x_label.as_str())
                .y_desc(y_label.as_str())
                .label_style((FAMILY, 15))
                .axis_desc_style((FAMILY, 18))
                .draw()
                .context("drawing axes")?;
            for (i, (name, pts)) in series.iter().enumerate() {
                let c = COLORS[i % COLORS.len()];
                let line = if spec.front {
                    front::front(pts)
                } else {
                    pts.clone()
                };
                chart
                    .draw_series(LineSeries::new(line, c.stroke_width(2)))
                    .context("drawing a series")?
                    .label(name.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                    });
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))
                    .context("drawing points")?;
            }
            chart
                .configure_series_labels()
                .label_font((FAMILY, 16))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(legend)
                .draw()
                .context("drawing the legend")?;
        }};
    }
    // A log axis gets 1-2-5 ticks: plotters puts one only at each power of ten, so an axis
    // within a decade (dt from 1/240 to 1/20 s) had a single tick.
    let log_x = || (x0..x1).log_scale().with_key_points(log_ticks(x0, x1));
    let log_y = || (y0..y1).log_scale().with_key_points(log_ticks(y0, y1));
    match (spec.log_x, spec.log_y) {
        (false, false) => finish!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
        (true, false) => finish!(builder.build_cartesian_2d(log_x(), y0..y1)?),
        (false, true) => finish!(builder.build_cartesian_2d(x0..x1, log_y())?),
        (true, true) => finish!(builder.build_cartesian_2d(log_x(), log_y())?),
    }
    root.present().context("writing the PNG")?;
    Ok(())
}

/// Ticks of a log axis from `lo` to `hi` (both > 0): 1, 2 and 5 times each power of ten
/// within it, or every integer multiple when that gives fewer than three.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let ticks = |steps: &[f64]| -> Vec<f64> {
        let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (first..=last)
            .flat_map(|e| steps.iter().map(move |m| m * 10f64.powi(e)))
            // Rounded to the power's digits, so 0.3 is 0.3 and not 0.30000000000000004.
            .map(|v| format!("{v:.12e}").parse::<f64>().unwrap_or(v))
            .filter(|v| *v >= lo && *v <= hi)
            .collect()
    };
    let coarse = ticks(&[1.0, 2.0, 5.0]);
    if coarse.len() >= 3 {
        coarse
    } else {
        ticks(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

#[cfg(test)]
mod tests {
    use super::log_ticks;

    #[test]
    fn a_log_axis_within_a_decade_gets_several_ticks() {
        // sag_vs_dt.png: dt from 1/240 to 1/20 s, padded by 1.3.
        let t = log_ticks(1.0 / 240.0 / 1.3, 1.3 / 20.0);
        assert_eq!(t, [0.005, 0.01, 0.02, 0.05]);
        assert_eq!(log_ticks(1.0, 1000.0).len(), 10);
        assert_eq!(log_ticks(0.25, 0.45), [0.3, 0.4]);
    }
}
