//! Bad scene files and arguments: a clear message naming file, line and key, a non-zero
//! exit, and never a panic.

use crate::common;

use common::*;

/// Runs `weft check` on `text` (with extra args) and returns stderr, asserting failure.
fn check_fails(name: &str, text: &str, extra: &[&str]) -> (String, String) {
    let dir = temp_dir(&format!("bad-{name}"));
    let path = write(&dir, "scene.toml", text);
    let mut args = vec!["check", path.as_str()];
    args.extend_from_slice(extra);
    let out = run(&args);
    let (_, err) = texts(&out);
    assert!(!out.status.success(), "{name}: must fail, stderr: {err}");
    assert_eq!(out.status.code(), Some(1), "{name}: {err}");
    assert!(!err.contains("panicked"), "{name}: panicked: {err}");
    (path, err)
}

#[test]
fn every_shipped_scene_checks() {
    for entry in std::fs::read_dir("assets/scenes").expect("scenes") {
        let path = entry.expect("entry").path();
        let out = run(&["check", &path.to_string_lossy()]);
        let (o, e) = texts(&out);
        assert!(out.status.success(), "{}: {o}{e}", path.display());
    }
}

#[test]
fn unknown_key_names_line_and_suggests() {
    let text = SMALL.replace("substeps = 4", "substepz = 4");
    let (path, err) = check_fails("unknown", &text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:4: sim.substepz: unknown key `substepz` (did you mean `substeps`?)"
        )),
        "{err}"
    );
}

#[test]
fn wrong_type_names_line_and_key() {
    let text = format!("{SMALL}stretch_compliance = \"soft\"\n");
    let (path, err) = check_fails("type", &text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:13: cloth.flag.stretch_compliance: invalid type"
        )),
        "{err}"
    );
}

#[test]
fn nan_and_negative_values_are_rejected_with_their_lines() {
    let text = format!("{SMALL}stretch_compliance = nan\n").replace("mass = 0.1", "mass = -1.0");
    let (path, err) = check_fails("nan", &text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:13: cloth.flag.stretch_compliance: must be finite and >= 0, got NaN"
        )),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "{path}:11: cloth.flag.mass: out of range: must be in [1e-6, 1e6] kg"
        )),
        "{err}"
    );
}

#[test]
fn missing_mesh_file_is_named() {
    let text = "[cloth.shirt]\nmesh = \"no/such/shirt.obj\"\nmass = 0.2\n";
    let (path, err) = check_fails("mesh", text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:2: cloth.shirt.mesh: cannot read mesh file `no/such/shirt.obj`"
        )),
        "{err}"
    );
}

#[test]
fn malformed_cloth_mesh_names_scene_key_and_obj_line() {
    let dir = temp_dir("bad-obj");
    write(&dir, "shirt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    let scene = write(
        &dir,
        "scene.toml",
        "[cloth.shirt]\nmesh = \"shirt.obj\"\nmass = 0.2\n",
    );
    let out = run(&["check", &scene]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("{scene}:2: cloth.shirt.mesh: bad mesh:")),
        "{err}"
    );
    assert!(
        err.contains("shirt.obj:4: face uses vertex 7 (OBJ counts from 1), but only 3 vertices"),
        "{err}"
    );
}

#[test]
fn bad_collider_values_are_named() {
    let text = format!(
        "{SMALL}\n[[collider]]\nshape = \"sphere\"\nradius = -0.5\n\n[[collider]]\nshape = \"cuboid\"\nradius = 1.0\n"
    );
    let (path, err) = check_fails("collider", &text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:16: collider[0].radius: must be finite and > 0, got -0.5"
        )),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "{path}:20: collider[1].radius: not used by a cuboid shape"
        )),
        "{err}"
    );
    assert!(err.contains("collider[1].half_extents: missing"), "{err}");
}

#[test]
fn absurd_grids_are_refused_without_overflow() {
    let text =
        "[cloth.a]\nresolution = [9223372036854775807, 9223372036854775807]\npins = [5, -1]\n";
    let (path, err) = check_fails("absurd", text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:2: cloth.a.resolution: each count must be in 2..=4096"
        )),
        "{err}"
    );
    assert!(
        err.contains("cloth.a.pins[1]: vertex -1 does not exist"),
        "{err}"
    );
}

