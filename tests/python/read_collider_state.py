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
* a scene with a skeleton `[character]` also lists its body parts (`body/<i>`, after the
  colliders), the same ones every frame (a glTF `model` body is a mesh, not listed); each part's pose agrees with its own parameters as documented:
  `position` is halfway between the end points `a` and `b` of a round cone, `rotation` turns
  (0, +-half_height, 0) onto `b` and `a`, and `half_height` is half their distance (1e-9 m).
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


def rotate(q: list, v: list) -> list:
    """The vector v turned by the unit quaternion q = [x, y, z, w]."""
    x, y, z, w = q
    u = [x, y, z]
    cross = lambda a, b: [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                          a[0] * b[1] - a[1] * b[0]]
    t = [2.0 * c for c in cross(u, v)]
    return [v[i] + w * t[i] + cross(u, t)[i] for i in range(3)]


def check_part(part: dict) -> float:
    """How far a body part's pose is from its own end points (m); 0 for a sphere."""
    assert part["shape"] in ("round-cone", "capsule", "sphere"), part["shape"]
    if part["shape"] != "round-cone":
        assert part["radius"] > 0.0, part
        return 0.0
    assert part["r0"] > 0.0 and part["r1"] > 0.0, part
    h, p, a, b = part["half_height"], part["position"], part["a"], part["b"]
    up = rotate(part["rotation"], [0.0, h, 0.0])
    worst = abs(2.0 * h - math.dist(a, b))
    for i in range(3):
        worst = max(worst, abs(p[i] - 0.5 * (a[i] + b[i])), abs(p[i] + up[i] - b[i]),
                    abs(p[i] - up[i] - a[i]))
    return worst


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
    character = "character" in scene
    assert colliders or character, "the scene has no [[collider]] and no [character]"
    # A skeleton's body is analytic (round cones, listed here); a glTF model's skinned mesh is
    # not (it is on /colliders only).
    skeletal = character and "model" not in scene["character"]
    parts = None
    assert [(t, v["frame"]) for t, v in states] == stats, "one message per /stats frame"
    worst = 0.0
    for log_time, value in states:
        t = log_time * 1e-9
        assert abs(value["time"] - t) < 1e-9, (value["time"], t)
        body = [c for c in value["colliders"] if c["name"].startswith("body/")]
        by_name = {c["name"]: c for c in value["colliders"] if c not in body}
        assert len(by_name) == len(colliders), sorted(by_name)
        assert bool(body) == skeletal, "body parts listed exactly when there is a skeleton body"
        names = [c["name"] for c in body]
        assert parts is None or names == parts, "the same body parts every frame"
        parts = names
        body_worst = max([check_part(c) for c in body], default=0.0)
        assert body_worst < 1e-9, f"frame {value['frame']}: a body part is {body_worst} m off"
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
        f"{len(colliders)} collider(s) at their analytic poses (worst {worst:.1e} m), "
        f"{len(parts or [])} body part(s)"
    )
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
