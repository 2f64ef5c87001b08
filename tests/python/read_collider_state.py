#!/usr/bin/env python3
"""Reads a Weft log's /colliders/state channel with readers Weft did not write and checks it.

Usage: read_collider_state.py LOG.mcap

* the reference Python `mcap` reader validates every CRC;
* the channel's schema is a valid JSON Schema (encoding `jsonschema`), and every message
  (encoding `json`) validates against it (the `jsonschema` package);
* there is one message per logged frame (as many as /stats messages, the same frame numbers,
  the same log times);
* every `[[collider]]` of the scene attached to the log (scene/effective.toml: the file after `--set`, read with tomllib)
  is listed every frame, with its shape's parameters as the scene gives them, at the pose its
  motion prescribes: static, linear x0 + v t, or oscillating x0 + A sin(2 pi f t) (t is the
  message's log time), to 1e-9 m. Colliders whose motion is a rotation are checked for their
  unit quaternion only.
"""

import json
import math
import sys

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import jsonschema
from mcap.reader import make_reader

TOPIC = "/colliders/state"


def expected_position(collider: dict, t: float) -> list:
    x0 = collider.get("position", [0.0, 0.0, 0.0])
    motion = collider.get("motion") or {"kind": "static"}
    kind = motion["kind"]
    if kind == "static":
        return x0
    if kind == "linear":
        return [x + v * t for x, v in zip(x0, motion["velocity"])]
    if kind == "oscillate":
        s = math.sin(2.0 * math.pi * motion["frequency"] * t)
        return [x + a * s for x, a in zip(x0, motion["amplitude"])]
    return None  # a rotation about a pivot moves the position too: not checked here


def main(log_path: str) -> int:
    with open(log_path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        channels = [c for c in summary.channels.values() if c.topic == TOPIC]
        assert len(channels) == 1, f"{TOPIC}: {len(channels)} channels"
        channel = channels[0]
        assert channel.message_encoding == "json", channel.message_encoding
        schema_record = summary.schemas[channel.schema_id]
        assert schema_record.encoding == "jsonschema", schema_record.encoding
        schema = json.loads(schema_record.data)
        jsonschema.Draft7Validator.check_schema(schema)
        validator = jsonschema.Draft7Validator(schema)
        states = []
        stats = []
        for _schema, ch, message in reader.iter_messages(topics=[TOPIC, "/stats"]):
            value = json.loads(message.data)
            if ch.topic == TOPIC:
                errors = sorted(validator.iter_errors(value), key=str)
                assert not errors, f"frame {value.get('frame')}: {errors[0].message}"
                states.append((message.log_time, value))
            else:
                stats.append((message.log_time, value["frame"]))
        attachments = {a.name: a.data for a in reader.iter_attachments()}
    scene = tomllib.loads(attachments["scene/effective.toml"].decode())
    colliders = scene.get("collider", [])
    assert colliders, "the scene has no [[collider]]"
    assert [(t, v["frame"]) for t, v in states] == stats, "one message per /stats frame"
    worst = 0.0
    for log_time, value in states:
        t = log_time * 1e-9
        assert abs(value["time"] - t) < 1e-9, (value["time"], t)
        by_name = {c["name"]: c for c in value["colliders"]}
        assert len(by_name) == len(colliders), sorted(by_name)
        for c in colliders:
            got = by_name[c["name"]]
            assert got["shape"] == c["shape"], (got["shape"], c["shape"])
            for key in ("radius", "half_height", "half_extents"):
                if key in c:
                    assert got[key] == c[key], (c["name"], key, got[key], c[key])
            q = got["rotation"]
            assert abs(math.sqrt(sum(x * x for x in q)) - 1.0) < 1e-12, q
            want = expected_position(c, t)
            if want is not None:
                worst = max(worst, max(abs(a - b) for a, b in zip(got["position"], want)))
    assert worst < 1e-9, f"positions differ from the analytic motion by {worst} m"
    print(
        f"read_collider_state.py: {log_path}: schema valid, {len(states)} frames, "
        f"{len(colliders)} collider(s) at their analytic poses (worst {worst:.1e} m)"
    )
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
