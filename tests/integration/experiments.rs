//! The experiment recorder: sweeps expand, shards split the queue, and the report and plots
//! are rebuilt from every result present.

use crate::common;

use common::*;

#[test]
fn shards_cover_the_queue_and_the_report_gathers_them() {
    let dir = temp_dir("experiments");
    write(&dir, "small.toml", SMALL);
    let exp = write(
        &dir,
        "exp.toml",
        r#"title = "tiny"
scene = "small.toml"
frames = 10
metrics = ["sag", "cost", "stretch_error_max"]
set = { "sim.damping" = 1.0 }

[[series]]
name = "xpbd"
vary = { "sim.substeps" = [1, 4], "sim.dt" = ["1/60", "1/30"] }

[[series]]
name = "pbd"
set = { "sim.method" = "pbd" }
vary = { "sim.substeps" = [1, 4] }

[[plot]]
file = "sag.png"
title = "sag"
x = "sim.substeps"
y = "sag"
log_x = true
"#,
    );
    let out_dir = dir.join("out");
    let o = out_dir.to_string_lossy();
    for shard in ["0/2", "1/2"] {
        let out = run(&[
            "experiments",
            &exp,
            "--out",
            &o,
            "--shard",
            shard,
            "--jobs",
            "1",
        ]);
        assert!(out.status.success(), "{:?}", texts(&out));
    }
    let out = run(&["experiments", &exp, "--out", &o, "--report-only"]);
    let (stdout, e) = texts(&out);
    assert!(out.status.success(), "{stdout}{e}");
    assert!(stdout.contains("6 of 6 runs have results"), "{stdout}");
    let csv = std::fs::read_to_string(out_dir.join("summary.csv")).expect("csv");
    assert_eq!(csv.lines().count(), 7, "{csv}");
    assert!(csv.starts_with("index,series,swept,status,sag,cost,stretch_error_max"));
    assert!(
        csv.contains("\"xpbd\",\"sim.dt=1/30 sim.substeps=4\",complete,"),
        "{csv}"
    );
    let png = std::fs::read(out_dir.join("sag.png")).expect("plot written");
    assert_eq!(&png[1..4], b"PNG");
    let runs = std::fs::read_dir(out_dir.join("runs"))
        .expect("runs")
        .count();
    assert_eq!(runs, 6);
    // A bad shard is refused.
    let out = run(&["experiments", &exp, "--out", &o, "--shard", "2/2"]);
    assert!(!out.status.success());
}

#[test]
fn bad_experiment_runs_are_refused_before_any_simulation() {
    let dir = temp_dir("experiments-bad");
    write(&dir, "small.toml", SMALL);
    let exp = write(
        &dir,
        "exp.toml",
        "scene = \"small.toml\"\nframes = 5\nmetrics = [\"sag\"]\n[[series]]\nname = \"x\"\nvary = { \"sim.substeps\" = [2, -1] }\n",
    );
    let out = run(&[
        "experiments",
        &exp,
        "--out",
        &dir.join("out").to_string_lossy(),
    ]);
    let (_, e) = texts(&out);
    assert!(!out.status.success());
    assert!(e.contains("command line (--set sim.substeps)"), "{e}");
    assert!(!dir.join("out/results/run-0.json").exists());
}

#[test]
fn a_non_finite_set_or_swept_value_is_an_error_naming_its_line_and_key() {
    // serde_json reads NaN and the infinities as null: the run was labelled
    // `sim.damping=null` and the scene got the string "null".
    let dir = temp_dir("experiments-nan");
    write(&dir, "small.toml", SMALL);
    let head = "scene = \"small.toml\"\nframes = 5\nmetrics = [\"sag\"]\n";
    for (name, body, want) in [
        (
            "vary",
            "[[series]]\nname = \"x\"\nvary = { \"sim.damping\" = [0.5, nan] }\n",
            ":6: series[0].vary.\"sim.damping\"[1]: must be a finite number, got nan",
        ),
        (
            "set",
            "set = { \"sim.gravity\" = [0, -inf, 0] }\n[[series]]\nname = \"x\"\n",
            ":4: set.\"sim.gravity\"[1]: must be a finite number, got -inf",
        ),
        (
            "series-set",
            "[[series]]\nname = \"x\"\n[[series]]\nname = \"y\"\n[series.set]\n\"sim.damping\" = +inf\n",
            ":9: series[1].set.\"sim.damping\": must be a finite number, got +inf",
        ),
    ] {
        let exp = write(&dir, &format!("{name}.toml"), &format!("{head}{body}"));
        let out_dir = dir.join(format!("out-{name}"));
        let out = run(&["experiments", &exp, "--out", &out_dir.to_string_lossy()]);
        let (_, e) = texts(&out);
        assert!(!out.status.success(), "{name}: {e}");
        assert!(e.contains(&format!("{exp}{want}")), "{name}: {e}");
        assert!(!e.contains("null"), "{name}: {e}");
        assert!(!out_dir.join("results").exists(), "{name}: ran anyway");
    }
}

