//! `weft render` through the binary: PNG frames, an animated GIF with the right frame count,
//! and clear errors. Needs a graphics adapter (CI: Mesa lavapipe or llvmpipe); without one
//! these tests fail rather than skip.

use crate::common;

use std::path::Path;

use common::*;
use image::AnimationDecoder;
use image::codecs::gif::GifDecoder;

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("output dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn render_writes_pngs_and_a_playable_gif() {
    let dir = temp_dir("render-sphere");
    let out_dir = dir.join("out");
    // 6 frames at dt = 1/60, every 2nd: 3 images 33 ms apart, each one a GIF frame.
    let out = run(&[
        "render",
        "assets/scenes/sphere_drop.toml",
        "--frames",
        "6",
        "--every",
        "2",
        "--size",
        "160x120",
        "--out",
        &out_dir.to_string_lossy(),
        "-q",
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "stdout: {o}\nstderr: {e}");
    let names = files(&out_dir);
    let pngs: Vec<&String> = names.iter().filter(|n| n.ends_with(".png")).collect();
    assert_eq!(
        pngs,
        ["frame_00000.png", "frame_00001.png", "frame_00002.png"],
        "{names:?}"
    );
    assert!(
        !names.iter().any(|n| n.contains("partial")),
        "no temporary file left: {names:?}"
    );
    let first = image::open(out_dir.join("frame_00000.png"))
        .expect("PNG decodes")
        .to_rgba8();
    let last = image::open(out_dir.join("frame_00002.png"))
        .expect("PNG decodes")
        .to_rgba8();
    assert_eq!(first.dimensions(), (160, 120));
    let distinct: std::collections::HashSet<[u8; 4]> = first.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 50, "not blank: {} colours", distinct.len());
    assert_ne!(first, last, "the cloth falls between the frames");

    let gif_name = names
        .iter()
        .find(|n| n.ends_with(".gif"))
        .unwrap_or_else(|| panic!("a GIF in {names:?}"));
    assert_eq!(gif_name, "sphere_drop.gif");
    let file = std::fs::File::open(out_dir.join(gif_name)).expect("GIF opens");
    let frames = GifDecoder::new(std::io::BufReader::new(file))
        .expect("GIF header decodes")
        .into_frames()
        .collect_frames()
        .expect("every GIF frame decodes");
    assert_eq!(frames.len(), 3);
    for f in &frames {
        assert_eq!(f.buffer().dimensions(), (160, 120));
        let (num, den) = f.delay().numer_denom_ms();
        let ms = f64::from(num) / f64::from(den);
        // 33.3 ms, stored in whole centiseconds.
        assert!((30.0..=40.0).contains(&ms), "delay {ms} ms");
    }
    if o.contains(".mp4") {
        assert!(out_dir.join("sphere_drop.mp4").is_file());
    } else {
        assert!(e.contains("ffmpeg"), "the MP4 skip is logged: {e}");
    }
}

