"""scripts/q-leave-one-out: every model is measured with networks trained without it.

Three generated 3×3×3 Soma cubes, one objective, seconds of training and search: the test is about
the protocol (which data each network saw, which networks each bench used, the summary), not
about the figures.
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

from conftest import ROOT, _asp_command, need

torch = need("torch", "asp.train needs torch (pip install ./py[train])")

SCRIPT = ROOT / "scripts" / "q-leave-one-out"


def test_each_model_is_benchmarked_with_networks_that_never_saw_it(tmp_path: Path) -> None:
    asp_cmd = _asp_command()
    if len(asp_cmd) != 1:  # the script runs one binary; `cargo run` is not one
        subprocess.run(["cargo", "build", "-q", "--locked", "-p", "asp-cli"], cwd=ROOT, check=True)
        asp_cmd = [str(ROOT / "target" / "debug" / "asp")]
    subprocess.run(asp_cmd + ["gen", "soma", "--size", "3", "--count", "3", "--seed", "5", "--out", "cubes", "-q"],
                   cwd=tmp_path, check=True)
    args = [sys.executable, str(SCRIPT), "cubes", "--out", "loo", "--objective", "access", "--asp", asp_cmd[0],
            "--episodes", "10", "--train-seconds", "2", "--batch", "4", "--eval-states", "20",
            "--settings", "vanilla,pretrained", "--seconds", "0.3,0.6"]
    p = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    names = ["soma3_000", "soma3_001", "soma3_002"]
    out = tmp_path / "loo"

    for name in names:
        doc = json.loads((out / "q" / f"{name}_access.onnx.json").read_text())
        assert name not in doc["train_assemblies"], doc["train_assemblies"]
        assert sorted(doc["train_assemblies"]) == sorted(set(names) - {name})
        assert set(doc["holdout_ranking"]) == {name}
        assert doc["train_ranking"] == {}  # skipped: only the held-out model is scored

    commands = (out / "log.txt").read_text().splitlines()
    benches = [c for c in commands if " bench mcts " in c]
    assert len(benches) == 3
    for name in names:
        (line,) = [c for c in benches if f"{name}.glb" in c]
        assert f"loo/q/{name}_access.onnx" in line, line
        assert all(f"loo/q/{other}_access.onnx" not in line for other in names if other != name), line

    with (out / "bench.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["model"], r["setting"], float(r["seconds"])) for r in rows} == {
        (n, s, t) for n in names for s in ("vanilla", "pretrained") for t in (0.3, 0.6)
    }
    summary = (out / "summary.md").read_text()
    assert "3 held-out model(s)" in summary
    assert "| pretrained |" in summary and "of 3" in summary

    # a second run finds every output and runs nothing again
    before = len(commands)
    p = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-3000:]
    assert len((out / "log.txt").read_text().splitlines()) == before
