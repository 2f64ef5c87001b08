//! The experiments file: a base scene, series of runs (a sweep is the cartesian product of
//! its `vary` lists), metrics and plots; expanded into a numbered queue of runs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Deserialize;
use serde_json::Value;
use weft_scene::Override;

use crate::experiments::metrics::Metric;

/// An experiments file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// Title of the report.
    #[serde(default)]
    pub title: String,
    /// Base scene, relative to the experiments file.
    pub scene: String,
    /// Simulated seconds per run (frames = round(duration / dt)); or give `frames`.
    #[serde(default)]
    pub duration: Option<f64>,
    /// Frames per run.
    #[serde(default)]
    pub frames: Option<u64>,
    /// Overrides applied to every run.
    #[serde(default)]
    pub set: BTreeMap<String, Value>,
    /// Metrics in the summary table.
    pub metrics: Vec<Metric>,
    /// The series of runs.
    pub series: Vec<Series>,
    /// Plots.
    #[serde(default)]
    pub plot: Vec<PlotSpec>,
    /// The cantilever bending test: the strip cloth shaped from its material per run.
    #[serde(default)]
    pub cantilever: Option<crate::experiments::cantilever::CantileverSpec>,
    /// The converged run `shape_error` and `trajectory_error` measure against.
    #[serde(default)]
    pub reference: Option<ReferenceSpec>,
}

/// `[reference]` of an experiments file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Overrides of the reference run, on top of the file's `set` (e.g. `sim.substeps`).
    #[serde(default)]
    pub set: BTreeMap<String, Value>,
    /// Frames between the trajectory's samples (≥ 1).
    #[serde(default = "one")]
    pub every: u64,
}

fn one() -> u64 {
    1
}

/// A series: fixed overrides plus a sweep.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// Overrides of this series.
    #[serde(default)]
    pub set: BTreeMap<String, Value>,
    /// Keys to sweep and their values; every combination is one run.
    #[serde(default)]
    pub vary: BTreeMap<String, Vec<Value>>,
}

/// A plot of a metric against a swept key or another metric.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlotSpec {
    /// Output file name (PNG), in the output directory.
    pub file: String,
    /// A swept key (e.g. `sim.dt`) or a metric name (e.g. `cost`).
    pub x: String,
    /// A metric.
    pub y: Metric,
    /// Title.
    #[serde(default)]
    pub title: String,
    /// Axis labels (default: the names).
    #[serde(default)]
    pub x_label: Option<String>,
    /// Axis labels (default: the names).
    #[serde(default)]
    pub y_label: Option<String>,
    /// Logarithmic x axis.
    #[serde(default)]
    pub log_x: bool,
    /// Logarithmic y axis.
    #[serde(default)]
    pub log_y: bool,
    /// Legend corner: `upper-left`, `upper-right` (default), `lower-left`, `lower-right`.
    #[serde(default)]
    pub legend: Option<String>,
    /// Join each series' points along its front (the points no cheaper point beats: lowest
    /// `y` so far in increasing `x`) instead of through all of them.
    #[serde(default)]
    pub front: bool,
}

/// One run of the queue.
#[derive(Clone, Debug)]
pub struct PlannedRun {
    /// Position in the whole queue (stable across shards).
    pub index: usize,
    /// Its series' name.
    pub series: String,
    /// `key=value` of the swept keys.
    pub label: String,
    /// Every override, common ones first.
    pub overrides: Vec<Override>,
    /// Swept keys and their numeric values (fractions such as "1/60" evaluated).
    pub x: BTreeMap<String, f64>,
}

/// A step into an experiments file: a key or an array index.
enum Seg {
    Key(String),
    Index(usize),
}

impl std::fmt::Display for Seg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Seg::Key(k) if k.contains('.') => write!(f, ".{}", Value::String(k.clone())),
            Seg::Key(k) => write!(f, ".{k}"),
            Seg::Index(i) => write!(f, "[{i}]"),
        }
    }
}

/// Where in `v` a null is (TOML has none: serde_json makes one of NaN and the infinities).
fn null_at(v: &Value) -> Option<Vec<Seg>> {
    let below = |seg: Seg, v: &Value| {
        null_at(v).map(|mut rest| {
            rest.insert(0, seg);
            rest
        })
    };
    match v {
        Value::Null => Some(Vec::new()),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, v)| below(Seg::Index(i), v)),
        Value::Object(o) => o.iter().find_map(|(k, v)| below(Seg::Key(k.clone()), v)),
        _ => None,
    }
}

