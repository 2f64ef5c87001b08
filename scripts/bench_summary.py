#!/usr/bin/env python3
"""Summarise Weft's `cargo bench` results as docs/benchmarks.md.

Reads every `<criterion>/**/new/benchmark.json` + `estimates.json` (criterion 0.8) and
`<criterion>/substeps_error.json` (written by crates/weft-scene/benches/substeps.rs), and prints:

- step time per frame of XPBD / PBD / explicit and implicit mass-spring at 32²…256² particles,
  projections per second, and the scaling exponent p of cost ∝ particles^p (least-squares fit
  in log-log);
- the reference workload at N = 64/128/256 on 1 and 2 threads;
- substeps × iterations at equal cost with the constraint error reached after 1 s;
- collisions (sphere, triangle mesh, self) with and without, and their exponents;
- each method on the walker in its T-shirt, and mesh-level cloth contact against none;
- self-collision vs constraint solve at N = 128; triangle-mesh contact (static and
  deforming meshes); a character's body; MCAP logging overhead;
- the Python package stepped frame by frame against `weft run`, from
  `<criterion>/python_frame_by_frame.json` (written by python/bench/frame_by_frame.py);
- and says which figures quoted elsewhere are not produced by a bench (the peer comparison,
  the self-collision clocks), pointing to where they are kept.

Figures are criterion's median point estimates. The page starts with where they come from:
the date, the commit (`git describe`), the CPU (`/proc/cpuinfo`'s model name) and the widest
vector path the CPU offers, or the one forced with WEFT_SIMD. Usage:
    python3 scripts/bench_summary.py [CRITERION_DIR] [--out docs/benchmarks.md] [--note TEXT]
                                     [--readme README.md]
    python3 scripts/bench_summary.py --from docs/benchmarks.md --readme README.md
--note adds a line to the header (e.g. the machine's load average during the run); a note
`other rows: …` says which rows were not rerun, and the README's line repeats it. CRITERION_DIR
defaults to $CRITERION_HOME, else $CARGO_TARGET_DIR/criterion, else
target/criterion. Without --out the page goes to standard output.

--readme FILE rewrites the block between `<!-- speed-table:start -->` and
`<!-- speed-table:end -->` in FILE: one table of the figures a user cares about (step time per
method at 128², the reference workload on 1 and 2 threads, colliders, triangle-mesh contact, the
dressed characters, MCAP logging) and one line naming the date, commit, CPU and kernel path. It
is derived from the benchmarks page alone: the page just generated, or with --from PAGE an
already generated page (criterion's output is then not read), so the README's table can be
regenerated without running the benches again.
"""
import contextlib
import datetime
import subprocess
import io
import json
import math
import os
import re
import sys
from pathlib import Path


def parse_args(argv):
    """The command line as a dict: root (criterion directory), out, note, readme, page (--from)."""
    opts = {"root": None, "out": None, "note": None, "readme": None, "page": None}
    flags = {"--out": ("out", "a file"), "--note": ("note", "a text"),
             "--readme": ("readme", "a file"), "--from": ("page", "a benchmarks page")}
    it = iter(argv)
    for a in it:
        if a in flags:
            key, what = flags[a]
            opts[key] = next(it, None)
            if opts[key] is None:
                sys.exit(f"bench_summary: {a} needs {what}")
        elif opts["root"] is None and not a.startswith("--"):
            opts["root"] = a
        else:
            sys.exit(f"bench_summary: unexpected argument {a!r}")
    if opts["readme"] is not None and opts["page"] is None and opts["out"] is None:
        sys.exit("bench_summary: --readme needs --out (the page the table is derived from) "
                 "or --from")
    if opts["page"] is not None:
        if opts["readme"] is None:
            sys.exit("bench_summary: --from needs --readme (it only rewrites the README's table)")
        if opts["root"] or opts["out"] or opts["note"]:
            sys.exit("bench_summary: --from reads a generated page; it takes no CRITERION_DIR, "
                     "--out or --note")
    return opts


def criterion_dir(arg):
    if arg:
        return Path(arg)
    if os.environ.get("CRITERION_HOME"):
        return Path(os.environ["CRITERION_HOME"])
    if os.environ.get("CARGO_TARGET_DIR"):
        return Path(os.environ["CARGO_TARGET_DIR"]) / "criterion"
    return Path("target/criterion")