#[test]
fn the_cusick_experiment_reports_the_drape_coefficient_by_resolution() {
    let dir = temp_dir("experiments-cusick");
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/cusick.toml");
    let exp = write(
        &dir,
        "exp.toml",
        &format!(
            r#"title = "cusick"
scene = {scene:?}
duration = 1.0
metrics = ["drape_coefficient"]

[[series]]
name = "cotton"
vary = {{ "cloth.specimen.resolution" = [[11, 11], [15, 15]] }}

[[plot]]
file = "dc.png"
title = "dc"
x = "cloth.specimen.resolution"
y = "drape_coefficient"
"#,
            scene = scene.to_string_lossy()
        ),
    );
    let o = dir.join("out");
    let out = run(&[
        "experiments",
        &exp,
        "--out",
        &o.to_string_lossy(),
        "--no-mcap",
    ]);
    let (stdout, e) = texts(&out);
    assert!(out.status.success(), "{stdout}{e}");
    let csv = std::fs::read_to_string(o.join("summary.csv")).expect("csv");
    // The disc has draped a second: less than flat, more than hanging straight down.
    let values: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().and_then(|v| v.parse().ok()).expect(l))
        .collect();
    assert_eq!(values.len(), 2, "{csv}");
    assert!(values.iter().all(|v| (0.1..0.95).contains(v)), "{csv}");
    // The plot's x is the resolution's columns: both points drawn.
    let png = std::fs::read(o.join("dc.png")).expect("plot written");
    assert_eq!(&png[1..4], b"PNG");
}

/// The race's error metrics: a run with the reference's own settings is 0 from it (same
/// bytes), XPBD's error falls as its substeps approach the reference's (convergence), every
/// run of a series appears in the table of the cheapest run to each accuracy, and a metric
/// that needs a reference without a `[reference]` is refused before anything runs.
#[test]
fn runs_are_measured_against_a_converged_reference() {
    let dir = temp_dir("experiments-reference");
    write(&dir, "small.toml", SMALL);
    let body = r#"title = "race"
scene = "small.toml"
frames = 30
metrics = ["shape_error", "trajectory_error", "ms_per_frame"]
set = { "sim.damping" = 0.0, "cloth.flag.orientation" = "horizontal" }

[[series]]
name = "xpbd"
vary = { "sim.substeps" = [1, 4, 16, 64] }

[[series]]
name = "implicit"
set = { "sim.method" = "implicit-mass-spring" }
vary = { "sim.substeps" = [4] }

[[plot]]
file = "front.png"
x = "ms_per_frame"
y = "trajectory_error"
log_x = true
log_y = true
front = true
"#;
    let missing = write(&dir, "missing.toml", body);
    let out = run(&[
        "experiments",
        &missing,
        "--out",
        &dir.join("o1").to_string_lossy(),
    ]);
    let (_, e) = texts(&out);
    assert!(!out.status.success());
    assert!(e.contains("`shape_error` needs a [reference] table"), "{e}");
    assert!(!dir.join("o1/results").exists(), "ran anyway");
    let exp = write(
        &dir,
        "exp.toml",
        &format!("{body}\n[reference]\nset = {{ \"sim.substeps\" = 64 }}\nevery = 2\n"),
    );
    let o = dir.join("o2");
    let out = run(&[
        "experiments",
        &exp,
        "--out",
        &o.to_string_lossy(),
        "--no-mcap",
        "--jobs",
        "1",
    ]);
    let (stdout, e) = texts(&out);
    assert!(out.status.success(), "{stdout}{e}");
    let csv = std::fs::read_to_string(o.join("summary.csv")).expect("csv");
    let value = |series: &str, swept: &str, col: usize| -> f64 {
        let line = csv
            .lines()
            .find(|l| l.contains(&format!("\"{series}\",\"{swept}\"")))
            .unwrap_or_else(|| panic!("{series} {swept}: {csv}"));
        line.split(',')
            .nth(4 + col)
            .and_then(|v| v.parse().ok())
            .expect(line)
    };
    let traj: Vec<f64> = [1, 4, 16, 64]
        .iter()
        .map(|n| value("xpbd", &format!("sim.substeps={n}"), 1))
        .collect();
    assert_eq!(traj[3], 0.0, "the reference's own settings: {csv}");
    assert_eq!(value("xpbd", "sim.substeps=64", 0), 0.0, "{csv}");
    assert!(
        traj[0] > traj[1] && traj[1] > traj[2] && traj[2] > 0.0,
        "{traj:?}"
    );
    assert!(value("implicit", "sim.substeps=4", 1) > 0.0, "{csv}");
    let md = std::fs::read_to_string(o.join("summary.md")).expect("md");
    assert!(
        md.contains("## Cheapest run to each accuracy (front.png)"),
        "{md}"
    );
    assert!(
        md.contains("| trajectory_error ≤ | xpbd | implicit |"),
        "{md}"
    );
    let png = std::fs::read(o.join("front.png")).expect("plot written");
    assert_eq!(&png[1..4], b"PNG");
}
