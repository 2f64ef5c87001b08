//! Helpers for the `weft` binary's tests: run it, write scenes, read its MCAP logs.
//!
//! - `screen`: screenshots of the virtual X server: read, compared by region, saved as PNG.
//! - `x11`: the real viewer in a virtual X server (Xvfb), driven by `xdotool`.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

use foxglove::Decode;
use foxglove::messages::PointCloud;

pub mod screen;
pub mod x11;

/// The binary under test.
pub fn weft() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_weft"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// Runs `weft` with `args`, returning its output.
pub fn run(args: &[&str]) -> Output {
    weft().args(args).output().expect("weft starts")
}

/// A fresh directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Writes `text` to `dir/name` and returns the path as a string.
pub fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write file");
    p.to_string_lossy().into_owned()
}

/// Writes `scene` to `dir/name`, runs `weft run` on it for `frames` frames with `--out
/// dir/<log>`, checks it succeeded, and returns the log's path.
pub fn logged_run(dir: &Path, name: &str, scene: &str, frames: u32, log: &str) -> PathBuf {
    let scene = write(dir, name, scene);
    let path = dir.join(log);
    let out = run(&[
        "run",
        &scene,
        "--frames",
        &frames.to_string(),
        "--out",
        &path.to_string_lossy(),
        "--log",
        "all",
    ]);
    assert!(out.status.success(), "{:?}", texts(&out));
    path
}

/// A small, quick scene: an 8×8 cloth hanging from two corners.
pub const SMALL: &str = r#"[sim]
method = "xpbd"
dt = "1/60"
substeps = 4
damping = 0.1

[cloth.flag]
resolution = [8, 8]
size = [0.5, 0.5]
center = [0.0, 1.0, 0.0]
mass = 0.1
pins = ["top-left", "top-right"]
"#;

/// A cloth over a sphere moving at constant velocity, a tilted box, a capsule and the ground.
pub const MOVING: &str = r#"[sim]
method = "xpbd"
dt = "1/60"
substeps = 4

[cloth.sheet]
resolution = [8, 8]
size = [0.5, 0.5]
orientation = "horizontal"
center = [0.0, 1.0, 0.0]
mass = 0.1
pins = []

[[collider]]
name = "ball"
shape = "sphere"
radius = 0.2
position = [0.0, 0.5, 0.0]
motion = { kind = "linear", velocity = [0.3, 0.0, -0.1] }

[[collider]]
name = "rod"
shape = "capsule"
radius = 0.05
half_height = 0.3
position = [1.0, 0.2, 0.0]
motion = { kind = "oscillate", amplitude = [0.0, 0.1, 0.0], frequency = 2.0 }

[[collider]]
name = "box"
shape = "cuboid"
half_extents = [0.1, 0.2, 0.3]
position = [-1.0, 0.3, 0.0]

[[collider]]
name = "ground"
shape = "plane"
normal = [0.0, 1.0, 0.0]
position = [0.0, -0.5, 0.0]
"#;