def load(root):
    """full_id -> (median ns per iteration, elements per iteration or None)."""
    out = {}
    for bj in root.glob("**/new/benchmark.json"):
        est = bj.with_name("estimates.json")
        if not est.exists():
            continue
        b = json.loads(bj.read_text())
        e = json.loads(est.read_text())
        thr = b.get("throughput") or {}
        elements = thr.get("Elements") if isinstance(thr, dict) else None
        out[b["full_id"]] = (e["median"]["point_estimate"], elements)
    return out


def exponent(xs, ys):
    """Least-squares slope of log y against log x (None with fewer than 2 points)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y and y > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def ms(r, key):
    v = r.get(key)
    return None if v is None else v[0] / 1e6


def fmt(x):
    if x is None:
        return "–"
    if x >= 100:
        return f"{x:.0f}"
    if x >= 10:
        return f"{x:.1f}"
    if x >= 1:
        return f"{x:.2f}"
    return f"{x:.3g}"


def fmt_p(p):
    return "–" if p is None else f"{p:.2f}"


SIZES = [32, 64, 128, 256]

METHODS = ["xpbd", "pbd", "mass-spring", "implicit-mass-spring"]


def ratio(a, b):
    """a / b as "12.3×", or "–" when either is missing."""
    return "–" if a is None or not b else f"{fmt(a / b)}×"


def methods(r):
    print("## Step time per frame (reference cloth, 10 substeps × 1 iteration)\n")
    head = " | ".join(f"{n}² ms/frame" for n in SIZES)
    print(f"| method | {head} | × XPBD at 128² | Mproj/s at 128² "
          "| exponent p (cost ∝ particles^p) |")
    print("|---" * (len(SIZES) + 4) + "|")
    any_row = False
    xpbd = ms(r, f"step/xpbd/{128 * 128}")
    for m in METHODS:
        t = [ms(r, f"step/{m}/{n * n}") for n in SIZES]
        if all(x is None for x in t):
            continue
        any_row = True
        v = r.get(f"step/{m}/{128 * 128}")
        rate = f"{v[1] / v[0] * 1e3:.0f}" if v and v[1] else "–"
        p = exponent([n * n for n, x in zip(SIZES, t) if x], [x for x in t if x])
        print(f"| {m} | " + " | ".join(fmt(x) for x in t)
              + f" | {ratio(t[2], xpbd)} | {rate} | {fmt_p(p)} |")
    if not any_row:
        print("(no results: run `cargo bench -p weft-scene --bench methods`)")
    print()


def reference(r):
    print("## Reference workload (N×N, stretch + shear, α = 0, 10 × 1, dt = 1/60)\n")
    print("| threads | N=64 ms/frame | N=128 ms/frame | N=256 ms/frame | ns/projection at 128 |")
    print("|---|---|---|---|---|")
    for t in [1, 2]:
        vals = [ms(r, f"reference/threads={t}/{n}") for n in [64, 128, 256]]
        v = r.get(f"reference/threads={t}/128")
        nsp = f"{v[0] / v[1]:.2f}" if v and v[1] else "–"
        print(f"| {t} | " + " | ".join(fmt(x) for x in vals) + f" | {nsp} |")
    print()


def substeps(r, root):
    print("## Substeps × iterations at equal cost (64², XPBD, α = 0, error after 1 s)\n")
    path = root / "substeps_error.json"
    rows = json.loads(path.read_text()) if path.exists() else []
    if not rows:
        print(f"(no {path}: run `cargo bench -p weft-scene --bench substeps`)\n")
        return
    print("| substeps × iterations | ms/frame (criterion) | RMS C at 1 s (m) | max abs C at 1 s (m) "
          "| mean RMS C, 0.5–1 s (m) |")
    print("|---|---|---|---|---|")
    for row in rows:
        s, i = row["substeps"], row["iterations"]
        t = ms(r, f"substeps_x_iterations/4096/{s}x{i}")
        print(f"| {s} × {i} | {fmt(t)} | {row['rms']:.2e} | {row['max']:.2e} | "
              f"{row.get('mean_rms', float('nan')):.2e} |")
    print()


def collisions(r):
    print("## Collisions: step time per frame with and without (XPBD scenarios)\n")
    head = " | ".join(f"{n}²" for n in SIZES)
    print(f"| scenario | | {head} | exponent p |")
    print("|---" * (len(SIZES) + 3) + "|")
    for name, label in [("collide_sphere", "sphere"), ("collide_trimesh", "triangle mesh"),
                        ("collide_self", "self-collision")]:
        wo = [ms(r, f"{name}/without/{n * n}") for n in SIZES]
        wi = [ms(r, f"{name}/with/{n * n}") for n in SIZES]
        extra = [b - a if a is not None and b is not None else None for a, b in zip(wo, wi)]
        for tag, vals in [("without", wo), ("with", wi), ("collision cost", extra)]:
            p = exponent([n * n for n, x in zip(SIZES, vals) if x], [x for x in vals if x])
            print(f"| {label} | {tag} ms | " + " | ".join(fmt(x) for x in vals) + f" | {fmt_p(p)} |")
    print()
    print("Collision handling alone, one substep (`self_collision` bench), ms:\n")
    print(f"| shape | {head} | exponent p |")
    print("|---" * (len(SIZES) + 2) + "|")
    for g in ["self_collision", "sphere", "trimesh"]:
        vals = [ms(r, f"{g}/{n * n}") for n in SIZES]
        p = exponent([n * n for n, x in zip(SIZES, vals) if x], [x for x in vals if x])
        print(f"| {g} | " + " | ".join(fmt(x) for x in vals) + f" | {fmt_p(p)} |")
    print()


def self_vs_solve(r):
    print("## Self-collision vs constraint solve, 128² self-fold strip, per frame\n")
    print("| what | ms/frame |")
    print("|---|---|")
    for f, label in [("constraint_solve", "constraint solve (no collisions)"),
                     ("solve_and_self_collision", "solve + self-collision"),
                     ("self_collision_hook", "self-collision hook alone")]:
        print(f"| {label} | {fmt(ms(r, f'self_vs_solve/16384/{f}'))} |")
    print()


def mesh_contact(r):
    print("## Triangle-mesh contact (`crates/weft-collide/benches/mesh_contact.rs`, XPBD, "
          "each cloth stepped 30 frames into contact first, or 120 to rest for the draped group)\n")
    print("| 128² cloth on a 20,480-triangle sphere mesh + ground | `static_mesh/16384`: landing, "
          "ms/frame | `static_mesh_draped/16384`: draped, ms/frame |")
    print("|---|---|---|")
    for f, label in [("constraint_solve", "constraint solve (same state, no collisions)"),
                     ("mesh", "mesh, Weft's f64 path"),
                     ("mesh_alone", "mesh alone (no ground)"),
                     ("mesh_parry", "mesh, parry's f32 projection"),
                     ("sphere_solve", "constraint solve of the analytic-sphere scene"),
                     ("sphere", "analytic sphere + ground"),
                     ("sphere_alone", "analytic sphere alone")]:
        landing = fmt(ms(r, f'static_mesh/16384/{f}'))
        draped = fmt(ms(r, f'static_mesh_draped/16384/{f}'))
        print(f"| {label} | {landing} | {draped} |")
    print()
    print("| 90² cloth on a breathing 5,120-triangle ball | `deforming_mesh/8100`: landing, "
          "ms/frame | `deforming_mesh_draped/8100`: draped, ms/frame |")
    print("|---|---|---|")
    for f, label in [("constraint_solve", "constraint solve"),
                     ("deforming", "animation and refit once a frame, faces and swept contact every substep")]:
        landing = fmt(ms(r, f'deforming_mesh/8100/{f}'))
        draped = fmt(ms(r, f'deforming_mesh_draped/8100/{f}'))
        print(f"| {label} | {landing} | {draped} |")
    print()


def character(r):
    print("## A character's body (`crates/weft-character/benches/character.rs`)\n")
    print("| what | µs |")
    print("|---|---|")
    for f, label in [("state/walker", "`Character::state(t)`, walker (24 joints, 20 shapes)"),
                     ("state/cmu", "`Character::state(t)`, CMU clip (38 joints, 25 shapes)"),
                     ("distance/8000", "signed distance of 8,000 points to the walker body, "
                                       "bounding-sphere culled"),
                     ("distance/8000/exhaustive", "the same, every shape tested"),
                     ("skin/simple_skin", "simple_skin linear blend skinning")]:
        v = r.get(f"character/{f}")
        print(f"| {label} | {fmt(None if v is None else v[0] / 1e3)} |")
    print()


def dressed(r):
    print("## A dressed character (`crates/weft-scene/benches/dressed.rs`, "
          "`crates/weft-character/benches/dressed.rs`, XPBD, 10 substeps × 1 iteration)\n")
    print("| the walker in its T-shirt (`assets/scenes/character.toml`, 10,203 particles, "
          "jersey), one frame after the seams closed | ms/frame |")
    print("|---|---|")
    for f, label in [("tshirt: solve + body + self-collision", "solve + body contact + self-collision"),
                     ("tshirt: solve + body", "solve + body contact"),
                     ("tshirt: solve only", "solve only (general loop, no contact)"),
                     ("tshirt, dihedral: solve + body + self-collision",
                      "whole frame, dihedral bending instead of the preset's isometric bending"),
                     ("tshirt, dihedral: solve only",
                      "solve only, dihedral bending (general loop, no contact)")]:
        print(f"| {label} | {fmt(ms(r, f'dressed walker frame/{f}'))} |")
    print()
    print("| a 12,903-particle sheet draped on the walking walker | ms/frame |")
    print("|---|---|")
    for f, label in [("solve/fused", "solve, fused frame (no hook)"),
                     ("solve/general", "solve, general loop (an inert hook)"),
                     ("contact-only", "the body's own work (poses, broad phase, sweep, planes)"),
                     ("body", "solve + body contact"),
                     ("body+self", "solve + body contact + self-collision")]:
        print(f"| {label} | {fmt(ms(r, f'dressed/{f}'))} |")
    print()
    print("| the BCN glTF character jumping in the wool cape (`assets/scenes/glb_character.toml`, "
          "2,374 particles, a 5,126-triangle skinned body) | ms/frame |")
    print("|---|---|")
    for f, label in [("glb cape: solve + skinned body + self-collision",
                      "solve + skinned-body contact + mesh contact (the scene's)"),
                     ("glb cape: solve + skinned body", "solve + skinned-body contact"),
                     ("glb cape: solve only", "solve only (no contact)"),
                     *[(f"glb cape 8k, frame {n}: {what}",
                        f"8,097-particle cape (`cape_fine.toml`), frames {n + 2}–{n + 11}: {label}")
                       for n in (30, 90, 150)
                       for what, label in (("solve + skinned body", "solve + skinned-body contact"),
                                           ("solve only", "solve only (no contact)"))]]:
        print(f"| {label} | {fmt(ms(r, f'dressed walker frame/{f}'))} |")
    print()
    print("| the walker in its T-shirt by method: the whole frame (solve, body contact, "
          "self-collision) from the same state, 10 substeps (explicit mass-spring: the substeps "
          "`weft check` advises, inside its guaranteed bound) | ms/frame | × XPBD |")
    print("|---|---|---|")
    xpbd = ms(r, "walker by method/xpbd")
    for m in METHODS:
        # Explicit springs run at their own substep count, named in the bench's id.
        key, label = f"walker by method/{m}", m
        for k in sorted(r):
            if k.startswith(f"{key} at ") and k.endswith(" substeps"):
                key, label = k, f"{m}, {k[len(key) + 4:]}"
        t = ms(r, key)
        print(f"| {label} | {fmt(t)} | {ratio(t, xpbd)} |")
    print()


def cloth_contact(r):
    print("## Cloth contact (`crates/weft-collide/benches/cloth_contact.rs`, "
          "`crates/weft-scene/benches/dressed.rs`, XPBD, 10 substeps × 1 iteration)\n")
    print("One frame from the same state with mesh-level cloth contact off and on, side by side "
          "in one run.\n")
    print("| scene | contact off ms/frame | contact on ms/frame | ratio |")
    print("|---|---|---|---|")
    for group, label in [("layers landing", "two 2 mm sheets (48², 1 m) landing on a ball "
                                            "(frame 12)"),
                         ("layers at rest", "the same sheets at rest (frame 180)"),
                         ("twist", "a 50² sheet, 4 mm, twisted a full turn (frame 120)")]:
        off = ms(r, f"cloth contact: {group}/contact off")
        on = ms(r, f"cloth contact: {group}/contact on")
        print(f"| {label} | {fmt(off)} | {fmt(on)} | {ratio(on, off)} |")
    print()
    print("| the walker in two thin garments (`assets/scenes/layered_outfit.toml`: the T-shirt "
          "under the cape, 1.5 mm each, 12,577 particles, body contact), one warm frame at "
          "0.5 s | ms/frame | ratio to none |")
    print("|---|---|---|")
    none = ms(r, "walker in two garments/no cloth contact")
    for name, label in [("no cloth contact", "no contact between or within the cloths"),
                        ("particle contact", "particle contact (thin layers slip through)"),
                        ("mesh contact", "mesh contact (the scene's: no crossing)")]:
        t = ms(r, f"walker in two garments/{name}")
        print(f"| {label} | {fmt(t)} | {ratio(t, none)} |")
    print()
    print("| the independent crossing count (`crates/weft-sim/benches/crossings.rs`: "
          "`Simulation::step` with the count off and on, and the count alone) | frame, count "
          "off | frame, count on | the count alone |")
    print("|---|---|---|---|")
    for scene, label in [("layers", "`layers.toml` (4,608 particles) from frame 20"),
                         ("twist", "`twist.toml` (2,500 particles) from frame 60"),
                         ("character", "`character.toml` (10,203 particles) from frame 12")]:
        row = [ms(r, f"crossings/{scene}/{k}") for k in ("frame_off", "frame_on", "measure_alone")]
        print(f"| {label} | " + " | ".join(fmt(x) for x in row) + " |")
    print()


def not_benches():
    print("## Figures that are not from a bench\n")
    print("Two kinds of figure quoted in the performance notes do not come from criterion and "
          "are not on this page:\n")
    print("- Weft against Taichi and the C grid kernel: `scripts/compare_peers.sh` (medians of "
          "whole runs of each solver, interleaved); its dated runs are in "
          "[performance-notes.md](performance-notes.md#against-the-peers).")
    print("- Self-collision against the constraint solve per phase of a fold, and where its time "
          "goes: the `self_collision_cost` example's own clocks "
          "(`cargo run --release -p weft-collide --example self_collision_cost`); its dated runs "
          "are in [performance-notes.md](performance-notes.md#where-self-collisions-time-goes-and-the-floor).")
    print()


LOG_ROWS = [
    ("particles", "`--log particles` (the default): positions, no compression"),
    ("particles_f16", "`--log particles --precision f16`"),
    ("particles_zstd", "`--log particles --compression zstd`"),
    ("all", "`--log all`: positions and the surface every frame"),
    ("all_zstd", "`--log all --compression zstd`"),
]


def logging(r, root):
    print("## MCAP logging (`weft run --out`, the log on its own thread)\n")
    path = root / "logging_bytes.json"
    try:
        sizes = json.loads(path.read_text())
    except (OSError, ValueError):
        sizes = {}
    scenes = [("reference", "the 128² reference"), ("walker", "the walker in its T-shirt")]
    head = " | ".join(f"{label} ms/frame | × no log | KB/frame" for _, label in scenes)
    print(f"| log | {head} |")
    print("|---|" + "---|" * (3 * len(scenes)))
    cells = []
    for scene, _ in scenes:
        cells += [fmt(ms(r, f"logging/{scene}/no_log")), "1", "–"]
    print("| no log | " + " | ".join(cells) + " |")
    for row, label in LOG_ROWS:
        cells = []
        for scene, _ in scenes:
            base, t = ms(r, f"logging/{scene}/no_log"), ms(r, f"logging/{scene}/{row}")
            size = sizes.get(f"{scene}/{row}")
            cells += [fmt(t), f"{t / base:.2f}" if base and t else "–",
                      f"{size / 1e3:.0f}" if size else "–"]
        print(f"| {label} | " + " | ".join(cells) + " |")
    print("\nEach sample's time includes finishing its log (the queue written out, the summary, "
          "the sync). KB/frame: a 120-frame log's size over its 121 frames "
          "(`logging_bytes.json`, written by the bench).\n")


def python_frames(root):
    """python/bench/frame_by_frame.py's figures, when it wrote them into the criterion folder."""
    print("## Python, frame by frame, against weft run\n")
    f = root / "python_frame_by_frame.json"
    if not f.exists():
        print("Not measured in this run: `python python/bench/frame_by_frame.py` (release builds "
              "of `weft` and of the package) writes `python_frame_by_frame.json` into the "
              "criterion folder.\n")
        return
    d = json.loads(f.read_text())
    print(f"`{d['scene']}` at 128², {d['frames']} frames a run, {d['runs']} runs of each "
          f"interleaved (`python/bench/frame_by_frame.py`, {d['date']}, commit {d['commit']}, "
          f"{d['cpu']}, kernel path {d['kernel_path']}, Python {d['python']}, load average "
          f"{d['load'][0]:g} before and {d['load'][1]:g} after): `weft run`'s "
          f"ms/frame against `sim.step()` called once a frame, medians. The issue's bound is "
          f"1.15.\n")
    print("| `weft run` ms/frame | Python `sim.step()` ms/frame | ratio of the medians | "
          "median of the paired ratios |")
    print("|---|---|---|---|")
    print(f"| {fmt(d['weft_run_ms'])} | {fmt(d['python_ms'])} | {d['ratio']:.3f} | "
          f"{d['paired_ratio']:.3f} |")
    print()
    print(f"What a `sim.step()` call adds to its frame (the frames handed to the thread pool, the "
          f"caller woken, the GIL taken back), measured on a 2 × 2 cloth: "
          f"{d['per_call_us']:.1f} µs.\n")


