//! The summary of an experiments queue: CSV, Markdown and plots, from every run result present.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;

use crate::experiments::plot;
use crate::experiments::spec::{PlannedRun, Spec};
use crate::experiments::{Row, RunResult};

fn fmt(v: Option<f64>) -> String {
    match v {
        Some(v) if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e5) => format!("{v:.4e}"),
        Some(v) => format!("{v:.4}"),
        None => "—".into(),
    }
}

/// Reads `results/run-*.json` under `out` and writes `summary.csv`, `summary.md` and the plots.
pub fn write(spec: &Spec, runs: &[PlannedRun], out: &Path) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for r in runs {
        let path = out.join("results").join(format!("run-{}.json", r.index));
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let result: RunResult = serde_json::from_str(&text)
            .with_context(|| format!("cannot parse {}", path.display()))?;
        if result.label == r.label && result.series == r.series {
            rows.push(Row { run: r, result });
        }
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
        rows.len(),
        runs.len(),
        names.join(" | "),
        "---|".repeat(names.len())
    );
    for row in &rows {
        let values: Vec<Option<f64>> = spec
            .metrics
            .iter()
            .map(|m| row.result.metrics.get(m.name()).copied().flatten())
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
    std::fs::write(out.join("summary.csv"), &csv)?;
    std::fs::write(out.join("summary.md"), &md)?;
    print!("{md}");
    for p in &spec.plot {
        let path = out.join(&p.file);
        plot::draw(p, &rows, &path).with_context(|| format!("plotting {}", path.display()))?;
        println!("plot: {}", path.display());
    }
    Ok(())
}
