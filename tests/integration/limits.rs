//! Limits stated before the machine runs out: physical ranges with reasons in `check`, memory
//! estimated before any cloth is built, file sizes capped, long sweeps asked for, `--jobs` and
//! `--shard` checked before anything is made.

use crate::common;

use common::*;

fn check(text: &str, extra: &[&str]) -> (Option<i32>, String, String) {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let dir = temp_dir(&format!("limits-check-{n}"));
    let path = write(&dir, "s.toml", text);
    let mut args = vec!["check", path.as_str()];
    args.extend_from_slice(extra);
    let out = run(&args);
    let (o, e) = texts(&out);
    assert!(!e.contains("panicked"), "{e}");
    (out.status.code(), o, e)
}

#[test]
fn values_that_overflow_the_solver_are_refused_with_their_range() {
    let cases = [
        ("sim.dt", SMALL.replace("dt = \"1/60\"", "dt = 1e-300")),
        (
            "cloth.flag.mass",
            SMALL.replace("mass = 0.1", "mass = 1e-320"),
        ),
        (
            "cloth.flag.stretch_compliance",
            format!("{SMALL}stretch_compliance = 1.797e308\n"),
        ),
        (
            "cloth.flag.size",
            SMALL.replace("size = [0.5, 0.5]", "size = [1e-300, 1e-300]"),
        ),
        (
            "cloth.flag.center",
            SMALL.replace("center = [0.0, 1.0, 0.0]", "center = [0.0, 1e308, 0.0]"),
        ),
    ];
    for (key, text) in cases {
        let (code, _, e) = check(&text, &[]);
        assert_eq!(code, Some(1), "{key}: {e}");
        assert!(e.contains(key) && e.contains("out of range"), "{key}: {e}");
        // The reason is given, and the value is short.
        assert!(e.contains('(') && e.len() < 600, "{key}: {e}");
        assert!(
            !e.contains("00000000000000000000"),
            "{key}: value written out: {e}"
        );
    }
    let (code, _, e) = check(
        SMALL,
        &[
            "--set",
            "sim.substeps=100000",
            "--set",
            "sim.iterations=100000",
        ],
    );
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("constraint sweeps per frame"), "{e}");
}

#[test]
fn a_scene_too_big_for_the_memory_is_refused_before_it_is_built() {
    let text = big(1024).replace(
        "[cloth.flag]",
        "[cloth.other]\nresolution = [1024, 1024]\n\n[cloth.flag]",
    );
    let (code, o, e) = check(&text, &["--max-memory", "512M"]);
    assert_eq!(code, Some(1), "{o}{e}");
    assert!(
        e.contains("resolution") && e.contains("2097152 particles") && e.contains("512 MiB"),
        "{e}"
    );
    assert!(e.contains("--max-memory"), "{e}");
    // The same scene with room passes the estimate (built on a smaller grid to stay quick).
    let (code, o, e) = check(&big(64), &["--max-memory", "512M"]);
    assert_eq!(code, Some(0), "{o}{e}");
}

#[test]
fn a_contact_list_too_big_for_the_memory_names_the_thickness_and_what_it_pairs() {
    // A 96² sheet 0.2 m thick: gigabytes of listed pairs under either contact (mesh about
    // 24 GiB, particles about 3.8).
    let scene = |contact: &str| {
        format!(
            "[cloth.c]\nresolution = [96, 96]\nthickness = 0.2\n\n\
             [self_collision]\ncontact = \"{contact}\"\n"
        )
    };
    for (contact, pairs) in [
        ("mesh", "pairs of elements (vertex–triangle and edge–edge)"),
        ("particles", "pairs of particles"),
    ] {
        let (code, o, e) = check(&scene(contact), &["--max-memory", "1G"]);
        assert_eq!(code, Some(1), "{contact}: {o}{e}");
        assert!(
            e.contains(":3: cloth.c.thickness") && e.contains(pairs) && e.contains("--max-memory"),
            "{contact}: {e}"
        );
    }
}