/// A JSON value written as TOML text for an override.
pub fn toml_text(v: &Value) -> String {
    match v {
        Value::String(s) => Value::String(s.clone()).to_string(),
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(toml_text).collect::<Vec<_>>().join(", ")
        ),
        Value::Object(o) => format!(
            "{{ {} }}",
            o.iter()
                .map(|(k, v)| format!("{k} = {}", toml_text(v)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        other => other.to_string(),
    }
}

/// A number, or a fraction string such as "1/60", or a list's first (a grid resolution's
/// columns).
pub fn numeric(v: &Value) -> Option<f64> {
    match v {
        Value::Array(a) => a.first().and_then(numeric),
        Value::Number(n) => n.as_f64(),
        Value::String(s) => match s.split_once('/') {
            Some((a, b)) => Some(a.trim().parse::<f64>().ok()? / b.trim().parse::<f64>().ok()?),
            None => s.trim().parse().ok(),
        },
        Value::Bool(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

fn plain(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

impl Spec {
    /// Reads an experiments file.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let spec: Spec = toml_edit::de::from_str(&text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            anyhow::anyhow!(
                "{}:{}: {}",
                path.display(),
                line.map(|l| l.to_string()).unwrap_or_default(),
                e.message().trim()
            )
        })?;
        if spec.series.is_empty() {
            bail!("{}: no [[series]]", path.display());
        }
        if spec.duration.is_some() == spec.frames.is_some() {
            bail!(
                "{}: give exactly one of `duration` and `frames`",
                path.display()
            );
        }
        if let Some(d) = spec.duration
            && !(d.is_finite() && d > 0.0)
        {
            bail!(
                "{}: duration must be finite and > 0, got {d}",
                path.display()
            );
        }
        let wants_reference = spec
            .metrics
            .iter()
            .chain(spec.plot.iter().map(|p| &p.y))
            .find(|m| m.needs_reference());
        if let (Some(m), None) = (wants_reference, &spec.reference) {
            bail!(
                "{}: the metric `{}` needs a [reference] table (the converged run it is \
                 measured against)",
                path.display(),
                m.name()
            );
        }
        if spec.reference.as_ref().is_some_and(|r| r.every == 0) {
            bail!("{}: reference.every must be at least 1", path.display());
        }
        spec.check_finite(path, &text)?;
        Ok(spec)
    }

    /// Refuses a `set` or `vary` value that is, or holds, NaN or an infinity. No scene key
    /// takes one, and the JSON values they are kept in cannot hold one: serde_json reads it
    /// as null, which reached the scene as the string "null" and the report as `null`.
    fn check_finite(&self, path: &Path, text: &str) -> anyhow::Result<()> {
        let mut values: Vec<(Vec<Seg>, &Value)> = Vec::new();
        for (k, v) in &self.set {
            values.push((vec![Seg::Key("set".into()), Seg::Key(k.clone())], v));
        }
        for (i, s) in self.series.iter().enumerate() {
            let series = || vec![Seg::Key("series".into()), Seg::Index(i)];
            for (k, v) in &s.set {
                let mut at = series();
                at.extend([Seg::Key("set".into()), Seg::Key(k.clone())]);
                values.push((at, v));
            }
            for (k, list) in &s.vary {
                for (j, v) in list.iter().enumerate() {
                    let mut at = series();
                    at.extend([Seg::Key("vary".into()), Seg::Key(k.clone()), Seg::Index(j)]);
                    values.push((at, v));
                }
            }
        }
        for (mut at, v) in values {
            let Some(inside) = null_at(v) else {
                continue;
            };
            at.extend(inside);
            let key: String = at.iter().map(|s| s.to_string()).collect();
            let key = key.trim_start_matches('.');
            let found = toml_edit::Document::parse(text).ok().and_then(|doc| {
                let mut item = doc.as_item();
                for seg in &at {
                    item = match seg {
                        Seg::Key(k) => item.get(k.as_str())?,
                        Seg::Index(i) => item.get(*i)?,
                    };
                }
                let span = item.span()?;
                let line = text.get(..span.start)?.matches('\n').count() + 1;
                Some((line, text.get(span)?.trim().to_owned()))
            });
            let (line, raw) = found.unwrap_or_default();
            let line = if line > 0 {
                format!("{line}:")
            } else {
                String::new()
            };
            let got = if raw.is_empty() {
                "NaN or an infinity".into()
            } else {
                raw
            };
            bail!(
                "{}:{line} {key}: must be a finite number, got {got}",
                path.display()
            );
        }
        Ok(())
    }

    /// Frames per run at a frame time step of `dt`.
    pub fn frames(&self, dt: f64) -> u64 {
        match (self.frames, self.duration) {
            (Some(f), _) => f,
            (None, Some(d)) => (d / dt).round().max(1.0) as u64,
            (None, None) => 1,
        }
    }

    /// The base scene's path.
    pub fn scene_path(&self, experiments_file: &Path) -> PathBuf {
        weft_scene::Scene::dir_of(experiments_file).join(&self.scene)
    }

    /// How many runs the queue holds (saturating), counted without expanding it.
    pub fn count(&self) -> u64 {
        self.series
            .iter()
            .map(|s| {
                s.vary
                    .values()
                    .fold(1u64, |n, v| n.saturating_mul(v.len() as u64))
            })
            .fold(0u64, u64::saturating_add)
    }

    /// Refuses a plot whose `x` is neither a swept key nor a metric, or whose `file` would land
    /// outside the output directory (absolute, or climbing out with `..`).
    pub fn check_plots(&self, runs: &[PlannedRun]) -> anyhow::Result<()> {
        for (i, p) in self.plot.iter().enumerate() {
            let swept = runs.iter().any(|r| r.x.contains_key(&p.x));
            if !swept && Metric::from_name(&p.x).is_none() {
                let mut keys: Vec<&str> = self
                    .series
                    .iter()
                    .flat_map(|s| s.vary.keys().map(String::as_str))
                    .collect();
                keys.sort_unstable();
                keys.dedup();
                bail!(
                    "plot[{i}].x: `{}` is neither a swept key ({}) nor a metric",
                    weft_scene::elide(&p.x),
                    if keys.is_empty() {
                        "none".to_owned()
                    } else {
                        keys.join(", ")
                    }
                );
            }
            let file = Path::new(&p.file);
            let inside = !p.file.is_empty()
                && file
                    .components()
                    .all(|c| matches!(c, std::path::Component::Normal(_)));
            if !inside {
                bail!(
                    "plot[{i}].file: `{}` must be a relative path inside the output directory \
                     (no leading `/`, no `..`)",
                    weft_scene::elide(&p.file)
                );
            }
        }
        Ok(())
    }

    /// Every run, in queue order.
    pub fn expand(&self) -> anyhow::Result<Vec<PlannedRun>> {
        let ov = |k: &str, v: &Value| -> anyhow::Result<Override> {
            Ok(format!("{k}={}", toml_text(v)).parse::<Override>()?)
        };
        let mut runs = Vec::new();
        for s in &self.series {
            let mut combos: Vec<Vec<(&String, &Value)>> = vec![vec![]];
            for (k, values) in &s.vary {
                if values.is_empty() {
                    bail!("series `{}`: vary.{k} is empty", s.name);
                }
                combos = combos
                    .into_iter()
                    .flat_map(|c| {
                        values.iter().map(move |v| {
                            let mut c = c.clone();
                            c.push((k, v));
                            c
                        })
                    })
                    .collect();
            }
            for combo in combos {
                let mut overrides = Vec::new();
                for (k, v) in self.set.iter().chain(&s.set) {
                    overrides.push(ov(k, v)?);
                }
                let mut x = BTreeMap::new();
                let mut label = Vec::new();
                for (k, v) in combo {
                    overrides.push(ov(k, v)?);
                    if let Some(n) = numeric(v) {
                        x.insert(k.clone(), n);
                    }
                    label.push(format!("{k}={}", plain(v)));
                }
                runs.push(PlannedRun {
                    index: runs.len(),
                    series: s.name.clone(),
                    label: label.join(" "),
                    overrides,
                    x,
                });
            }
        }
        Ok(runs)
    }
}

/// Parses `K/N` (K in 0..N).
pub fn parse_shard(s: &str) -> anyhow::Result<(usize, usize)> {
    let (k, n) = s.split_once('/').context("--shard takes K/N, e.g. 0/4")?;
    let (k, n): (usize, usize) = (k.trim().parse()?, n.trim().parse()?);
    if n == 0 || k >= n {
        bail!("--shard {s}: need N >= 1 and K in 0..N");
    }
    Ok((k, n))
}
