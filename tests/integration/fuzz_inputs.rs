//! Every kind of file weft reads, mutated from the shipped ones as a hostile user would (bytes
//! flipped, files cut, numbers replaced by extreme ones, lines dropped or repeated): `weft check`
//! of a scene that uses a mutated garment, BVH clip, OBJ mesh or glTF model, and `weft recover`
//! of a mutated log, each run as a process with a time limit. A case fails on a panic, a signal
//! (an abort on a huge allocation, a stack overflow), a hang, or an exit 0 that says nothing
//! or writes an empty file. Deterministic (a fixed seed); `WEFT_FUZZ_CASES` sets the cases per
//! kind (default 64).

use crate::common;

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use common::*;

/// The longest a case may take (the slowest, a dressed character's check, takes about a
/// second here).
const LIMIT: Duration = Duration::from_secs(60);

/// Numbers that break readers: overflow, underflow, huge counts, NaN.
const HOSTILE: &[&str] = &[
    "1e308",
    "-1e308",
    "1e-300",
    "nan",
    "inf",
    "0",
    "-1",
    "4000000000",
    "18446744073709551615",
    "99999999999999999999999",
    "1e11",
    "-0",
];

/// xorshift64*: a fixed sequence for a fixed seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.' || b[i] == b'e') {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// `text` mutated once or a few times: numbers replaced, lines dropped or repeated, or cut.
fn mutate_text(text: &str, rng: &mut Rng) -> String {
    let mut t = text.to_owned();
    for _ in 0..1 + rng.below(3) {
        match rng.below(4) {
            0 | 1 => {
                let spans = numbers(&t);
                if let Some(&(a, b)) = spans.get(rng.below(spans.len())) {
                    let value = HOSTILE[rng.below(HOSTILE.len())];
                    t.replace_range(a..b, value);
                }
            }
            2 => {
                let mut lines: Vec<&str> = t.lines().collect();
                if !lines.is_empty() {
                    let k = rng.below(lines.len());
                    if rng.below(2) == 0 {
                        lines.remove(k);
                    } else {
                        lines.insert(k, lines[k]);
                    }
                }
                t = lines.join("\n");
            }
            _ => {
                let mut cut = rng.below(t.len());
                while !t.is_char_boundary(cut) {
                    cut -= 1;
                }
                t.truncate(cut);
            }
        }
    }
    t
}

/// `bytes` with a few bytes flipped, or cut short.
fn mutate_bytes(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = bytes.to_vec();
    if rng.below(4) == 0 {
        b.truncate(rng.below(b.len()));
        return b;
    }
    for _ in 0..1 + rng.below(4) {
        let k = rng.below(b.len());
        b[k] ^= 1 << rng.below(8);
    }
    b
}

