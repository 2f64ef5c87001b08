//! The summary of an experiments queue: CSV, Markdown and plots, from every run result present.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::experiments::metrics::Metric;
use crate::experiments::spec::{PlannedRun, Spec};
use crate::experiments::{NOT_RUN, Row, RunResult, result_path};
use crate::experiments::{front, plot};
use crate::output::Output;

/// A value for the Markdown table: whole numbers (frame counts) as integers, the rest to four
/// decimals or in scientific notation.
fn fmt(v: Option<f64>) -> String {
    match v {
        Some(v) if v.fract() == 0.0 && v.abs() < 1e15 => format!("{v:.0}"),
        Some(v) if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e5) => format!("{v:.4e}"),
        Some(v) => format!("{v:.4}"),
        None => "—".into(),
    }
}

/// The value of `m` the summary shows for `result`: none where the run diverged and `m`
/// measures the cloth's state (its last value describes a blown-up cloth, e.g. a sag of 1e12 m).
fn shown(m: Metric, result: &RunResult) -> Option<f64> {
    let value = result.metrics.get(m.name()).copied().flatten();
    match result.status.starts_with("diverged") && m.measures_state() {
        true => None,
        false => value,
    }
}

/// The files the report writes under `out`, with what they are called in messages.
pub fn files(spec: &Spec, out: &Path) -> Vec<(&'static str, PathBuf)> {
    let mut v = vec![
        ("the summary", out.join("summary.csv")),
        ("the summary", out.join("summary.md")),
    ];
    v.extend(spec.plot.iter().map(|p| ("a plot", out.join(&p.file))));
    v
}

/// Reads `results/run-*.json` under `out` and writes `summary.csv`, `summary.md` and the plots;
/// a planned run with no result is listed as `not run`, with no values, and a diverged run with
/// its cost and length only (see [`shown`]).
pub fn write(spec: &Spec, runs: &[PlannedRun], out: &Path) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    let mut with_results = 0;
    for r in runs {
        let path = result_path(out, r.index);
        let found = match std::fs::read_to_string(&path) {
            Ok(text) => {
                let result: RunResult = serde_json::from_str(&text)
                    .with_context(|| format!("cannot parse {}", path.display()))?;
                (result.label == r.label && result.series == r.series).then_some(result)
            }
            Err(_) => None,
        };
        let result = match found {
            Some(result) if result.status != NOT_RUN => {
                with_results += 1;
                result
            }
            _ => RunResult::not_run(r),
        };
        rows.push(Row { run: r, result });
    }
    let names: Vec<&str> = spec.metrics.iter().map(|m| m.name()).collect();
    let mut csv = format!("index,series,swept,status,{}\n", names.join(","));
    let mut md = format!(
        "# {}\n\n{} of {} runs have results.\n\n| # | series | swept | status | {} |\n|---|---|---|---|{}\n",
        if spec.title.is_empty() {
            "Experiments"
        } else {
            &spec.title
        },
        with_results,
        runs.len(),
        names.join(" | "),
        "---|".repeat(names.len())
    );
    for row in &rows {
        let values: Vec<Option<f64>> = spec
            .metrics
            .iter()
            .map(|&m| shown(m, &row.result))
            .collect();
        let status = row.result.status.split(':').next().unwrap_or("");
        let _ = writeln!(
            csv,
            "{},\"{}\",\"{}\",{},{}",
            row.run.index,
            row.run.series,
            row.run.label,
            status,
            values
                .iter()
                .map(|v| v.map(|v| v.to_string()).unwrap_or_default())
                .collect::<Vec<_>>()
                .join(",")
        );
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            row.run.index,
            row.run.series,
            row.run.label,
            status,
            values
                .iter()
                .map(|v| fmt(*v))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    // Plots first, so a closed or full standard output never costs a plot. Only complete runs
    // are plotted: an interrupted run's values cover part of its time.
    let complete: Vec<Row<'_>> = rows
        .iter()
        .filter(|r| r.result.status == "complete")
        .map(|r| Row {
            run: r.run,
            result: r.result.clone(),
        })
        .collect();
    for p in spec.plot.iter().filter(|p| p.front) {
        md.push_str(&front::cheapest_table(p, &plot::points(p, &complete)));
    }
    crate::output::write_file(&out.join("summary.csv"), csv.as_bytes())?;
    crate::output::write_file(&out.join("summary.md"), md.as_bytes())?;
    let mut drawn = Vec::new();
    for p in &spec.plot {
        let path = out.join(&p.file);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
        }
        let png = Output::create(&path)?;
        plot::draw(p, &complete, png.partial())
            .with_context(|| format!("plotting {}", path.display()))?;
        png.commit()?;
        drawn.push(path);
    }
    say!("{}", md.trim_end())?;
    for path in drawn {
        say!("plot: {}", path.display())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_diverged_run_shows_its_cost_and_length_but_no_state() {
        let mut result = RunResult {
            index: 0,
            series: "s".into(),
            label: "k=1e7".into(),
            status: "diverged: particle 3 at frame 12".into(),
            metrics: Default::default(),
            mcap: None,
        };
        result.metrics.insert("sag".into(), Some(3.2e12));
        result.metrics.insert("frames".into(), Some(12.0));
        result.metrics.insert("ms_per_frame".into(), Some(0.5));
        assert_eq!(shown(Metric::Sag, &result), None);
        assert_eq!(shown(Metric::Frames, &result), Some(12.0));
        assert_eq!(shown(Metric::MsPerFrame, &result), Some(0.5));
        result.status = "complete".into();
        assert_eq!(shown(Metric::Sag, &result), Some(3.2e12));
    }

    #[test]
    fn counts_are_integers_and_measures_keep_their_decimals() {
        assert_eq!(fmt(Some(100.0)), "100");
        assert_eq!(fmt(Some(0.0)), "0");
        assert_eq!(fmt(Some(250_000.0)), "250000");
        assert_eq!(fmt(Some(0.3)), "0.3000");
        assert_eq!(fmt(Some(2.5e-4)), "2.5000e-4");
        assert_eq!(fmt(None), "—");
    }
}