#[test]
fn mesh_files_above_the_cap_and_devices_are_refused() {
    let dir = temp_dir("mesh-cap");
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    obj.push_str(&"# padding\n".repeat(200));
    obj.push_str("f 1 2 3\n");
    write(&dir, "m.obj", &obj);
    let scene = write(&dir, "s.toml", "[cloth.c]\nmesh = \"m.obj\"\nmass = 0.2\n");
    let out = run(&["check", &scene, "--max-file-size", "1K"]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("cloth.c.mesh") && e.contains("limit of 1024"),
        "{e}"
    );
    let out = run(&["check", &scene]);
    assert!(out.status.success(), "{:?}", texts(&out));
    let zero = write(
        &dir,
        "z.toml",
        "[cloth.c]\nmesh = \"/dev/zero\"\nmass = 0.2\n",
    );
    let out = run(&["check", &zero]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("not a regular file"), "{e}");
}

#[test]
fn an_obj_coordinate_beyond_float32_is_out_of_range_not_non_finite() {
    let dir = temp_dir("obj-far");
    write(&dir, "m.obj", "v 0 0 0\nv 1e308 0 0\nv 0 1 0\nf 1 2 3\n");
    let scene = write(&dir, "s.toml", "[cloth.c]\nmesh = \"m.obj\"\nmass = 0.2\n");
    let out = run(&["check", &scene]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("m.obj:2") && e.contains("out of range"), "{e}");
    assert!(!e.contains("non-finite"), "{e}");
}

fn experiments_file(dir: &std::path::Path, name: &str, vary: &str, plot: &str) -> String {
    write(dir, "small.toml", SMALL);
    write(
        dir,
        name,
        &format!(
            "scene = \"small.toml\"\nframes = 3\nmetrics = [\"sag\"]\n\n[[series]]\nname = \"s\"\nvary = {vary}\n{plot}"
        ),
    )
}

