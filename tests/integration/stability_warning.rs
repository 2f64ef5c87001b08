//! A scene past its explicit springs' stability limit is warned about before `run`, `view`,
//! `render` and `experiments` start, in the words `weft check` uses; `run --strict` refuses
//! it; `check` and `render` take `--method` as `run` and `view` do.

use crate::common;

use common::{run, temp_dir, texts, weft, write};

/// Stiff springs (k = 2,000 N/m on 16 × 16 particles of 0.3 kg in all) at 4 substeps of
/// 1/60 s: explicit mass-spring is far past its limit; XPBD is not bound by it.
const STIFF: &str = r#"[sim]
dt = "1/60"
substeps = 4

[cloth.stiff]
resolution = [16, 16]
size = [1.0, 1.0]
center = [0.0, 1.5, 0.0]
mass = 0.3
pins = ["top-left", "top-right"]
stretch_spring_stiffness = 2000.0
shear_spring_stiffness = 800.0
"#;

const WARNING: &str = "will explode: use sim.substeps >=";

fn scene(name: &str) -> (std::path::PathBuf, String) {
    let dir = temp_dir(name);
    let scene = write(&dir, "stiff.toml", STIFF);
    (dir, scene)
}

#[test]
fn check_takes_method_and_warns_past_the_limit() {
    let (_, scene) = scene("warn-check");
    let out = run(&["check", &scene, "--method", "mass-spring"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(o.contains("methods: mass-spring"), "{o}");
    assert!(o.contains(WARNING), "{o}");
    let out = run(&["check", &scene, "--method", "xpbd"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(!o.contains("warning"), "{o}");
}

#[test]
fn run_warns_before_it_starts_and_strict_refuses() {
    let (dir, scene) = scene("warn-run");
    let out = run(&["run", &scene, "--method", "mass-spring", "--frames", "1"]);
    let (_, e) = texts(&out);
    let warning = e.find(WARNING).unwrap_or_else(|| panic!("no warning: {e}"));
    let started = e.find("cloth(s),").expect("the run's first line");
    assert!(
        e[..warning].contains("weft: warning: cloth `stiff` (mass-spring)"),
        "{e}"
    );
    assert!(warning < started, "the warning comes first: {e}");
    // --strict: an error, nothing run, no log.
    let log = dir.join("run.mcap");
    let out = run(&[
        "run",
        &scene,
        "--method",
        "mass-spring",
        "--strict",
        "--out",
        &log.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{o}{e}");
    assert!(e.contains(WARNING) && e.contains("--strict"), "{e}");
    assert!(!o.contains("frames"), "{o}");
    assert!(!log.exists(), "nothing was run, so no log");
    // Within the limit: no warning, and --strict runs it.
    let out = run(&["run", &scene, "--strict", "--frames", "2", "-q"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(!e.contains("warning"), "{e}");
}

#[test]
fn view_warns_before_it_opens_a_window() {
    let (_, scene) = scene("warn-view");
    let out = weft()
        .args(["view", &scene, "--method", "mass-spring"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .expect("weft starts");
    let (_, e) = texts(&out);
    assert!(e.contains(WARNING), "{e}");
}

#[test]
fn render_takes_method_and_warns() {
    let (dir, scene) = scene("warn-render");
    let images = dir.join("images");
    let out = run(&[
        "render",
        &scene,
        "--method",
        "mass-spring",
        "--frames",
        "1",
        "--size",
        "64x64",
        "--out",
        &images.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    assert!(e.contains(WARNING), "{o}{e}");
    assert!(e.contains("cloth `stiff` (mass-spring)"), "{e}");
}

#[test]
fn experiments_warn_before_each_run_past_the_limit() {
    let (dir, _) = scene("warn-experiments");
    let exp = write(
        &dir,
        "exp.toml",
        r#"title = "stiff"
scene = "stiff.toml"
frames = 1
metrics = ["frames"]

[[series]]
name = "springs"
set = { "sim.method" = "mass-spring" }
vary = { "sim.substeps" = [4, 200] }
"#,
    );
    let out = run(&[
        "experiments",
        &exp,
        "--out",
        &dir.join("out").to_string_lossy(),
        "--no-mcap",
        "--jobs",
        "1",
    ]);
    let (o, e) = texts(&out);
    let warned: Vec<&str> = e.lines().filter(|l| l.contains(WARNING)).collect();
    assert_eq!(warned.len(), 1, "{o}{e}");
    assert!(warned[0].contains("run   0 springs"), "{e}");
}

#[test]
fn a_diverged_run_prints_no_exploded_lowest_point() {
    let (_, scene) = scene("diverged-summary");
    let out = run(&["run", &scene, "--method", "mass-spring", "--frames", "3"]);
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(2), "{o}{e}");
    assert!(o.contains("lowest point y = — (diverged)"), "{o}");
    assert!(e.contains("diverged at frame"), "{e}");
}
