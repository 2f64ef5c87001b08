//! The recorder keeps what it did: each run's result is written when the run ends (a killed
//! queue keeps them), `--resume` skips runs that have one, runs never started are `not run`
//! (never zeros), and a bad plot is refused before the first run.

use crate::common;

use std::process::Stdio;
use std::time::Duration;

use common::*;

/// An experiments file over `runs` runs of a scene big enough that each takes a while.
fn queue(dir: &std::path::Path, n: usize, runs: usize, plot: &str) -> String {
    write(dir, "s.toml", &big(n));
    let values = (1..=runs)
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    write(
        dir,
        "exp.toml",
        &format!(
            "scene = \"s.toml\"\nframes = 20\nmetrics = [\"sag\", \"cost\"]\n\n[[series]]\nname = \"s\"\nvary = {{ \"sim.iterations\" = [{values}] }}\n{plot}"
        ),
    )
}

fn results(dir: &std::path::Path) -> usize {
    std::fs::read_dir(dir.join("results")).map_or(0, |d| {
        d.filter(|e| {
            e.as_ref().is_ok_and(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.ends_with(".json") && !name.contains(".partial")
            })
        })
        .count()
    })
}

#[test]
fn a_killed_queue_keeps_its_results_and_resume_skips_them() {
    let dir = temp_dir("recorder-kill");
    let exp = queue(&dir, 24, 40, "");
    let out_dir = dir.join("out");
    let child = weft()
        .args(["experiments", &exp, "--jobs", "1", "--no-mcap", "--out"])
        .arg(&out_dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("starts");
    let some = wait_for(Duration::from_secs(120), || results(&out_dir) >= 3);
    signal(child.id(), "KILL");
    let _ = exits_within(child, Duration::from_secs(10));
    assert!(some, "no result written while the queue ran");
    let kept = results(&out_dir);
    assert!(kept < 40, "the queue finished before the kill");
    let out = weft()
        .args([
            "experiments",
            &exp,
            "--jobs",
            "2",
            "--no-mcap",
            "--resume",
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .expect("runs");
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(
        e.contains(&format!("--resume: {kept} of 40 runs already have results")),
        "{e}"
    );
    assert!(e.contains(&format!("{} of 40 runs", 40 - kept)), "{e}");
    assert!(o.contains("40 of 40 runs have results"), "{o}");
}

#[test]
fn runs_never_started_are_not_run_never_zero() {
    let dir = temp_dir("recorder-int");
    let exp = queue(&dir, 24, 40, "");
    let out_dir = dir.join("out");
    let child = weft()
        .args(["experiments", &exp, "--jobs", "1", "--no-mcap", "--out"])
        .arg(&out_dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    assert!(wait_for(Duration::from_secs(120), || results(&out_dir) >= 2));
    signal(child.id(), "INT");
    let (out, _) = exits_within(child, Duration::from_secs(30));
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(130), "{o}{e}");
    let csv = std::fs::read_to_string(out_dir.join("summary.csv")).expect("summary");
    assert_eq!(
        csv.lines().count(),
        41,
        "every planned run has a row: {csv}"
    );
    let not_run: Vec<&str> = csv.lines().filter(|l| l.contains(",not run,")).collect();
    assert!(!not_run.is_empty(), "{csv}");
    for line in not_run {
        assert!(
            line.ends_with(",not run,,"),
            "no values for a run never made: {line}"
        );
    }
    assert!(!csv.contains(",0,0"), "{csv}");
}

#[test]
fn a_misspelt_plot_key_and_an_escaping_plot_file_are_refused_first() {
    let dir = temp_dir("recorder-plot");
    for (plot, expected) in [
        (
            "[[plot]]\nfile = \"p.png\"\nx = \"sim.iteratoins\"\ny = \"sag\"\n",
            "plot[0].x: `sim.iteratoins` is neither a swept key (sim.iterations) nor a metric",
        ),
        (
            "[[plot]]\nfile = \"/tmp/weft-escape.png\"\nx = \"sim.iterations\"\ny = \"sag\"\n",
            "plot[0].file",
        ),
        (
            "[[plot]]\nfile = \"../escape.png\"\nx = \"sim.iterations\"\ny = \"sag\"\n",
            "plot[0].file",
        ),
    ] {
        let exp = queue(&dir, 8, 2, plot);
        let out_dir = dir.join("out");
        let out = run(&["experiments", &exp, "--out", &out_dir.to_string_lossy()]);
        let (_, e) = texts(&out);
        assert_eq!(out.status.code(), Some(1), "{e}");
        assert!(e.contains(expected), "{e}");
        assert!(!out_dir.join("runs").exists(), "refused after runs began");
    }
    assert!(!dir.join("escape.png").exists());
}