#[test]
fn invalid_toml_is_reported_with_its_line() {
    let text = SMALL.replace("damping = 0.1", "damping = = 0.1");
    let (path, err) = check_fails("syntax", &text, &[]);
    assert!(err.contains(&format!("{path}:5: not valid TOML")), "{err}");
}

#[test]
fn command_line_overrides_are_reported_as_such() {
    let (_, err) = check_fails("set", SMALL, &["--set", "sim.substeps=0"]);
    assert!(
        err.contains("command line (--set sim.substeps): sim.substeps: must be an integer in 1..=100000, got 0"),
        "{err}"
    );
    let (_, err) = check_fails(
        "set2",
        SMALL,
        &["--set", "cloth.flag.stretch_compliance=-1"],
    );
    assert!(
        err.contains("command line (--set cloth.flag.stretch_compliance)"),
        "{err}"
    );
    let out = run(&["check", "assets/scenes/hanging.toml", "--set", "nonsense"]);
    assert!(!out.status.success());
    assert!(texts(&out).1.contains("KEY=VALUE"));
}

#[test]
fn overrides_never_add_a_cloth_or_a_list_entry() {
    // A typo for the cloth `flag` used to add a second cloth; a negative index used to blame
    // a line past the end of the file.
    let (path, err) = check_fails("set-cloth", SMALL, &["--set", "cloth.flg.mass=5"]);
    assert!(
        err.contains(
            "command line (--set cloth.flg.mass): cloth.flg.mass: no cloth named `flg` in the \
             scene (did you mean `flag`?); its cloths: flag"
        ),
        "{err}"
    );
    let out = run(&["check", &path, "--set", "collider[-1].radius=1"]);
    let (_, err) = texts(&out);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains(
            "command line (--set collider[-1].radius): collider[-1].radius: [-1] is a negative \
             index, which is not valid"
        ),
        "{err}"
    );
    assert!(!err.contains(&format!("{path}:")), "{err}");
    let (_, err) = check_fails("set-list", SMALL, &["--set", "collider[0].radius=1"]);
    assert!(
        err.contains(
            "collider[0].radius: the scene has no `collider` entries, so [0] does not exist"
        ),
        "{err}"
    );
    // Sections the file lacks are still made.
    let dir = temp_dir("set-sections");
    let cloth = SMALL.find("[cloth.flag]").expect("a cloth");
    let bare = write(&dir, "bare.toml", &SMALL[cloth..]);
    for set in [
        "self_collision.enabled=true",
        "sim.substeps=20",
        "wind.aero.drag_coefficient=1",
    ] {
        let out = run(&["check", &bare, "--set", set]);
        assert!(out.status.success(), "{set}: {:?}", texts(&out));
    }
}

#[test]
fn arrays_of_the_wrong_length_and_duplicate_keys_name_file_line_and_key() {
    let text = SMALL.replace("resolution = [8, 8]", "resolution = [8, 8, 1]");
    let (path, err) = check_fails("length", &text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:8: cloth.flag.resolution: takes 2 values, got 3"
        )),
        "{err}"
    );
    let text = SMALL.replace("damping = 0.1", "damping = 0.1\ndt = 0.02");
    let (path, err) = check_fails("duplicate", &text, &[]);
    assert!(
        err.contains(&format!(
            "{path}:6: sim.dt: duplicate key: first defined on line 3, again on line 6"
        )),
        "{err}"
    );
}

#[test]
fn missing_scene_file_fails_cleanly() {
    let out = run(&["run", "no/such/scene.toml", "--frames", "1"]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("no/such/scene.toml: cannot read the scene file"),
        "{err}"
    );
}

#[test]
fn unwritable_output_fails_before_the_run() {
    let out = run(&[
        "run",
        "--frames",
        "100000",
        "--out",
        "/no/such/dir/run.mcap",
    ]);
    let (o, err) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot write /no/such/dir/run.mcap"), "{err}");
    assert!(!o.contains("frames,"), "simulated anyway: {o}");
}

#[test]
fn check_explain_prints_the_scene_with_every_default() {
    let out = run(&["check", "--explain", "assets/scenes/minimal.toml"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    for key in [
        "[cloth.flag]",
        "iterations = 1",
        "thickness = 0.005",
        "bend_isometric_compliance = ",
        "rotation_deg = [0.0, 0.0, 0.0]",
    ] {
        assert!(o.contains(key), "{key} missing from:\n{o}");
    }
    assert!(
        !o.contains("memory:"),
        "the summary instead of the scene:\n{o}"
    );
}
