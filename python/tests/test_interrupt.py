"""Ctrl-C: SIGINT to a process stepping a big scene raises KeyboardInterrupt within a second,
even inside a frame that takes longer than that, and closes its recording as interrupted."""

import os
import signal
import subprocess
import sys
import time

from mcap.reader import make_reader

from conftest import REPO

# One frame of a 192² cloth at 20,000 substeps: seconds, so the stop must come from
# inside the frame, not between frames.
CHILD = r"""
import sys, time
import weft
sim = weft.Simulation(
    "assets/scenes/reference.toml",
    overrides={"cloth.reference.resolution": [192, 192], "sim.substeps": 20000},
)
sim.record(sys.argv[1], frames=100)
print("stepping", flush=True)
try:
    sim.step(100)
except KeyboardInterrupt:
    print(f"interrupted {time.monotonic()!r} frame {sim.frame}", flush=True)
    sys.exit(0)
print("finished without an interrupt", flush=True)
sys.exit(1)
"""


def test_sigint_raises_keyboard_interrupt_within_a_second_inside_a_long_frame(tmp_path):
    log = tmp_path / "big.mcap"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(log)],
        cwd=REPO,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout.readline().strip() == "stepping"
        time.sleep(0.5)
        sent = time.monotonic()
        os.kill(child.pid, signal.SIGINT)
        line = child.stdout.readline().split()
        assert child.wait(timeout=30) == 0, line
    finally:
        child.kill()
    assert line[0] == "interrupted", line
    caught = float(line[1])
    assert caught - sent < 1.0, f"KeyboardInterrupt {caught - sent:.3f} s after SIGINT"
    assert line[3] == "0", "the stop came inside the first frame"
    with open(log, "rb") as f:
        meta = {m.name: dict(m.metadata) for m in make_reader(f, validate_crcs=True).iter_metadata()}
    assert meta["weft.status"] == {"status": "interrupted", "frames": "0", "message": ""}