#[test]
fn unwritable_output_fails_with_a_message() {
    let dir = temp_dir("render-unwritable");
    // A directory cannot be made under a regular file, even as root.
    let blocker = write(&dir, "file", "not a directory");
    let target = format!("{blocker}/frames");
    let out = run(&[
        "render", "--frames", "2", "--size", "32x24", "--out", &target, "-q",
    ]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("cannot create output directory"), "{e}");
    assert!(e.contains(&target), "names the path: {e}");
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn bad_render_arguments_are_named() {
    let dir = temp_dir("render-bad-args");
    let out_dir = dir.join("out").to_string_lossy().into_owned();
    let out = run(&["render", "--size", "100by20", "--out", &out_dir]);
    let (_, e) = texts(&out);
    assert!(!out.status.success());
    assert!(e.contains("100by20") && e.contains("--size"), "{e}");

    let out = run(&["render", "--frames", "3", "--every", "5", "--out", &out_dir]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("nothing to render"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn experiments_render_each_run_into_its_directory() {
    let dir = temp_dir("render-experiments");
    write(&dir, "small.toml", SMALL);
    let exp = write(
        &dir,
        "exp.toml",
        "scene = \"small.toml\"\nframes = 12\nmetrics = [\"sag\"]\n[[series]]\nname = \"x\"\nvary = { \"sim.substeps\" = [2, 4] }\n",
    );
    let out_dir = dir.join("out");
    let out = run(&[
        "experiments",
        &exp,
        "--out",
        &out_dir.to_string_lossy(),
        "--no-mcap",
        "--render",
        "--jobs",
        "2",
    ]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    let mut run_dirs: Vec<_> = std::fs::read_dir(out_dir.join("runs"))
        .expect("runs")
        .map(|d| d.expect("entry").path())
        .filter(|p| p.is_dir())
        .collect();
    run_dirs.sort();
    assert_eq!(run_dirs.len(), 2, "{run_dirs:?}");
    for d in &run_dirs {
        // The initial state and 12 frames at 1/60 s, rendered every 2nd for ~30 images/s:
        // frames 0, 2, …, 12, 7 PNGs and 7 GIF frames.
        let names = files(d);
        let pngs = names.iter().filter(|n| n.ends_with(".png")).count();
        assert_eq!(pngs, 7, "{}: {names:?}", d.display());
        let file = std::fs::File::open(d.join("small.gif")).expect("GIF in the run directory");
        let frames = GifDecoder::new(std::io::BufReader::new(file))
            .expect("GIF decodes")
            .into_frames()
            .collect_frames()
            .expect("frames decode");
        assert_eq!(frames.len(), 7);
    }
}

/// The poster's key result on video: an experiment run whose springs explode in the first frame
/// is recorded as diverged, keeps a video (the initial state, then that frame held and marked)
/// and says why beside it, instead of failing the run.
#[test]
fn an_experiment_run_that_diverges_at_once_keeps_its_marked_video() {
    let dir = temp_dir("render-diverged");
    write(&dir, "small.toml", SMALL);
    let exp = write(
        &dir,
        "exp.toml",
        r#"title = "explodes"
scene = "small.toml"
frames = 4
metrics = ["frames"]
set = { "sim.method" = "mass-spring", "sim.substeps" = 1, "cloth.flag.stretch_spring_stiffness" = 1e7 }

[[series]]
name = "springs"
vary = { "sim.dt" = ["1/60"] }
"#,
    );
    let out_dir = dir.join("out");
    let out = run(&[
        "experiments",
        &exp,
        "--render",
        "--jobs",
        "1",
        "--out",
        &out_dir.to_string_lossy(),
    ]);
    let (o, e) = texts(&out);
    let result = std::fs::read_to_string(out_dir.join("results/run-0.json"))
        .unwrap_or_else(|err| panic!("a result for the run ({err})\nstdout: {o}\nstderr: {e}"));
    assert!(
        result.contains("\"status\": \"diverged"),
        "the run is recorded as diverged: {result}\nstderr: {e}"
    );
    let run_dir = std::fs::read_dir(out_dir.join("runs"))
        .expect("runs/")
        .map(|d| d.expect("entry").path())
        .find(|p| p.is_dir())
        .expect("the run's render folder");
    let names = files(&run_dir);
    assert!(names.contains(&"diverged.txt".to_owned()), "{names:?}");
    assert!(
        names.iter().any(|n| n.ends_with(".gif")),
        "a finished GIF: {names:?}"
    );
    assert!(
        names.iter().filter(|n| n.ends_with(".png")).count() >= 2,
        "the initial frame and the held, marked one: {names:?}"
    );
    let why = std::fs::read_to_string(run_dir.join("diverged.txt")).expect("diverged.txt");
    assert!(why.contains("stability limit"), "{why}");
}

#[test]
fn render_never_writes_over_an_input() {
    let dir = temp_dir("render-inputs");
    // A scene whose name is one of the frames the render writes into its own directory.
    let scene = write(&dir, "frame_00000.png", SMALL);
    let d = dir.to_string_lossy().into_owned();
    let args = [
        "render", &scene, "--frames", "2", "--size", "32x24", "--out", &d, "-q",
    ];
    let out = run(&args);
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{o}{e}");
    assert!(e.contains("refusing to overwrite an input"), "{e}");
    assert!(e.contains("frame_00000.png"), "names the file: {e}");
    assert_eq!(
        std::fs::read_to_string(&scene).expect("the scene is kept"),
        SMALL
    );
    // --out that is the scene, by another spelling.
    let same = dir.join(".").join("frame_00000.png");
    let out = run(&[
        "render",
        &scene,
        "--frames",
        "2",
        "--out",
        &same.to_string_lossy(),
        "-q",
    ]);
    let (_, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("refusing to overwrite an input"), "{e}");
}

#[test]
fn a_failing_frame_write_names_the_path_and_leaves_no_frame() {
    let dir = temp_dir("render-full");
    let scene = write(&dir, "s.toml", SMALL);
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).expect("out dir");
    // A 1-block file-size limit (EFBIG, SIGXFSZ ignored) stands in for a full disk: the
    // first PNG cannot be written whole.
    let out = run_on_full_disk(
        1,
        &[
            "render",
            &scene,
            "--frames",
            "2",
            "--size",
            "160x120",
            "--out",
            &out_dir.to_string_lossy(),
            "-q",
        ],
    );
    let (o, e) = texts(&out);
    assert_eq!(out.status.code(), Some(1), "{o}{e}");
    let frame = out_dir.join("frame_00000.png");
    assert!(
        e.contains(&frame.display().to_string()),
        "names the path: {e}"
    );
    assert!(!e.contains("panicked"), "{e}");
    let names = files(&out_dir);
    assert!(
        names.is_empty(),
        "no frame, GIF or partial passed off as whole: {names:?}"
    );
}

/// `weft render SCENE-LESS ARGS` into `dir/<name>` with XDG_RUNTIME_DIR unset (as in a
/// container or CI).
fn render_without_runtime_dir(dir: &Path, name: &str, extra: &[&str]) -> std::process::Output {
    let out_dir = dir.join(name).to_string_lossy().into_owned();
    weft()
        .args([
            "render", "--frames", "20", "--size", "64x48", "--out", &out_dir,
        ])
        .args(extra)
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .expect("weft starts")
}

#[test]
fn render_without_a_runtime_dir_prints_no_error_about_it() {
    let dir = temp_dir("render-runtime-dir");
    let out = render_without_runtime_dir(&dir, "out", &["-q"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(!e.contains("XDG_RUNTIME_DIR"), "{e}");
}

#[test]
fn render_off_a_terminal_prints_progress_lines() {
    let dir = temp_dir("render-progress");
    let out = render_without_runtime_dir(&dir, "loud", &[]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    let lines: Vec<&str> = e.lines().filter(|l| l.contains("frame ")).collect();
    assert!(lines.len() >= 2, "{e}");
    assert!(
        lines
            .last()
            .is_some_and(|l| l.starts_with("weft: frame 20/20 (100 %)")),
        "{e}"
    );
    let out = render_without_runtime_dir(&dir, "quiet", &["-q"]);
    let (o, e) = texts(&out);
    assert!(out.status.success(), "{o}{e}");
    assert!(!e.contains("(100 %)"), "-q: no progress: {e}");
}

/// The centre pixel of `weft render SMALL` with `camera` (extra arguments), 1 frame.
fn centre_pixel(dir: &Path, name: &str, camera: &[&str]) -> image::Rgba<u8> {
    let scene = write(dir, "small.toml", SMALL);
    let out_dir = dir.join(name);
    let mut args = vec![
        "render", &scene, "--frames", "1", "--size", "80x60", "-q", "--out",
    ];
    let out_str = out_dir.to_string_lossy().into_owned();
    args.push(&out_str);
    args.extend_from_slice(camera);
    let out = run(&args);
    assert!(out.status.success(), "{:?}", texts(&out));
    let img = image::open(out_dir.join("frame_00000.png")).expect("a frame");
    img.to_rgba8().get_pixel(40, 30).to_owned()
}

#[test]
fn render_looks_from_eye_at_target() {
    let dir = temp_dir("render-eye");
    // The cloth hangs at y = 1 around x = z = 0: looking at it, the centre is cloth-coloured
    // (red front or blue back); looking away, it is the grey sky.
    let coloured = |p: image::Rgba<u8>| {
        let (hi, lo) = (p[0].max(p[1]).max(p[2]), p[0].min(p[1]).min(p[2]));
        hi - lo > 40
    };
    let at = centre_pixel(&dir, "at", &["--eye", "0,1,2", "--target", "0,1,0"]);
    assert!(coloured(at), "looking at the cloth: {at:?}");
    let away = centre_pixel(&dir, "away", &["--eye", "0,1,2", "--target", "0,1.3,4"]);
    assert!(!coloured(away), "looking away: {away:?}");
    let out = run(&["render", "--out", &dir.to_string_lossy(), "--eye", "0,1,2"]);
    let (_, err) = texts(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--target"), "{err}");
}
