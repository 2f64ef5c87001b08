//! `weft fabric`: a lab's measurements become a material table a scene accepts, the virtual
//! cantilever reads each direction's bending length back, and bad measurements are named.

use crate::common::*;

#[test]
fn measurements_become_a_material_the_virtual_cantilever_reads_back() {
    let out = run(&[
        "fabric",
        "--weight",
        "130",
        "--bending-length-warp",
        "2.0",
        "--bending-length-weft",
        "1.5",
        "--extension-warp",
        "4",
        "--extension-weft",
        "8",
    ]);
    let (stdout, stderr) = texts(&out);
    assert!(out.status.success(), "{stdout}{stderr}");
    // Every line but the table is a TOML comment: the output pastes into a cloth table.
    let table: Vec<&str> = stdout.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(table.len(), 1, "{stdout}");
    assert!(
        table[0].starts_with("material = { density = 130.0"),
        "{stdout}"
    );
    let dir = temp_dir("fabric");
    let scene = write(
        &dir,
        "strip.toml",
        &format!(
            "[sim]\nsubsteps = 10\n\n[cloth.c]\nresolution = [12, 12]\n{}\n",
            table[0]
        ),
    );
    let check = run(&["check", &scene]);
    assert!(check.status.success(), "{:?}", texts(&check));
    // Each direction's bending length comes back within 3 % (about 2° of chord).
    for direction in ["warp", "weft"] {
        let line = (stdout.lines())
            .find(|l| l.contains(&format!("{direction}: bending length")))
            .unwrap_or_else(|| panic!("no {direction} reading in {stdout}"));
        let percent: f64 = line
            .split('(')
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|p| p.trim_end_matches('%').parse().ok())
            .unwrap_or_else(|| panic!("no percentage in {line}"));
        assert!(percent.abs() < 3.0, "{line}");
    }
    assert!(!stderr.contains("warning"), "{stderr}");
}

#[test]
fn bad_measurements_are_refused_naming_the_option() {
    let base = [
        ("--weight", "130"),
        ("--bending-length-warp", "2.0"),
        ("--extension-warp", "4"),
    ];
    let args = |replace: Option<(&'static str, &'static str)>| {
        let mut v = vec!["fabric", "--no-check"];
        for (f, x) in base {
            if replace.is_none_or(|(r, _)| r != f) {
                v.extend([f, x]);
            }
        }
        v.extend(replace.map(|(f, x)| [f, x]).into_iter().flatten());
        v
    };
    let ok = run(&args(None));
    assert!(ok.status.success(), "{:?}", texts(&ok));
    for (flag, value, expect) in [
        ("--weight", "0", "--weight: must be finite and > 0"),
        (
            "--extension-weft",
            "-2",
            "--extension-weft: must be finite and > 0",
        ),
        ("--shear", "nan", "--shear: must be finite and > 0"),
        ("--load", "inf", "--load: must be finite and > 0"),
        (
            "--bending-length-weft",
            "15",
            "--bending-length-weft: 15 cm needs a 30 cm overhang",
        ),
    ] {
        let out = run(&args(Some((flag, value))));
        let (stdout, stderr) = texts(&out);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{flag} {value}: {stdout}{stderr}"
        );
        assert!(stderr.contains(expect), "{flag} {value}: {stderr}");
        assert!(!stdout.contains("material ="), "{flag} {value}: {stdout}");
    }
}

#[test]
fn weft_run_reports_xpbds_bending_residual_where_a_fabric_bends() {
    let residual = |set: &[&str]| {
        let mut args = vec!["run", "assets/scenes/hanging.toml", "--frames", "10"];
        args.extend_from_slice(set);
        let out = run(&args);
        let (stdout, stderr) = texts(&out);
        assert!(out.status.success(), "{stdout}{stderr}");
        (stdout.lines())
            .find_map(|l| l.strip_prefix("bending residual (XPBD, last substep): "))
            .map(|rest| {
                let v = rest.split(' ').next().unwrap_or("");
                v.parse::<f64>()
                    .unwrap_or_else(|_| panic!("not a number in {rest}"))
            })
    };
    // Cotton bends through XPBD hinges solved to tolerance: a small residual.
    let cotton = residual(&["--set", "cloth.cloth.material=cotton"]).expect("a residual line");
    assert!((0.0..0.05).contains(&cotton), "{cotton}");
    // Bend-distance constraints (the default scene) and other methods have no hinge residual.
    assert_eq!(residual(&[]), None);
    assert_eq!(
        residual(&["--set", "cloth.cloth.material=cotton", "--method", "pbd"]),
        None
    );
}
