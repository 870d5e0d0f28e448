"""The MCAP of `asp plan --mcap`, read back with Foxglove's Python `mcap` reader.

Needs the `asp` binary (`$ASP_BIN`, else target/debug/asp or target/release/asp of this
checkout) and `pip install mcap`; skips with the reason when either is missing.
"""
from __future__ import annotations

import json
import os
import pathlib
import subprocess

import pytest

from conftest import need

mcap_reader = need("mcap.reader", "pip install mcap")

ROOT = pathlib.Path(__file__).resolve().parents[2]


def asp_binary():
    candidates = [os.environ.get("ASP_BIN")] + [str(ROOT / "target" / p / "asp") for p in ("debug", "release")]
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    pytest.skip("no asp binary: build it (cargo build -p asp-cli) or set ASP_BIN")


def test_lack_table_mcap_has_the_foxglove_topics_and_increasing_times(tmp_path):
    out = tmp_path / "lack.mcap"
    model = ROOT / "tests" / "data" / "ikea" / "table_lack_0825.glb"
    run = subprocess.run([asp_binary(), "plan", str(model), "--up", "z", "--quiet", "--mcap", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    counts, schemas, last = {}, {}, -1
    with open(out, "rb") as f:
        reader = mcap_reader.make_reader(f)
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            schemas[channel.topic] = (schema.name, schema.encoding, channel.message_encoding)
            assert message.log_time >= last
            last = message.log_time
            body = json.loads(message.data)
            if schema.name == "foxglove.SceneUpdate":
                assert set(body) == {"deletions", "entities"}
            else:
                assert all(t["parent_frame_id"] in ("world", "model") for t in body["transforms"])
        summary = reader.get_summary()
    assert schemas["/asp/parts"] == ("foxglove.SceneUpdate", "jsonschema", "json")
    assert schemas["/asp/paths"] == ("foxglove.SceneUpdate", "jsonschema", "json")
    assert schemas["/tf"] == ("foxglove.FrameTransforms", "jsonschema", "json")
    steps = counts["/asp/paths"]
    assert steps >= 4, counts
    assert counts["/asp/parts"] == steps + 1
    # 2 s per step, 20 poses per second during 80 % of it: 33 poses per step, plus the first message
    assert counts["/tf"] == 1 + 33 * steps
    assert summary.statistics.message_count == sum(counts.values())
