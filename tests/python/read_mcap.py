#!/usr/bin/env python3
"""Reads a Weft MCAP log with the reference Python reader (not written by Weft) and checks it.

Usage: read_mcap.py LOG.mcap FINAL.json

* every record's CRC is validated (validate_crcs=True);
* each /cloth/<name>/particles channel decodes as foxglove.PointCloud (protobuf) with float32
  x, y, z at offsets 0, 4, 8 and a 12-byte stride, one message per frame, in time order;
* the last message of each cloth equals the positions Weft dumped with --dump-final;
* the run's metadata says it completed the frames it claims, and the scene is attached.
"""

import json
import struct
import sys

from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory


def main(log_path: str, final_path: str) -> int:
    with open(final_path) as f:
        final = json.load(f)
    expected = final["cloths"]
    with open(log_path, "rb") as f:
        reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        topics = {c.topic for c in summary.channels.values()}
        wanted = [f"/cloth/{name}/particles" for name in expected]
        missing = [t for t in wanted if t not in topics]
        assert not missing, f"missing channels {missing}; have {sorted(topics)}"
        for ch in summary.channels.values():
            if ch.topic in wanted:
                schema = summary.schemas[ch.schema_id]
                assert schema.name == "foxglove.PointCloud", schema.name
                assert schema.encoding == "protobuf" and ch.message_encoding == "protobuf"
        counts = {t: 0 for t in wanted}
        last = {}
        last_time = {t: -1 for t in wanted}
        for _schema, channel, message, decoded in reader.iter_decoded_messages(topics=wanted):
            t = channel.topic
            assert message.log_time > last_time[t], f"{t}: log time not increasing"
            last_time[t] = message.log_time
            counts[t] += 1
            assert decoded.point_stride == 12, decoded.point_stride
            fields = [(x.name, x.offset, x.type) for x in decoded.fields]
            assert [(n, o) for n, o, _ in fields] == [("x", 0), ("y", 4), ("z", 8)], fields
            assert all(ty == 7 for _, _, ty in fields), f"not FLOAT32: {fields}"
            last[t] = decoded.data
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        attachments = [a.name for a in reader.iter_attachments()]

    assert metadata["weft.status"]["status"] == "complete", metadata["weft.status"]
    frames = int(metadata["weft.status"]["frames"])
    assert frames == final["frame"], (frames, final["frame"])
    assert "scene/source.toml" in attachments, attachments
    worst = 0.0
    for name, positions in expected.items():
        t = f"/cloth/{name}/particles"
        assert counts[t] == frames + 1, f"{t}: {counts[t]} messages for {frames} frames"
        data = last[t]
        assert len(data) == 12 * len(positions), (len(data), len(positions))
        got = struct.unpack(f"<{3 * len(positions)}f", data)
        for i, p in enumerate(positions):
            for k in range(3):
                # The JSON holds the float32 values; round them to float32 again to compare.
                want = struct.unpack("<f", struct.pack("<f", p[k]))[0]
                worst = max(worst, abs(got[3 * i + k] - want))
    assert worst == 0.0, f"positions differ from Weft's dump by up to {worst}"
    total = sum(len(p) for p in expected.values())
    print(
        f"read_mcap.py: {log_path}: CRCs valid, {len(expected)} cloth(s), {frames} frames, "
        f"{total} particles match Weft's final positions exactly"
    )
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
