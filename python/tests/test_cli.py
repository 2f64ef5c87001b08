"""Same results as the CLI: the positions `weft run --dump-final` writes and the MCAP log
`weft run --out` writes, bit for bit and byte for byte."""

import json

import numpy as np
import pytest
from mcap.reader import make_reader

import weft

from conftest import run_weft

# (scene, frames, overrides as --set): one method, three methods side by side, colliders that
# move, and a character's body (the log's /colliders/state channel).
CASES = [
    ("assets/scenes/hanging.toml", 45, {}),
    ("assets/scenes/compare.toml", 30, {}),
    ("assets/scenes/sphere_drop.toml", 30, {"sim.substeps": 12}),
    ("assets/scenes/skirt.toml", 8, {}),
]


def cli_sets(overrides):
    args = []
    for k, v in overrides.items():
        args += ["--set", f"{k}={v}"]
    return args


@pytest.mark.parametrize("scene,frames,overrides", CASES)
def test_positions_are_bit_identical_to_weft_runs_dump(tmp_path, weft_bin, scene, frames, overrides):
    dump = tmp_path / "final.json"
    run_weft(weft_bin, "run", scene, "--frames", frames, "--quiet", "--dump-final", dump,
             *cli_sets(overrides))
    final = json.loads(dump.read_text())
    sim = weft.Simulation(scene, overrides=overrides)
    for _ in range(frames):
        sim.step()
    assert final["frame"] == sim.frame == frames
    assert final["time"] == sim.time
    assert sorted(final["cloths"]) == sorted(sim.cloths)
    for name, points in final["cloths"].items():
        # The dump holds float32 (as the log does): the float64 positions rounded alike.
        want = np.array(points, dtype=np.float32)
        got = sim.positions(name).astype(np.float32)
        assert got.tobytes() == want.tobytes(), name


@pytest.mark.parametrize("scene,frames,overrides", CASES)
def test_a_recording_is_byte_identical_to_weft_runs_log(tmp_path, weft_bin, scene, frames, overrides):
    cli = tmp_path / "cli.mcap"
    run_weft(weft_bin, "run", scene, "--frames", frames, "--quiet", "--out", cli,
             "--mesh-every", 5, *cli_sets(overrides))
    sim = weft.Simulation(scene, overrides=overrides)
    py = tmp_path / "py.mcap"
    sim.record(py, frames=frames, mesh_every=5)
    sim.step(frames // 2)
    sim.step(frames - frames // 2)
    assert sim.stop_recording() == py
    assert py.read_bytes() == cli.read_bytes()


def test_a_recording_with_weft_runs_logging_choices_is_byte_identical(tmp_path, weft_bin):
    scene = CASES[0][0]
    cli = tmp_path / "cli.mcap"
    run_weft(weft_bin, "run", scene, "--frames", 11, "--quiet", "--out", cli, "--log", "all",
             "--every", 3, "--mesh-every", 2, "--precision", "f16", "--compression", "zstd")
    sim = weft.Simulation(scene)
    py = tmp_path / "py.mcap"
    sim.record(py, frames=11, log="all", every=3, mesh_every=2, precision="f16",
               compression="zstd")
    sim.step(11)
    sim.stop_recording()
    assert py.read_bytes() == cli.read_bytes()
    with pytest.raises(ValueError, match="not one of"):
        sim.record(tmp_path / "bad.mcap", log="mesh")


def test_weft_replay_reproduces_a_python_recording(tmp_path, weft_bin):
    log = tmp_path / "py.mcap"
    sim = weft.Simulation("assets/scenes/hanging.toml", overrides={"sim.substeps": 14})
    sim.record(log, frames=20)
    sim.step(20)
    sim.stop_recording()
    out = run_weft(weft_bin, "replay", log, "--quiet")
    assert "byte-identical" in out.stdout, out.stdout


def test_a_recording_stopped_by_a_divergence_says_so(tmp_path):
    log = tmp_path / "explode.mcap"
    sim = weft.Simulation("assets/scenes/explode.toml")
    sim.record(log, frames=100)
    with pytest.raises(weft.SimulationError):
        sim.step(100)
    with open(log, "rb") as f:
        meta = {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}
    assert meta["weft.status"]["status"] == "diverged"
    assert "diverged" in meta["weft.status"]["message"]
    assert meta["weft.status"]["frames"] == str(sim.frame)