#[test]
fn a_huge_sweep_asks_for_yes_and_jobs_and_shards_are_checked_first() {
    let dir = temp_dir("sweep-limits");
    let values = format!(
        "[{}]",
        (1..=1000)
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let exp = experiments_file(
        &dir,
        "huge.toml",
        &format!(
            "{{ \"sim.substeps\" = {values}, \"sim.iterations\" = {values}, \"sim.damping\" = {values} }}"
        ),
        "",
    );
    let out_dir = dir.join("out");
    let o = out_dir.to_string_lossy().into_owned();
    let out = run(&["experiments", &exp, "--out", &o]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("1000000000 runs"), "{e}");
    assert!(!out_dir.exists(), "nothing made for a refused queue");

    let exp = experiments_file(&dir, "two.toml", "{ \"sim.substeps\" = [1, 2] }", "");
    let small_sweep = {
        let vals = format!(
            "[{}]",
            (1..=40)
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        experiments_file(
            &dir,
            "long.toml",
            &format!("{{ \"sim.substeps\" = {vals}, \"sim.iterations\" = {vals} }}"),
            "",
        )
    };
    let out = run(&["experiments", &small_sweep, "--out", &o]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("1600 runs") && e.contains("--yes"), "{e}");
    assert!(!out_dir.exists());

    let out = run(&["experiments", &exp, "--out", &o, "--jobs", "0"]);
    assert_eq!(out.status.code(), Some(2), "{:?}", texts(&out));
    let out = run(&["experiments", &exp, "--out", &o, "--shard", "5/3"]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(!out_dir.exists(), "--shard 5/3 made {}", out_dir.display());

    let out = run(&["experiments", &exp, "--out", &o, "--jobs", "100000"]);
    let (so, e) = texts(&out);
    assert!(out.status.success(), "{so}{e}");
    assert!(e.contains("--jobs 100000 cut to"), "{e}");
}

#[test]
fn the_memory_limit_covers_the_runs_that_run_at_once() {
    let dir = temp_dir("queue-memory");
    // 128² = 16384 particles: about 19 MiB each once built, beside the process's 32 MiB:
    // 51 MiB for one run, 71 MiB for two at once.
    write(&dir, "mid.toml", &big(128));
    let exp = write(
        &dir,
        "q.toml",
        "scene = \"mid.toml\"\nframes = 1\nmetrics = [\"sag\"]\n\n[[series]]\nname = \"s\"\n\
         vary = { \"sim.substeps\" = [1, 2] }\n",
    );
    let o = dir.join("out").to_string_lossy().into_owned();
    let args = |jobs: &'static str| {
        vec![
            "experiments".to_owned(),
            exp.clone(),
            "--out".into(),
            o.clone(),
            "--no-mcap".into(),
            "--max-memory".into(),
            "60M".into(),
            "--jobs".into(),
            jobs.into(),
        ]
    };
    let two: Vec<String> = args("2");
    let out = run(&two.iter().map(String::as_str).collect::<Vec<_>>());
    let (so, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{so}{e}");
    assert!(
        e.contains("2 runs at a time") && e.contains("--jobs") && e.contains("60 MiB"),
        "{e}"
    );
    assert!(
        !dir.join("out").join("results").join("run-0.json").exists(),
        "no run started"
    );
    let one: Vec<String> = args("1");
    let out = run(&one.iter().map(String::as_str).collect::<Vec<_>>());
    let (so, e) = texts(&out);
    assert!(out.status.success(), "one at a time fits: {so}{e}");
}

/// A size as `human` prints it ("154 MiB", "2.1 GiB"), in bytes.
fn parse_human(s: &str) -> f64 {
    let (n, unit) = s.trim().split_once(' ').expect("number and unit");
    let n: f64 = n.parse().expect("a number");
    n * match unit {
        "MiB" => (1u64 << 20) as f64,
        "GiB" => (1u64 << 30) as f64,
        other => panic!("unit {other}"),
    }
}

/// Runs `scene` for 5 frames with a log (and `extra` arguments); its peak memory and the
/// estimate it printed.
fn peak_and_estimate(scene: &str, extra: &[&str], dir: &std::path::Path) -> (f64, f64) {
    let log = dir.join("a.mcap");
    let mut args = vec![
        "run",
        scene,
        "--frames",
        "5",
        "--out",
        log.to_str().expect("utf-8 path"),
    ];
    args.extend_from_slice(extra);
    let out = run(&args);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{scene}: {e}");
    let line = o
        .lines()
        .find_map(|l| l.strip_prefix("memory: peak "))
        .unwrap_or_else(|| panic!("{scene}: no memory line in {o}"));
    let (peak, estimate) = line.split_once(", estimated ").expect("peak, estimate");
    (parse_human(peak), parse_human(estimate))
}

#[test]
fn peak_memory_stays_within_the_estimate_on_every_shipped_scene_and_thick_cloths() {
    let dir = temp_dir("peak-memory");
    let mut scenes: Vec<String> = std::fs::read_dir("assets/scenes")
        .expect("scenes")
        .map(|e| e.expect("entry").path().to_string_lossy().into_owned())
        .filter(|p| p.ends_with(".toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 10, "{scenes:?}");
    // Particle contact's lists that hold most pairs of particles: the estimate counts them.
    let sheet = |name: &str, n: usize, y: f64, t: f64| {
        format!(
            "[cloth.{name}]\nresolution = [{n}, {n}]\norientation = \"horizontal\"\n\
             center = [0.0, {y}, 0.0]\nthickness = {t}\n\n"
        )
    };
    // 1 m thick, as thick as a 1 m sheet may be: every pair within reach.
    let particles = "[self_collision]\ncontact = \"particles\"\n";
    let two = sheet("a", 48, 1.001, 1.0) + &sheet("b", 48, 1.0, 1.0) + particles;
    scenes.push(write(&dir, "two.toml", &two));
    scenes.push(write(
        &dir,
        "thick.toml",
        &(sheet("a", 96, 1.0, 0.5) + particles),
    ));
    // A large grid with every constraint family under each method: what the methods add per
    // particle dwarfs the process (the implicit method's peak was 2.3 times a one-size estimate).
    for method in ["xpbd", "mass-spring", "implicit-mass-spring"] {
        let grid = format!(
            "[sim]\nmethod = \"{method}\"\n\n[cloth.c]\nresolution = [320, 320]\n\
             orientation = \"horizontal\"\nbend_distance_enabled = true\n\
             bend_dihedral_enabled = true\ntether_enabled = true\n"
        );
        scenes.push(write(&dir, &format!("{method}.toml"), &grid));
    }
    for scene in &scenes {
        // `explode.toml` shows mass-spring blowing up; with enough substeps it runs on.
        let extra: &[&str] = if scene.ends_with("explode.toml") {
            &["--set", "sim.substeps=60"]
        } else {
            &[]
        };
        let (peak, estimate) = peak_and_estimate(scene, extra, &dir);
        println!(
            "{scene}: peak {:.0} MiB, estimate {:.0} MiB",
            peak / 1048576.0,
            estimate / 1048576.0
        );
        assert!(
            peak <= 1.5 * estimate,
            "{scene}: peak {peak} > 1.5 × {estimate}"
        );
    }
}
