"""End to end, as a user runs it: generate assemblies, collect labelled states, train the
removability GNN for a few seconds, export it to ONNX, and plan held-out assemblies with
``asp plan --order gnn``: the learned ordering must run fewer removal tests than the thesis'
vanilla AbD (``--order shuffled``) over the same seeds."""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import need

torch = need("torch", "asp.train needs torch (pip install ./py[train])")

ROOT = Path(__file__).resolve().parents[2]


def asp_bin() -> str:
    exe = os.environ.get("ASP_BIN")
    if exe:
        return exe
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "asp"
        if p.exists():
            return str(p)
    pytest.skip("no asp binary: build it (cargo build -p asp-cli) or set ASP_BIN")


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    r = subprocess.run(args, cwd=cwd, capture_output=True, text=True)
    assert r.returncode in (0, 1), f"{args}: exit {r.returncode}\n{r.stderr}"
    return r


def removal_tests_of(asp: str, model: Path, *flags: str, cwd: Path) -> int:
    r = run(asp, "plan", str(model), "--json", "--quiet", *flags, cwd=cwd)
    plan = json.loads(r.stdout)
    assert plan["status"] == "found", plan["status"]
    return plan["stats"]["removal_tests"]


def test_learned_ordering_beats_vanilla_on_held_out_assemblies(tmp_path: Path) -> None:
    asp = asp_bin()
    run(asp, "gen", "profiles", "--preset", "single-layer", "--count", "3", "--seed", "11", "--out", "train", cwd=tmp_path)
    run(asp, "gen", "soma", "--size", "4", "--count", "3", "--seed", "12", "--out", "train_soma", cwd=tmp_path)
    run(asp, "gen", "profiles", "--preset", "single-layer", "--count", "2", "--seed", "13", "--out", "held", cwd=tmp_path)
    run(asp, "collect", "removability", "train", "train_soma", "--runs", "4", "--seed", "0", "--out", "rem", cwd=tmp_path)
    index = json.loads((tmp_path / "rem" / "index.json").read_text())
    assert len(index["assemblies"]) == 6 and all(a["states"] > 0 for a in index["assemblies"])
    r = subprocess.run(
        [sys.executable, "-m", "asp.train", "removability", "rem", "--out", "rem.onnx", "--epochs", "8",
         "--seconds", "40", "--seed", "0"],
        cwd=tmp_path, capture_output=True, text=True,
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "rem.onnx").stat().st_size > 1000
    held = sorted((tmp_path / "held").glob("*.glb"))
    assert len(held) == 2
    vanilla, learned = [], []
    for model in held:
        for seed in range(3):
            vanilla.append(removal_tests_of(asp, model, "--order", "shuffled", "--seed", str(seed), cwd=tmp_path))
            learned.append(removal_tests_of(asp, model, "--order", "gnn", "--model", "rem.onnx", "--seed", str(seed), cwd=tmp_path))
    assert statistics.mean(learned) < statistics.mean(vanilla), (learned, vanilla)
