#!/usr/bin/env python3
"""Frame by frame from Python against `weft run`: the 128² reference (assets/scenes/reference.toml)
stepped one `sim.step()` call a frame, beside the ms/frame `weft run` prints for the same scene
and frames, runs of each interleaved; medians, their ratio, the CPU and the kernel path.

Both must be release builds, as a user gets them:

    cargo build --release --bin weft
    pip install ./python                          # maturin, release profile
    python python/bench/frame_by_frame.py --runs 9 --frames 600

It writes its figures to target/criterion/python_frame_by_frame.json (--json elsewhere), where
`python3 scripts/bench_summary.py --out docs/benchmarks.md` finds them for the section "Python,
frame by frame, against weft run", as it finds the criterion benches' own. Exits 1 when the
ratio is above the bound of 1.15.
"""

import argparse
import datetime
import json
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

import weft

REPO = Path(__file__).resolve().parents[2]
SCENE = "assets/scenes/reference.toml"


def cli_ms_per_frame(weft_bin, frames):
    """The ms/frame `weft run` prints (its stepping loop's wall time over the frames)."""
    out = subprocess.run(
        [str(weft_bin), "run", SCENE, "--frames", str(frames), "--quiet"],
        cwd=REPO, capture_output=True, text=True, check=True,
    ).stdout
    return float(re.search(r"([0-9.]+) ms/frame", out).group(1))


def python_ms_per_frame(frames):
    """The same frames stepped from Python, one call a frame; the loop's wall time over them."""
    sim = weft.Simulation(SCENE)
    start = time.perf_counter()
    for _ in range(frames):
        sim.step()
    return 1e3 * (time.perf_counter() - start) / frames


def per_call_us(calls=2000, runs=7):
    """What a `sim.step()` call costs beyond its frame (µs): a 2 × 2 cloth at one substep stepped
    by one call of `calls` frames against `calls` calls of one frame, medians of `runs`."""
    sim = weft.Simulation('[sim]\nsubsteps = 1\n[cloth.a]\nresolution = [2, 2]\npins = ["top"]\n')
    one, many = [], []
    for _ in range(runs):
        start = time.perf_counter()
        sim.step(calls)
        one.append(time.perf_counter() - start)
        start = time.perf_counter()
        for _ in range(calls):
            sim.step()
        many.append(time.perf_counter() - start)
    return 1e6 * (statistics.median(many) - statistics.median(one)) / calls


def cpu_model():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def simd_path():
    forced = os.environ.get("WEFT_SIMD")
    if forced:
        return f"{forced} (forced with WEFT_SIMD)"
    flags = set(Path("/proc/cpuinfo").read_text().split())
    if "avx512f" in flags:
        return "avx512"
    if "avx2" in flags and "fma" in flags:
        return "avx2"
    return "scalar"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--weft", type=Path, default=REPO / "target" / "release" / "weft")
    parser.add_argument("--frames", type=int, default=600)
    parser.add_argument("--runs", type=int, default=9)
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    parser.add_argument("--json", type=Path, default=target / "criterion" / "python_frame_by_frame.json",
                        help="where to write the figures")
    args = parser.parse_args()
    os.chdir(REPO)
    # One untimed run of each first: page cache, CPU frequency, the thread pool.
    cli_ms_per_frame(args.weft, 60)
    python_ms_per_frame(60)
    load_before = os.getloadavg()[0]
    cli, py = [], []
    for _ in range(args.runs):
        cli.append(cli_ms_per_frame(args.weft, args.frames))
        py.append(python_ms_per_frame(args.frames))
    result = {
        "date": datetime.date.today().isoformat(),
        "commit": subprocess.run(["git", "describe", "--always", "--dirty"], cwd=REPO,
                                 capture_output=True, text=True).stdout.strip(),
        "cpu": f"{cpu_model()}, {os.cpu_count()} logical CPUs",
        "kernel_path": simd_path(),
        "scene": SCENE,
        "frames": args.frames,
        "runs": args.runs,
        "weft_run_ms": statistics.median(cli),
        "python_ms": statistics.median(py),
        "weft_run_all": cli,
        "python_all": py,
        "python": sys.version.split()[0],
        # The 1-minute load average before and after: other work on the machine shows here.
        "load": [round(load_before, 2), round(os.getloadavg()[0], 2)],
        "weft": weft.__version__,
    }
    result["per_call_us"] = per_call_us()
    result["ratio"] = result["python_ms"] / result["weft_run_ms"]
    # Each Python run against the `weft run` just before it: drift in the machine's load
    # cancels within a pair.
    result["paired_ratio"] = statistics.median(p / c for p, c in zip(py, cli))
    print(f"weft run:           median {result['weft_run_ms']:.3f} ms/frame  {[round(x, 3) for x in cli]}")
    print(f"Python, step() × N: median {result['python_ms']:.3f} ms/frame  {[round(x, 3) for x in py]}")
    print(f"a step() call costs {result['per_call_us']:.1f} µs beyond its frame")
    print(f"ratio of medians {result['ratio']:.3f}, median of paired ratios "
          f"{result['paired_ratio']:.3f}; {result['cpu']}; kernel path {result['kernel_path']}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.json}")
    return 0 if result["ratio"] <= 1.15 else 1


if __name__ == "__main__":
    sys.exit(main())