/// Runs weft with `args` for case `case`; fails the test on a panic, a signal, a hang, or an
/// exit 0 that prints nothing or leaves `out` (if any) empty.
fn survive(case: &str, args: &[&str], out: Option<&Path>) {
    let mut child = weft()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("weft starts");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("waits") {
            break s;
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{case}: no answer within {LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let output = child.wait_with_output().expect("output");
    let (o, e) = texts(&output);
    assert!(
        status.signal().is_none(),
        "{case}: killed by signal {:?}: {e}",
        status.signal()
    );
    assert!(
        status.code() != Some(101) && !e.contains("panicked"),
        "{case}: panic: {e}"
    );
    if status.success() {
        assert!(!o.trim().is_empty(), "{case}: exit 0 saying nothing");
        if let Some(out) = out {
            let len = std::fs::metadata(out).map(|m| m.len()).unwrap_or(0);
            assert!(len > 0, "{case}: exit 0 with an empty {}", out.display());
        }
    } else {
        assert!(!e.trim().is_empty(), "{case}: exit {status} saying nothing");
    }
}

/// Cases per kind.
fn cases() -> usize {
    std::env::var("WEFT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

/// `weft check` of `scene` (which reads `file`) with `file` mutated `cases()` times.
fn fuzz_check(kind: &str, scene: &str, file: &str, seed: &[u8], text: bool) {
    let dir = temp_dir(&format!("fuzz-{kind}"));
    let scene = write(&dir, "s.toml", scene);
    let mut rng = Rng(kind.bytes().fold(0x9E37_79B9_7F4A_7C15, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01B3)
    }));
    for case in 0..cases() {
        let bytes = if text {
            let t = std::str::from_utf8(seed).expect("text seed");
            mutate_text(t, &mut rng).into_bytes()
        } else {
            mutate_bytes(seed, &mut rng)
        };
        std::fs::write(dir.join(file), &bytes).expect("write case");
        survive(&format!("{kind} case {case}"), &["check", &scene], None);
    }
}

fn asset(path: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).expect("shipped asset")
}

#[test]
fn mutated_garments_never_crash_or_hang_check() {
    let scene = "[character]\nskeleton = \"walker\"\nbody = \"walker\"\n\n\
                 [cloth.shirt]\ngarment = \"g.toml\"\nthickness = 0.004\n";
    fuzz_check(
        "garment",
        scene,
        "g.toml",
        &asset("assets/garments/tshirt.toml"),
        true,
    );
}

#[test]
fn mutated_bvh_clips_never_crash_or_hang_check() {
    let scene = "[character]\nskeleton = \"m.bvh\"\nscale = 0.056444\nbody = \"cmu\"\n\n\
                 [cloth.c]\nresolution = [4, 4]\n";
    fuzz_check(
        "bvh",
        scene,
        "m.bvh",
        &asset("assets/characters/cmu_01_01_4s.bvh"),
        true,
    );
}

#[test]
fn mutated_obj_meshes_never_crash_or_hang_check() {
    let scene = "[cloth.c]\nresolution = [8, 8]\n\n[[collider]]\nshape = \"mesh\"\n\
                 mesh = \"m.obj\"\n";
    fuzz_check(
        "obj",
        scene,
        "m.obj",
        &asset("assets/meshes/blob.obj"),
        true,
    );
}

#[test]
fn mutated_gltf_models_never_crash_or_hang_check() {
    let scene = "[character]\nmodel = \"m.glb\"\n\n[cloth.c]\nresolution = [4, 4]\n";
    fuzz_check(
        "glb",
        scene,
        "m.glb",
        &asset("assets/characters/bcn_epileptic.glb"),
        false,
    );
    let scene = "[character]\nmodel = \"m.gltf\"\n\n[cloth.c]\nresolution = [4, 4]\n";
    fuzz_check(
        "gltf",
        scene,
        "m.gltf",
        &asset("assets/characters/simple_skin.gltf"),
        true,
    );
}

#[test]
fn mutated_logs_never_crash_or_hang_recover() {
    let dir = temp_dir("fuzz-mcap");
    let log = logged_run(
        &dir,
        "s.toml",
        "[cloth.c]\nresolution = [12, 12]\npins = [\"top\"]\n",
        20,
        "a.mcap",
    );
    let seed = std::fs::read(&log).expect("log");
    let mut rng = Rng(0x5DEE_CE66_D1CE_4E5B);
    let (case_log, out) = (dir.join("m.mcap"), dir.join("r.mcap"));
    for case in 0..cases() {
        std::fs::write(&case_log, mutate_bytes(&seed, &mut rng)).expect("write case");
        let _ = std::fs::remove_file(&out);
        let args = [
            "recover",
            case_log.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
        ];
        survive(&format!("mcap case {case}"), &args, Some(&out));
    }
    // Not MCAP at all: refused, nothing written.
    std::fs::write(&case_log, b"[sim]\ndt = 0.01\n").expect("write");
    let _ = std::fs::remove_file(&out);
    let status = run(&[
        "recover",
        case_log.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
    ])
    .status;
    assert_eq!(status.code(), Some(1));
    assert!(!out.exists());
}
