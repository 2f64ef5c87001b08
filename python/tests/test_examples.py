"""The examples in python/examples/ run (small, with --quick) and do what they say."""

import csv
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

import weft

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def example(name, *args, cwd):
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *map(str, args)],
        cwd=cwd,
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_the_sweep_writes_a_csv_and_a_plot_of_sag_growing_with_compliance(tmp_path):
    out = example("sweep_compliance.py", "--quick", "--out", tmp_path / "sweep", cwd=tmp_path)
    with open(tmp_path / "sweep" / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 4
    alpha = [float(r["stretch_compliance"]) for r in rows]
    sag = [float(r["sag_m"]) for r in rows]
    assert alpha == sorted(alpha) and sag == sorted(sag) and sag[-1] > 2 * sag[0], sag
    # Each row is the run a Simulation gives in this process too.
    sys.path.insert(0, str(EXAMPLES))
    try:
        import sweep_compliance
    finally:
        sys.path.pop(0)
    again = sweep_compliance.run((alpha[1], 60, 16))
    assert again["sag_m"] == sag[1]
    png = (tmp_path / "sweep" / "sweep.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000
    assert "wrote" in out


def test_the_fit_recovers_the_compliance_that_made_the_target(tmp_path):
    out = example("fit_stretch.py", "--quick", "--truth", "0.05", cwd=tmp_path)
    fitted = float(re.search(r"α = ([0-9.e+-]+) m/N in", out).group(1))
    assert abs(np.log10(fitted) - np.log10(0.05)) < 0.05, out
    got, target = map(float, re.search(r"its sag ([0-9.]+) mm against the target ([0-9.]+) mm", out).groups())
    assert abs(got - target) < 0.01, out


def test_the_reader_reads_a_log_into_numpy(tmp_path):
    out = example("read_mcap.py", "--frames", "30", cwd=tmp_path)
    assert "complete after 30 frames" in out
    assert "positions (31, 1024, 3) (float32)" in out
    assert "equals sim.positions()" in out
    # And a log of the CLI's three-method scene, read by the function itself.
    sys.path.insert(0, str(EXAMPLES))
    try:
        import read_mcap
    finally:
        sys.path.pop(0)
    sim = weft.Simulation("assets/scenes/compare.toml")
    sim.record(tmp_path / "compare.mcap", frames=5)
    sim.step(5)
    sim.stop_recording()
    log = read_mcap.read_log(tmp_path / "compare.mcap")
    assert sorted(log["cloths"]) == sorted(sim.cloths)
    for name, (times, positions) in log["cloths"].items():
        assert positions.shape == (6, len(sim.positions(name)), 3)
        np.testing.assert_allclose(times, np.arange(6) / 60, atol=1e-9)
        assert np.array_equal(positions[-1], sim.positions(name).astype(np.float32))
    assert list(log["stats"]["frame"]) == [0, 1, 2, 3, 4, 5]