def cpu_model():
    """The CPU's model name from /proc/cpuinfo (or the platform's name)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    import platform
    return platform.processor() or platform.machine()


def simd_path():
    """WEFT_SIMD when set, else the widest vector path the CPU's flags offer."""
    forced = os.environ.get("WEFT_SIMD")
    if forced:
        return f"{forced} (forced with WEFT_SIMD)"
    try:
        flags = set(Path("/proc/cpuinfo").read_text().split())
    except OSError:
        flags = set()
    if "avx512f" in flags:
        return "avx512 (the widest this CPU offers)"
    if "avx2" in flags and "fma" in flags:
        return "avx2 (the widest this CPU offers)"
    return "scalar"


def git(*args):
    try:
        return subprocess.run(["git", *args], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def header(root, count, note):
    date = datetime.date.today().isoformat()
    print("# Benchmarks\n")
    print("Generated by `python3 scripts/bench_summary.py --out docs/benchmarks.md` from "
          "criterion's output after `cargo bench --workspace`; do not edit by hand. Figures are "
          "criterion's median point estimates, in ms per frame unless a column says otherwise.\n")
    print(f"- date: {date}")
    print(f"- commit: {git('describe', '--always', '--dirty')}")
    print(f"- CPU: {cpu_model()}, {os.cpu_count()} logical CPUs")
    print(f"- kernel path: {simd_path()}")
    if note:
        print(f"- {note}")
    print(f"- {count} benchmarks read from `{root}`\n")


def main():
    opts = parse_args(sys.argv[1:])
    if opts["page"] is not None:
        try:
            page = Path(opts["page"]).read_text()
        except OSError as e:
            print(f"bench_summary: cannot read {opts['page']}: {e}", file=sys.stderr)
            return 1
        return update_readme(opts["readme"], page, opts["page"])
    root = criterion_dir(opts["root"])
    r = load(root)
    if not r:
        print(f"no criterion results under {root}: run `cargo bench` first", file=sys.stderr)
        return 1
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        write_page(r, root, opts["note"])
    page = buf.getvalue()
    out = opts["out"]
    if out:
        page += kept_sections(out)
        tmp = Path(out).with_suffix(".md.tmp")
        tmp.write_text(page)
        tmp.replace(out)
        print(f"wrote {out}", file=sys.stderr)
    else:
        sys.stdout.write(page)
    if opts["readme"]:
        return update_readme(opts["readme"], page, out)
    return 0


def kept_sections(path):
    """The sections of the page at `path` whose heading says "by hand": figures measured
    outside criterion (an experiments queue, a bench not yet summarised), kept when the page is
    regenerated."""
    try:
        old = Path(path).read_text()
    except OSError:
        return ""
    kept, keep = [], False
    for line in old.splitlines(keepends=True):
        if line.startswith("## "):
            keep = "by hand" in line
        if keep:
            kept.append(line)
    return ("\n" + "".join(kept)) if kept else ""


def write_page(r, root, note):
    header(root, len(r), note)
    methods(r)
    reference(r)
    substeps(r, root)
    collisions(r)
    self_vs_solve(r)
    mesh_contact(r)
    character(r)
    dressed(r)
    cloth_contact(r)
    logging(r, root)
    python_frames(root)
    not_benches()


# --- The README's Speed table, read back from a generated benchmarks page. ---

START, END = "<!-- speed-table:start -->", "<!-- speed-table:end -->"


def page_sections(page):
    """(sections, bullets): sections maps each heading (without '## ') to its tables, each a
    list of rows (lists of cells), header row first, separator row left out; bullets maps the
    names of the page's header bullets (`- date: …`, `- commit: …`, …) to their values."""
    sections, bullets, current = {}, {}, None
    table = None
    for line in page.splitlines():
        if line.startswith("## "):
            current = line[3:].strip()
            sections[current] = []
            table = None
        elif line.startswith("|") and current is not None:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if all(re.fullmatch(r":?-+:?", c) for c in cells):
                continue
            if table is None:
                table = []
                sections[current].append(table)
            table.append(cells)
        else:
            table = None
            m = re.match(r"- ([A-Za-z ]+): (.*)$", line)
            if current is None and m:
                bullets[m.group(1)] = m.group(2).strip()
    return sections, bullets


def cell(sections, heading, row, column, table=None):
    """The cell of the page under the `## heading...` section (a prefix), in the table whose
    first header cell contains `table` (or the first table), the row whose leading cells are
    `row` (a string or a tuple) and the column whose header contains `column`; None when
    missing or '–'."""
    row = (row,) if isinstance(row, str) else tuple(row)
    for name, tables in sections.items():
        if not name.startswith(heading):
            continue
        for t in tables:
            if table is not None and table not in t[0][0]:
                continue
            cols = [i for i, h in enumerate(t[0]) if column in h]
            if not cols:
                continue
            for r in t[1:]:
                if tuple(r[:len(row)]) == row and cols[0] < len(r):
                    v = r[cols[0]]
                    return None if v in ("", "–", "-") else v
    return None


STEP = "Step time per frame"
REFERENCE = "Reference workload"
COLLISIONS = "Collisions: step time"
MESH = "Triangle-mesh contact"
DRESSED = "A dressed character"
LOGGING = "MCAP logging"

# (what, scene or workload, threads, where in the page: (heading, row, column, table)).
SPEED_ROWS = [
    *[(f"step, {label}", scene, "all", (STEP, m, "128² ms", None))
      for m, label, scene in [
          ("xpbd", "XPBD", "`reference.toml` at 128² (16,384 particles)"),
          ("pbd", "PBD", "the same"),
          ("mass-spring", "explicit mass-spring", "the same"),
          ("implicit-mass-spring", "implicit mass-spring", "the same")]],
    ("step, XPBD", "the same", "1", (REFERENCE, "1", "N=128", None)),
    ("step, XPBD", "the same", "2", (REFERENCE, "2", "N=128", None)),
    ("with a sphere and the ground", "128² cloth draped over a sphere", "all",
     (COLLISIONS, ("sphere", "with ms"), "128²", None)),
    ("with self-collision", "128² curtain folding onto itself", "all",
     (COLLISIONS, ("self-collision", "with ms"), "128²", None)),
    ("with a triangle mesh, landing", "128² cloth on a 20,480-triangle sphere mesh", "all",
     (MESH, "mesh, Weft's f64 path", "landing", "128² cloth")),
    ("with a triangle mesh, draped", "the same, at rest on it", "all",
     (MESH, "mesh, Weft's f64 path", "draped", "128² cloth")),
    ("with a moving triangle mesh", "90² cloth on a breathing 5,120-triangle ball", "all",
     (MESH, "animation and refit once a frame, faces and swept contact every substep", "draped",
      "90² cloth")),
    ("dressed character", "`character.toml`: the walker in its T-shirt", "all",
     (DRESSED, "solve + body contact + self-collision", "ms/frame", "the walker in its T-shirt")),
    ("skinned glTF character", "`glb_character.toml`: a cape on a jumping body, mesh contact", "all",
     (DRESSED, "solve + skinned-body contact + mesh contact (the scene's)", "ms/frame",
      "the BCN glTF")),
    ("`weft run --out` (particles, the default)", "`reference.toml` at 128²", "all",
     (LOGGING, "`--log particles` (the default): positions, no compression",
      "128² reference ms/frame", None)),
    ("`weft run --out --log all`", "the same", "all",
     (LOGGING, "`--log all`: positions and the surface every frame", "128² reference ms/frame",
      None)),
    ("`weft run --out` (particles, the default)", "`character.toml`", "all",
     (LOGGING, "`--log particles` (the default): positions, no compression",
      "T-shirt ms/frame", None)),
]


def speed_block(page, source):
    """The README's Speed block (between the markers, markers excluded) from a page's text, and
    the rows the page lacks."""
    sections, bullets = page_sections(page)
    missing = []
    lines = ["| what | scene | threads | ms per frame |", "|---|---|---|---|"]
    scene_above, shown_above = None, False
    for what, scene, threads, (heading, row, column, table) in SPEED_ROWS:
        # "the same" names the row above's scene; spelt out when that row was left out.
        if scene == "the same":
            scene = scene if shown_above else scene_above
        elif scene.startswith("the same,"):
            scene = scene if shown_above else scene_above + scene[len("the same"):]
        else:
            scene_above = scene
        if row is None:
            # A one-row table: the first data row.
            v = None
            for name, tables in sections.items():
                if name.startswith(heading) and tables and len(tables[0]) > 1:
                    cols = [i for i, h in enumerate(tables[0][0]) if column in h]
                    if cols:
                        v = tables[0][1][cols[0]]
                        v = None if v in ("", "–", "-") else v
        else:
            v = cell(sections, heading, row, column, table)
        shown_above = v is not None
        if v is None:
            missing.append(what if threads == "all" else f"{what}, {threads} thread(s)")
            continue
        lines.append(f"| {what} | {scene} | {threads} | {v} |")
    cpu = bullets.get("CPU", "unknown CPU")
    lines.append("")
    # A page whose benches were not all rerun says so in a `- other rows: …` note.
    other = bullets.get("other rows")
    other = f" (rows not rerun then: {other})" if other else ""
    lines.append(f"Measured {bullets.get('date', 'on an unknown date')} at commit "
                 f"{bullets.get('commit', 'unknown')}{other} on {cpu}, kernel path "
                 f"{bullets.get('kernel path', 'unknown')}; criterion medians, threads \"all\" "
                 f"meaning every logical CPU. Generated from [{source}]({source}) by "
                 f"`python3 scripts/bench_summary.py --from {source} --readme README.md`; every "
                 f"benchmark and how it was run are on that page.")
    return "\n".join(lines), missing


def update_readme(readme, page, source):
    """Rewrites the Speed block of `readme` from the page's text; 1 when the markers are missing."""
    path = Path(readme)
    try:
        text = path.read_text()
    except OSError as e:
        print(f"bench_summary: cannot read {readme}: {e}", file=sys.stderr)
        return 1
    a, b = text.find(START), text.find(END)
    if a < 0 or b < a:
        print(f"bench_summary: {readme} has no {START} … {END} block", file=sys.stderr)
        return 1
    block, missing = speed_block(page, source)
    for m in missing:
        print(f"bench_summary: {source} has no figure for {m}: row left out", file=sys.stderr)
    new = text[:a + len(START)] + "\n" + block + "\n" + text[b:]
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(new)
    tmp.replace(path)
    print(f"rewrote the speed table of {readme}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