/// stdout and stderr as text.
pub fn texts(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// What a test reads back from a log.
pub struct Log {
    /// Message counts by topic.
    pub counts: BTreeMap<String, usize>,
    /// The last particle positions by cloth topic.
    pub last: BTreeMap<String, Vec<[f32; 3]>>,
    /// Metadata records by name.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// Attachment names.
    pub attachments: Vec<String>,
}

/// Reads a log with the `mcap` crate (CRCs checked), decoding particle clouds.
pub fn read_log(path: &Path) -> Log {
    let bytes = std::fs::read(path).expect("log exists");
    let summary = mcap::Summary::read(&bytes)
        .expect("summary readable")
        .expect("log has a summary");
    let mut counts = BTreeMap::new();
    let mut last = BTreeMap::new();
    let mut previous_time = 0;
    for m in mcap::MessageStream::new(&bytes).expect("readable") {
        let m = m.expect("message decodes");
        let topic = m.channel.topic.clone();
        *counts.entry(topic.clone()).or_insert(0) += 1;
        assert!(m.log_time >= previous_time, "log time goes backwards");
        previous_time = m.log_time;
        if topic.ends_with("/particles") {
            let pc = PointCloud::decode(&m.data[..]).expect("PointCloud decodes");
            // float32 x, y, z, or binary16 (`--precision f16`), read with the `half` crate.
            let pts = match pc.point_stride {
                12 => pc
                    .data
                    .chunks_exact(12)
                    .map(|c| {
                        let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
                        [f(0), f(4), f(8)]
                    })
                    .collect(),
                6 => pc
                    .data
                    .chunks_exact(6)
                    .map(|c| {
                        let f = |k: usize| half::f16::from_le_bytes([c[k], c[k + 1]]).to_f32();
                        [f(0), f(2), f(4)]
                    })
                    .collect(),
                other => panic!("{topic}: point stride {other}"),
            };
            last.insert(topic, pts);
        }
    }
    let mut metadata = BTreeMap::new();
    for idx in &summary.metadata_indexes {
        let md = mcap::read::metadata(&bytes, idx).expect("metadata");
        metadata.insert(md.name, md.metadata);
    }
    let attachments = summary
        .attachment_indexes
        .iter()
        .map(|a| a.name.clone())
        .collect();
    Log {
        counts,
        last,
        metadata,
        attachments,
    }
}

/// Sends `signal` (e.g. "INT", "TERM", "KILL") to process `pid`.
pub fn signal(pid: u32, signal: &str) {
    let ok = Command::new("kill")
        .args([format!("-{signal}"), pid.to_string()])
        .status()
        .expect("kill runs");
    assert!(ok.success(), "kill -{signal} {pid} failed");
}

/// Waits until `ready()` holds, polling every 20 ms, for at most `limit`; false on timeout.
pub fn wait_for(limit: Duration, mut ready: impl FnMut() -> bool) -> bool {
    let start = std::time::Instant::now();
    while start.elapsed() < limit {
        if ready() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    ready()
}

/// Waits for `child` to exit within `limit`; kills it and fails the test otherwise. Returns its
/// output and how long it took.
pub fn exits_within(child: Child, limit: Duration) -> (Output, Duration) {
    let start = std::time::Instant::now();
    let pid = child.id();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    match rx.recv_timeout(limit) {
        Ok(out) => (out.expect("waits"), start.elapsed()),
        Err(_) => {
            let _ = Command::new("kill")
                .args(["-KILL", &pid.to_string()])
                .status();
            panic!("weft (pid {pid}) did not exit within {limit:?}");
        }
    }
}

/// The temporary file a run writes before renaming it to `target` (`a.mcap` →
/// `a.partial-<pid>-<n>.mcap`), the newest if there are several; a path that does not exist
/// when there is none.
pub fn partial(target: &Path) -> PathBuf {
    let stem = target
        .file_stem()
        .expect("stem")
        .to_string_lossy()
        .into_owned();
    let ext = target
        .extension()
        .expect("extension")
        .to_string_lossy()
        .into_owned();
    let prefix = format!("{stem}.partial-");
    let suffix = format!(".{ext}");
    let dir = target.parent().expect("a directory");
    let newest = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok())
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(&prefix) && n.ends_with(&suffix)
        })
        .max_by_key(|e| e.metadata().and_then(|m| m.modified()).ok());
    newest.map_or_else(
        || target.with_file_name(format!("{stem}.partial-none.{ext}")),
        |e| e.path(),
    )
}

/// A bigger scene: a `n`×`n` cloth, so a frame takes a while and a log grows chunk by chunk.
pub fn big(n: usize) -> String {
    SMALL.replace("resolution = [8, 8]", &format!("resolution = [{n}, {n}]"))
}

/// Starts `weft` with `args` followed by `--out target`, in the background (stdout dropped,
/// stderr kept for the test's messages).
pub fn spawn_logging(args: &[&str], target: &Path) -> Child {
    weft()
        .args(args)
        .arg("--out")
        .arg(target)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("weft starts")
}

/// Waits at most `limit` for the partial log of `target` to hold more than `bytes` bytes.
pub fn partial_grows_past(target: &Path, bytes: u64, limit: Duration) -> bool {
    wait_for(limit, || {
        std::fs::metadata(partial(target)).is_ok_and(|m| m.len() > bytes)
    })
}

/// Runs `weft` with `args` on a "disk" that fills up after `blocks` KiB: a file-size limit
/// (EFBIG, with SIGXFSZ ignored) stands in for a full filesystem.
pub fn run_on_full_disk(blocks: u32, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {blocks}; exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_weft"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sh runs")
}
