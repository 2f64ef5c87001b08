#!/usr/bin/env python3
"""Read a Weft MCAP log into numpy: every cloth's positions per frame, and the /stats channel.

    python python/examples/read_mcap.py run.mcap     # a log of `weft run --out` or sim.record
    python python/examples/read_mcap.py              # records one first, then reads it back

Uses the `mcap` and `mcap-protobuf-support` packages from PyPI (the reference MCAP reader, not
Weft's): /cloth/<name>/particles are foxglove.PointCloud messages whose data is float32 x, y, z
per particle; /stats is JSON.
"""

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

SCENE = Path(__file__).resolve().parents[2] / "assets" / "scenes" / "hanging.toml"


def read_log(path):
    """The log at `path` as arrays: {"cloths": {name: (times (k,), positions (k, n, 3) float32)},
    "stats": {field: (k,) array}, "metadata": {record: {key: value}}}."""
    frames = {}
    stats = []
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
        topics = [c.topic for c in reader.get_summary().channels.values()]
        clouds = [t for t in topics if t.startswith("/cloth/") and t.endswith("/particles")]
        for _schema, channel, message, decoded in reader.iter_decoded_messages(topics=clouds):
            name = channel.topic[len("/cloth/") : -len("/particles")]
            points = np.frombuffer(decoded.data, dtype="<f4").reshape(-1, 3)
            frames.setdefault(name, []).append((message.log_time * 1e-9, points))
        for _schema, _channel, message in reader.iter_messages(topics=["/stats"]):
            stats.append(json.loads(message.data))
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    cloths = {
        name: (np.array([t for t, _ in seq]), np.stack([p for _, p in seq]))
        for name, seq in frames.items()
    }
    columns = {k: np.array([s[k] for s in stats]) for k in (stats[0] if stats else {})}
    return {"cloths": cloths, "stats": columns, "metadata": metadata}


def record_one(path, frames):
    """Records the hanging cloth for `frames` frames; returns its final positions."""
    import weft

    sim = weft.Simulation(SCENE)
    sim.record(path, frames=frames)
    sim.step(frames)
    sim.stop_recording()
    return sim.positions("cloth")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", nargs="?", type=Path, help="an MCAP log (default: record one)")
    parser.add_argument("--frames", type=int, default=120, help="frames to record without a log")
    args = parser.parse_args()
    final = None
    with tempfile.TemporaryDirectory() as tmp:
        path = args.log
        if path is None:
            path = Path(tmp) / "hanging.mcap"
            final = record_one(path, args.frames)
        log = read_log(path)
    run = log["metadata"].get("weft.run", {})
    status = log["metadata"].get("weft.status", {})
    print(f"{path.name}: scene {run.get('scene')}, {status.get('status')} after {status.get('frames')} frames")
    for name, (times, positions) in log["cloths"].items():
        lowest = positions[:, :, 1].min(axis=1)
        print(
            f"  {name}: positions {positions.shape} ({positions.dtype}), t = {times[0]:.3f}..{times[-1]:.3f} s, "
            f"lowest point {lowest[0]:+.4f} → {lowest[-1]:+.4f} m"
        )
    energy = log["stats"].get("kinetic_energy")
    if energy is not None:
        print(f"  kinetic energy: peak {energy.max():.4g} J at frame {int(energy.argmax())}")
    if final is not None:
        logged = log["cloths"]["cloth"][1][-1]
        assert np.array_equal(logged, final.astype(np.float32)), "the log's last frame is the state"
        print("  the last logged frame equals sim.positions() rounded to float32")


if __name__ == "__main__":
    main()
